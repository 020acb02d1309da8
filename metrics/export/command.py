"""``python -m metrics.export``: WWR per facade and per orientation, in the files energy tools read.

Reads the result files of a comparison (``--results``, as ``metrics.compare``
wrote them) and the scenes' ``building.json`` (``--data``), builds the one
table (:mod:`metrics.export.table`) and writes, into ``--out``, the formats asked
for (:mod:`metrics.export.formats`, :mod:`metrics.export.cityjson`;
``docs/export.md``). Each file is written atomically; ``cityjson/`` is replaced whole.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from dataset.benchmark_cache import (
    DefaultBenchmark,
    benchmark_of_results,
    default_results_folder,
)
from envelope.atomic import atomic_directory, write_json_atomic, write_text_atomic
from envelope.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from envelope.footprint import geojson_to_polygon
from envelope.orientation import true_north_xy_from_world
from envelope.results import MethodResult, code_version, read_result
from envelope.scenes.scene import find_scene_folders
from envelope.truth import BuildingTruth, read_building
from metrics.export.cityjson import cityjson_building
from metrics.export.formats import (
    cea_csv,
    energyplus_csv,
    facades_csv,
    geomeppy_json,
    header_lines,
    honeybee_json,
    metadata,
    orientations_csv,
    teaser_json,
)
from metrics.export.table import (
    TRUTH_METHOD,
    FacadeRow,
    North,
    building_north,
    orientation_rows,
    result_rows,
    truth_rows,
)
from metrics.score.aggregate import method_rank, protocol_rank
from metrics.score.facade_scoring import estimates_by_truth_facade

FORMATS = ("csv", "energyplus", "cea", "geomeppy", "honeybee", "teaser", "cityjson")
CITYJSON_FOLDER = "cityjson"


@dataclass(frozen=True)
class ExportInputs:
    """What an export reads: each building's truth (if any), the results, unreadable files."""

    truths: dict[str, BuildingTruth]
    results: tuple[MethodResult, ...]
    skipped: tuple[str, ...] = ()


def read_inputs(results_dir: Path, data_dir: Path | None) -> ExportInputs:
    """Every result JSON in ``results_dir`` and every scene's ``building.json`` in ``data_dir``.

    Raises
    ------
    ValueError
        If ``results_dir`` is not a folder or holds no readable result.
    """
    if not results_dir.is_dir():
        raise ValueError(f"--results {results_dir} is not a folder; run `python -m "
                         "metrics.compare` first, or name the folder of its result files")
    results, skipped = [], []
    for path in sorted(results_dir.glob("*.json")):
        try:
            results.append(read_result(path))
        except ValueError as exc:
            skipped.append(str(exc))
    if not results:
        raise ValueError(f"{results_dir} holds no readable result file (<scene>__<method>__"
                         "<protocol>.json); run `python -m metrics.compare` first")
    truths = {}
    for scene_dir in find_scene_folders(data_dir) if data_dir is not None else ():
        if (scene_dir / "building.json").is_file():
            try:
                truth = read_building(scene_dir / "building.json")
            except ValueError as exc:
                skipped.append(str(exc))
                continue
            truths[scene_dir.name] = truth
    return comparison_inputs(truths, results, skipped)


def comparison_inputs(truths: dict[str, BuildingTruth], results: Sequence[MethodResult],
                      skipped: Sequence[str] = ()) -> ExportInputs:
    """What an export reads, from what is in memory (a comparison's truths and results):
    the results ordered by scene, method and views."""
    ordered = sorted(results, key=lambda r: (r.scene, method_rank(r.method),
                                             protocol_rank(r.protocol)))
    return ExportInputs(truths, tuple(ordered), tuple(skipped))


def export(inputs: ExportInputs, out_dir: Path, formats: Sequence[str], *,
           north_deg: float | None = None, produced_by: str = "python -m metrics.export",
           progress: bool = False) -> list[Path]:
    """Write the ``formats`` (names in :data:`FORMATS`) into ``out_dir``; returns the files.

    ``north_deg`` overrides every building's north (``--north-deg``).
    """
    unknown = sorted(set(formats) - set(FORMATS))
    if unknown:
        raise ValueError(f"unknown format(s) {', '.join(unknown)}; choose from "
                         f"{', '.join(FORMATS)} or all")
    buildings = sorted(set(inputs.truths) | {r.scene for r in inputs.results})
    norths = {b: building_north(inputs.truths.get(b), north_deg) for b in buildings}
    rows = _table(inputs, buildings, norths)
    by_bin = orientation_rows(rows)
    stamp = f"produced by `{produced_by}` (envelope-bench {code_version()})"
    header, meta = header_lines(stamp, norths), metadata(stamp, norths)
    texts: dict[str, str | dict] = {}
    if "csv" in formats:
        texts["facades.csv"] = facades_csv(rows, header)
        texts["orientations.csv"] = orientations_csv(by_bin, header)
    if "energyplus" in formats:
        texts["energyplus_wwr.csv"] = energyplus_csv(by_bin, header)
    if "cea" in formats:
        texts["cea_architecture.csv"] = cea_csv(by_bin, header)
    if "geomeppy" in formats:
        blocks = {b: _block(t, norths[b]) for b, t in inputs.truths.items()}
        texts["geomeppy.json"] = geomeppy_json(by_bin, blocks, meta)
    if "honeybee" in formats:
        texts["honeybee.json"] = honeybee_json(by_bin, meta)
    if "teaser" in formats:
        texts["teaser.json"] = teaser_json(by_bin, meta)
    written = []
    for name, content in texts.items():
        path = out_dir / name
        if isinstance(content, dict):
            write_json_atomic(path, content)
        else:
            write_text_atomic(path, content)
        written.append(path)
    if "cityjson" in formats:
        written += _write_cityjson(inputs, norths, out_dir / CITYJSON_FOLDER, stamp, progress)
    return written


def _table(inputs: ExportInputs, buildings: Sequence[str], norths: dict[str, North]
           ) -> list[FacadeRow]:
    rows: list[FacadeRow] = []
    for b in buildings:
        truth = inputs.truths.get(b)
        if truth is not None:
            rows += truth_rows(truth, norths[b])
        for result in (r for r in inputs.results if r.scene == b):
            rows += result_rows(result, truth, norths[b])
    return rows


def _block(truth: BuildingTruth, north: North) -> dict | None:
    """The footprint (true-north x/y, counter-clockwise, not closed) and height for
    geomeppy's ``IDF.add_block(name, coordinates, height)``; the largest part of a
    multi-part footprint."""
    try:
        footprint = geojson_to_polygon(truth.footprint)
    except ValueError:
        return None
    parts = getattr(footprint, "geoms", [footprint])
    ring = max(parts, key=lambda p: p.area).exterior
    xy = true_north_xy_from_world(list(ring.coords)[:-1] if ring.is_ccw
                                  else list(ring.coords)[:-1][::-1], north.deg)
    return {"name": truth.id, "coordinates": [[round(float(x), 6), round(float(y), 6)]
                                              for x, y in xy],
            "height": truth.height_m}


def _write_cityjson(inputs: ExportInputs, norths: dict[str, North], folder: Path, stamp: str,
                    progress: bool) -> list[Path]:
    names: list[str] = []
    with atomic_directory(folder) as tmp:
        drawable = [t for t in inputs.truths.values() if t.facade_outlines_m]
        for truth in tqdm(drawable, desc="CityJSON", unit="building", disable=not progress):
            north = norths[truth.id]
            jobs = [(TRUTH_METHOD, "", None)] + [
                (r.method, r.protocol, estimates_by_truth_facade(r, truth))
                for r in inputs.results if r.scene == truth.id]
            for method, protocol, estimates in jobs:
                if method != TRUTH_METHOD and estimates is None:
                    continue  # a result whose facades cannot be put on the truth's
                name = "__".join(filter(None, (truth.id, method, protocol))) + ".city.json"
                try:
                    doc = cityjson_building(truth, north, method, protocol, estimates, stamp)
                except ValueError as exc:  # one building's odd wall skips its file, not all
                    print(f"CityJSON {name} skipped: {exc}", file=sys.stderr)
                    continue
                (tmp / name).write_text(json.dumps(doc, separators=(",", ":")) + "\n")
                names.append(name)
    return [folder / n for n in names]


def _parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    default = DefaultBenchmark()
    parser = argparse.ArgumentParser(
        prog="python -m metrics.export",
        description="Write each building's WWR per facade and per orientation (N/E/S/W, "
        "EnergyPlus bins), for the truth and every method's result, in the files energy "
        "modelling tools read: a per-facade and per-orientation CSV, an EnergyPlus-style WWR "
        "table, City Energy Analyst wwr_* columns, a geomeppy wwr_map, Honeybee ratios, "
        "TEASER area dicts and CityJSON LoD3 buildings. Conventions (azimuth, north, bins, "
        "gross/net areas) are printed at the top of every file; docs/export.md explains "
        "them. Without --results it exports the built-in default comparison's results "
        f"({default.folder}-results).")
    parser.add_argument("--results", type=Path, help="folder of result JSONs written by "
                        "`python -m metrics.compare` (default: the built-in default run's)")
    parser.add_argument("--data", type=Path, help="the scenes (their building.json): "
                        "orientation of 2D results, truth rows, CityJSON walls (default: "
                        "<X> for --results <X>-results, as metrics.compare names them)")
    parser.add_argument("--out", type=Path, help="output folder (default: <X>-export next "
                        "to <X>-results)")
    parser.add_argument("--format", default="all",
                        help=f"comma-separated formats out of {','.join(FORMATS)}, or all "
                        "(default)")
    parser.add_argument("--north-deg", type=float,
                        help="clockwise angle from true north to the scenes' +y axis "
                        "(EnergyPlus North Axis), for every building; default: what each "
                        "building.json states (procedural scenes: 0, +y is north)")
    add_debug_flag(parser)
    return parser.parse_args(argv)


def _paths(args: argparse.Namespace) -> tuple[Path, Path | None, Path]:
    results = args.results
    data = args.data
    if results is None:
        folder = DefaultBenchmark().folder
        results, data = default_results_folder(folder), data or folder
    guess = benchmark_of_results(results)
    if data is None and guess is not None and guess.is_dir():
        data = guess
    stem = results.name if guess is None else guess.name
    out = args.out or results.with_name(f"{stem}-export")
    return results, data, out


def main(argv: Sequence[str] | None = None) -> int:
    args = _parse_args(argv)

    def body() -> int:
        start = time.perf_counter()
        formats = FORMATS if args.format.strip() == "all" else tuple(
            f.strip() for f in args.format.split(",") if f.strip())
        results, data, out = _paths(args)
        check_output_folder(out, "--out")
        inputs = read_inputs(results, data)
        for reason in inputs.skipped:
            print(f"skipped: {reason}", file=sys.stderr)
        if data is None:
            print("note: no --data: 2D results get no orientation and no truth rows are "
                  "written (their facades are the scene's)", file=sys.stderr)
        argv_text = " ".join(sys.argv[1:] if argv is None else argv)
        written = export(inputs, out, formats, north_deg=args.north_deg,
                         produced_by=f"python -m metrics.export {argv_text}".strip(),
                         progress=True)
        print(f"wrote {len(written)} files for {len(inputs.results)} results of "
              f"{len({r.scene for r in inputs.results})} buildings to {out} "
              f"in {time.perf_counter() - start:.1f} s")
        return 0

    return run_cli("metrics.export.command", body, debug=args.debug)


if __name__ == "__main__":
    exit_cli(main())
