"""neural3d's measurement stages switched off one at a time, on the saved fields of a comparison.

    python bench/neural3d_stages.py --results DIR [--scenes NAME ...] [--resolution 256]
        [--without STAGE[,STAGE...] ...] [--threads 2] [--json FILE] [--compare-to FILE]

For every run a comparison kept (``DIR/neural3d_runs/<scene>/``, DIR being
``metrics.compare``'s ``--results``), the final field is meshed once
(:func:`neural3d.extract.semantic_mesh_of_field`, marching cubes at
``--resolution``) and measured with each stage set
(:func:`neural3d.extract.measure_mesh`): all stages on, then each stage of
:data:`neural3d.extraction.extract_config.STAGES` off (and the stages that need
it), or only the sets given by ``--without`` (``all`` is always measured).
Prints, in Markdown, the WWR, window and facade errors (APE %) and the
footprint IoU of every stage set per building and per family.

``--json FILE`` writes everything at full precision: per building a fingerprint
of the mesh and, per stage set, the measured part of the result (WWR, areas,
per-facade figures, footprint, warnings) and its errors. ``--compare-to FILE``
reads such a file (made before a change to the code, on the same runs and
resolution) and checks that every building and stage set both hold has the same
mesh and the same result, float for float; it prints each difference and exits
with status 1 if there is one.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead
# (imported as bench.neural3d_stages, the path is the importer's and stays as it is).
if not __package__:
    sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402

from bench.tables import markdown_table  # noqa: E402
from dataset.set_roles import refuse_report_only  # noqa: E402
from envelope.atomic import write_json_atomic  # noqa: E402
from envelope.results import code_version  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402
from metrics.score.errors import building_errors  # noqa: E402
from neural3d.extract import measure_mesh, semantic_mesh_of_field  # noqa: E402
from neural3d.extraction.extract_config import STAGES, ExtractConfig, without_stages  # noqa: E402
from neural3d.extraction.meshing import SemanticMesh  # noqa: E402
from neural3d.field.trained import load_trained_field  # noqa: E402
from neural3d.method import RUNS_FOLDER, trained_runs, trained_scene_dirs  # noqa: E402

ALL = "all"
MEASURED = ("wwr", "window_area_m2", "facade_area_m2", "facades", "footprint", "warnings")
ERRORS = ("wwr_ape", "window_ape", "facade_ape", "footprint_iou")


def stage_sets(without: list[str] | None) -> dict[str, tuple[str, ...]]:
    """Label -> stages switched off: ``all`` (none), then each given set (default: each
    stage alone). A label is the set's stages, each prefixed with '-'."""
    sets = [s.split(",") for s in without] if without else [[s] for s in STAGES]
    out: dict[str, tuple[str, ...]] = {ALL: ()}
    for names in sets:
        names = tuple(n.strip() for n in names if n.strip())
        without_stages(ExtractConfig(), *names)  # unknown names: ValueError
        out[",".join(f"-{n}" for n in names)] = names
    return out


def mesh_fingerprint(mesh: SemanticMesh) -> dict:
    """Vertex and face counts and a SHA-256 of the mesh's vertices, faces and probabilities."""
    digest = hashlib.sha256()
    for array in (mesh.vertices_m, mesh.faces, mesh.vertex_probabilities):
        digest.update(array.tobytes())
    return {"vertices": len(mesh.vertices_m), "faces": len(mesh.faces),
            "sha256": digest.hexdigest()}


def measure_building(run_dir: Path, extract: ExtractConfig,
                     sets: dict[str, tuple[str, ...]]) -> dict:
    """One building: its mesh's fingerprint and, per stage set, the result and its errors."""
    run = json.loads((run_dir / "run.json").read_text())
    truth = read_scene(run["scene_dir"], validate=False).building
    device = torch.device("cpu")
    field = load_trained_field(run_dir, device=device)
    tic = time.perf_counter()
    mesh = semantic_mesh_of_field(field, extract, device)
    row: dict = {"scene": run_dir.name, "family": truth.type if truth else None,
                 "mesh": mesh_fingerprint(mesh), "mesh_s": round(time.perf_counter() - tic, 1)}
    row["sets"] = measure_sets(field, mesh, truth, extract, sets, device=device)
    return row


def measure_sets(field, mesh: SemanticMesh, truth, extract: ExtractConfig,
                 sets: dict[str, tuple[str, ...]], *, device: torch.device) -> dict:
    """Per stage set (label -> stages off): the measured part of the result of ``mesh``
    (:func:`neural3d.extract.measure_mesh` of ``field``, a ``TrainedField`` or anything
    with its interface), its errors against ``truth`` and the seconds it took."""
    out = {}
    for label, off in sets.items():
        tic = time.perf_counter()
        result = measure_mesh(field, mesh, without_stages(extract, *off), device=device)
        errors = building_errors(result, truth)
        out[label] = {
            "result": json.loads(json.dumps({k: result.to_json_dict()[k] for k in MEASURED})),
            "errors": {k: getattr(errors, k) for k in ERRORS},
            "measure_s": round(time.perf_counter() - tic, 1)}
        print(f"  {field.scene_name} {label}: {out[label]['errors']}", file=sys.stderr,
              flush=True)
    return out


@dataclass(frozen=True)
class Column:
    """A column of the tables: ``header``, the figure ``entry[section][key]`` of a stage
    set's entry (``entry[key]`` when ``section`` is None), printed with ``digits``."""

    header: str
    section: str | None
    key: str
    digits: int


ERROR_COLUMNS = (Column("WWR %", "errors", "wwr_ape", 2),
                 Column("window %", "errors", "window_ape", 2),
                 Column("facade %", "errors", "facade_ape", 2),
                 Column("IoU", "errors", "footprint_iou", 3))
SECONDS = Column("measure s", None, "measure_s", 1)


def _value(entry: dict, column: Column) -> float | None:
    return entry[column.key] if column.section is None else entry[column.section][column.key]


def _cell(values: list[float | None], digits: int) -> str:
    known = [v for v in values if v is not None]
    return f"{statistics.mean(known):.{digits}f}" if known else "-"


def markdown(buildings: list[dict], columns: tuple[Column, ...] = ERROR_COLUMNS) -> str:
    """Per family (mean) and per building, for each stage set: the ``columns`` (by default
    WWR / window / facade APE % and footprint IoU; per building also the seconds)."""
    labels = list(buildings[0]["sets"])
    families = sorted({b["family"] for b in buildings}, key=str)
    family_rows = []
    for label in labels:
        for family in [*families, None] if len(families) > 1 else families:
            members = [b for b in buildings if family is None or b["family"] == family]
            entries = [b["sets"][label] for b in members]
            name = "all" if family is None else family
            family_rows.append([label, f"{name} ({len(members)})", *[
                _cell([_value(e, c) for e in entries], c.digits) for c in columns]])
    per_building = (*columns, SECONDS)
    building_rows = [[label, b["scene"], *[
        _cell([_value(b["sets"][label], c)], c.digits) for c in per_building]]
        for label in labels for b in buildings]
    return "\n\n".join([
        markdown_table("Per family (mean), each stage set",
                       ["stages", "family (buildings)", *(c.header for c in columns)],
                       family_rows),
        markdown_table("Per building, each stage set",
                       ["stages", "building", *(c.header for c in per_building)],
                       building_rows)])


def differences(saved: dict, buildings: list[dict]) -> tuple[list[str], int]:
    """Every difference between a saved ``--json`` file and these buildings (same mesh,
    same result for each stage set both hold), and how many stage-set results were
    compared."""
    found, compared = [], 0
    old = {b["scene"]: b for b in saved["buildings"]}
    for b in buildings:
        if b["scene"] not in old:
            continue
        if b["mesh"] != old[b["scene"]]["mesh"]:
            found.append(f"{b['scene']}: mesh {old[b['scene']]['mesh']} -> {b['mesh']}")
        for label, entry in b["sets"].items():
            before = old[b["scene"]]["sets"].get(label)
            if before is None:
                continue
            compared += 1
            found += [f"{b['scene']} {label} {path}: {a!r} -> {c!r}"
                      for path, a, c in _diff(before["result"], entry["result"], "")]
    return found, compared


def _diff(a, b, path: str):
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            yield from _diff(a.get(key), b.get(key), f"{path}.{key}")
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            yield from _diff(x, y, f"{path}[{i}]")
    elif a != b or type(a) is not type(b):
        yield path, a, b


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--results", type=Path, required=True,
                        help="a comparison's --results folder (holds neural3d_runs/)")
    parser.add_argument("--scenes", nargs="*", default=None, help="only these scene names")
    parser.add_argument("--resolution", type=int, default=ExtractConfig.resolution,
                        help="marching-cubes samples along the box's longest side (default "
                             f"{ExtractConfig.resolution}; the comparison's own for --compare-to)")
    parser.add_argument("--without", action="append", default=None, metavar="STAGE[,STAGE]",
                        help="a stage set to measure with these stages off (repeat for more "
                             f"sets; default: each stage alone). Stages: {', '.join(STAGES)}")
    parser.add_argument("--threads", type=int, default=2,
                        help="torch threads (1 beside another torch job on 2 cores)")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    parser.add_argument("--compare-to", type=Path, default=None,
                        help="a --json file to check these results against, float for float")
    args = parser.parse_args(argv)
    try:
        sets = stage_sets(args.without)
    except ValueError as exc:
        parser.error(str(exc))
    runs = trained_runs(args.results, args.scenes)
    if not runs:
        parser.error(f"no trained runs in {args.results / RUNS_FOLDER}")
    try:
        refuse_report_only(trained_scene_dirs(runs), "measure the stages")
    except ValueError as exc:
        parser.error(str(exc))
    saved = None
    if args.compare_to is not None:
        try:
            saved = json.loads(args.compare_to.read_text())
            saved["buildings"]
        except (OSError, ValueError, TypeError, KeyError) as exc:
            parser.error(f"--compare-to {args.compare_to}: not a file this bench wrote with "
                         f"--json ({exc})")
    torch.set_num_threads(args.threads)
    extract = ExtractConfig(resolution=args.resolution)
    buildings = [measure_building(run, extract, sets) for run in runs]
    print(f"code {code_version()}, marching cubes {args.resolution}, "
          f"{args.threads} thread(s)\n")
    print(markdown(buildings))
    if args.json is not None:
        write_json_atomic(args.json, {"code_version": code_version(),
                                      "resolution": args.resolution, "threads": args.threads,
                                      "buildings": buildings})
    if saved is None:
        return 0
    found, compared = differences(saved, buildings)
    print(f"\ncompared with {args.compare_to} (code {saved.get('code_version')}, marching "
          f"cubes {saved.get('resolution')}): {compared} stage-set results, "
          f"{len(found)} difference(s)")
    for line in found:
        print(f"  {line}")
    return 1 if found or compared == 0 else 0


if __name__ == "__main__":
    raise SystemExit(main())
