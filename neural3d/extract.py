"""Measure a trained semantic SDF: mesh, per-vertex semantics, WWR, footprint, result file.

``python -m neural3d.extract --run DIR`` writes, into ``DIR/extract`` (or ``--out``):

- ``mesh.ply``: marching-cubes mesh, per-vertex ``label`` (argmax of the semantic
  head, mapped to :mod:`envelope.classes` ids by the run's class names) and RGB
  from the colour network looking at the surface head-on (view direction =
  -vertex normal, so the colour does not depend on where a camera happened to be);
- ``footprint.geojson``: the ground floor's outline, the zero contour of the SDF averaged
  over ``footprint_heights_m``, its straight runs straightened
  (:mod:`neural3d.extraction.straight_walls`); it is the result's ``footprint``;
- ``footprint_widest.geojson``: the widest outline, the union of the sections from the
  lowest footprint plane to the box top (:func:`widest_outline`), straightened alike: what
  a roof plan draws (not in the result, which holds one footprint);
- ``<scene>__neural3d__train.json``: the :class:`envelope.results.MethodResult`.

Facades are the mesh's own facade groups (:mod:`neural3d.extraction.measure`), numbered
1..K, each with its outward normal and centre in world metres; nothing of the
ground truth is read. Evaluation pairs them with the truth's facades
(:mod:`metrics.score.facade_match`).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np
import torch

from envelope.atomic import write_json_atomic
from envelope.classes import NUM_CLASSES, class_id_from_name
from envelope.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from envelope.device import resolve_device
from envelope.footprint import polygon_to_geojson
from envelope.resources import check_mesh_resources
from envelope.results import FacadeEstimate, MethodResult, code_version, write_result
from envelope.semantic_ply import write_semantic_ply
from neural3d.extraction.extract_config import (
    STAGES,
    ExtractConfig,
    footprint_cell_m,
    footprint_heights_m,
    without_stages,
)
from neural3d.extraction.footprint import footprint_from_sdf, widest_outline_from_sdf
from neural3d.extraction.measure import MeshMeasurement, measure_semantic_mesh
from neural3d.extraction.meshing import (
    ColorFn,
    LabelFn,
    SdfFn,
    SemanticMesh,
    color_vertices,
    extract_mesh,
)
from neural3d.extraction.straight_walls import straighten_footprint

METHOD_NAME = "neural3d"
"""The method's name, in its result files and in :data:`neural3d.method.METHOD_NEURAL3D`."""


def field_sdf_fn(trained, device: torch.device, chunk_points: int) -> SdfFn:
    """NumPy SDF callable (N, 3) world m -> (N,) m of a ``TrainedField`` (which evaluates
    at most ``chunk_points`` points per call of its network)."""

    def sdf(points_m: np.ndarray) -> np.ndarray:
        return _numpy(trained.sdf_m(_tensor(points_m, device), chunk_points=chunk_points))

    return sdf


def field_probability_fn(trained, device: torch.device, chunk_points: int):
    """NumPy callable (N, 3) world m -> (N, NUM_CLASSES) class probabilities of a
    ``TrainedField``'s semantic head (softmax), in :mod:`envelope.classes` id order;
    classes the run does not know have probability 0."""
    class_ids = _class_ids_of(trained.class_names)

    def probabilities(points_m: np.ndarray) -> np.ndarray:
        logits = _numpy(trained.semantic_logits(_tensor(points_m, device),
                                                chunk_points=chunk_points))
        if logits.ndim != 2 or logits.shape[1] != len(class_ids):
            raise ValueError(f"semantic head gave shape {logits.shape}; expected "
                             f"(N, {len(class_ids)}) for classes {trained.class_names}")
        e = np.exp(logits - logits.max(axis=1, keepdims=True))
        out = np.zeros((len(logits), NUM_CLASSES), dtype=np.float32)
        out[:, class_ids] = e / e.sum(axis=1, keepdims=True)
        return out

    return probabilities


def field_label_fn(trained, device: torch.device, chunk_points: int) -> LabelFn:
    """NumPy class-id callable (N, 3) -> (N,) :mod:`envelope.classes` ids (semantic-head
    argmax)."""
    probabilities = field_probability_fn(trained, device, chunk_points)

    def label(points_m: np.ndarray) -> np.ndarray:
        return np.argmax(probabilities(points_m), axis=1)

    return label


def field_color_fn(trained, device: torch.device, chunk_points: int) -> ColorFn:
    """NumPy colour callable (points (N, 3), view dirs (N, 3)) -> (N, 3) in [0, 1]."""

    def color(points_m: np.ndarray, view_dirs: np.ndarray) -> np.ndarray:
        both = _tensor(np.concatenate([points_m, view_dirs], axis=1), device)
        return _numpy(trained.rgb(both[:, :3], both[:, 3:], chunk_points=chunk_points))

    return color


def semantic_mesh_of_field(trained, config: ExtractConfig, device: torch.device, *,
                           progress: bool = False) -> SemanticMesh:
    """Marching-cubes mesh of the field over its box, with vertex classes and colours."""
    sdf = field_sdf_fn(trained, device, config.chunk_points)
    vertices_m, faces = extract_mesh(
        sdf, trained.box_min_m, trained.box_max_m, resolution=config.resolution,
        chunk_points=config.chunk_points,
        min_component_area_fraction=config.min_component_area_fraction, progress=progress,
    )
    probabilities = field_probability_fn(trained, device, config.chunk_points)(
        vertices_m).astype(np.float32)
    labels = np.argmax(probabilities, axis=1).astype(np.uint8)
    rgb = color_vertices(vertices_m, faces, field_color_fn(trained, device, config.chunk_points))
    return SemanticMesh(vertices_m, faces, labels, rgb, probabilities)


def measure_field(
    trained, config: ExtractConfig, *, device: torch.device | None = None,
    progress: bool = False,
) -> tuple[MethodResult, SemanticMesh]:
    """Mesh, measure and outline a trained field; nothing is written.

    Parameters
    ----------
    trained : neural3d.field.trained.TrainedField
    config : ExtractConfig (use a modest ``resolution``, e.g. 128, while training)
    device : where to evaluate the field; None takes ``trained.device`` if it has one, else CPU.
    progress : show a progress bar over the SDF grid.

    Returns
    -------
    result : MethodResult (method "neural3d", protocol: the split the field was trained on,
        ``trained.split``); a footprint that
        cannot be found becomes ``None`` with a warning.
    mesh : SemanticMesh

    Raises
    ------
    ValueError
        If the field has no surface in its box.
    """
    start = time.perf_counter()
    device = device if device is not None else getattr(trained, "device", torch.device("cpu"))
    mesh = semantic_mesh_of_field(trained, config, device, progress=progress)
    return measure_mesh(trained, mesh, config, device=device, start_s=start), mesh


def measure_mesh(trained, mesh: SemanticMesh, config: ExtractConfig, *, device: torch.device,
                 start_s: float | None = None) -> MethodResult:
    """The result of a field's semantic mesh: the mesh measured
    (:func:`neural3d.extraction.measure.measure_semantic_mesh`) and the field's footprint.

    ``start_s``: the :func:`time.perf_counter` the result's ``wall_time_s`` counts from
    (default: now). A footprint that cannot be found becomes ``None`` with a warning.
    """
    start = time.perf_counter() if start_s is None else start_s
    m = measure_semantic_mesh(mesh.vertices_m, mesh.faces, mesh.vertex_labels,
                              config=config.measure,
                              vertex_probabilities=mesh.vertex_probabilities)
    warnings: list[str] = []
    if m.wwr is None:
        warnings.append("the mesh has no wall, window or door vertex: WWR undefined")
    facades = facade_estimates(m)
    try:
        polygon = footprint_from_sdf(
            field_sdf_fn(trained, device, config.chunk_points), trained.box_min_m,
            trained.box_max_m, heights_m=footprint_heights_m(trained.box_max_m, config),
            cell_m=footprint_cell_m(trained.box_min_m, trained.box_max_m, config),
            min_area_m2=config.footprint_min_area_m2, roofed_hole_fill=config.roofed_hole_fill,
        )
        if config.straight_walls:
            polygon = straighten_footprint(polygon, tolerance_m=config.footprint_wall_tolerance_m,
                                           min_wall_m=config.footprint_min_wall_m)
        footprint = polygon_to_geojson(polygon)
    except ValueError as exc:
        footprint = None
        warnings.append(f"no footprint: {exc}")
    return MethodResult(
        scene=trained.scene_name, method=METHOD_NAME, protocol=trained.split, wwr=m.wwr,
        window_area_m2=m.window_area_m2, facade_area_m2=m.facade_area_m2, facades=facades,
        footprint=footprint, config=asdict(config), code_version=code_version(),
        facade_identity="geometry",
        wall_time_s=time.perf_counter() - start, warnings=tuple(warnings),
    )


def extract_run(
    run_dir: Path,
    *,
    config: ExtractConfig = ExtractConfig(),
    device: torch.device,
    out_dir: Path | None = None,
    progress: bool = False,
    step: int | None = None,
) -> MethodResult:
    """Load a trained run, measure it, and write mesh.ply, footprint.geojson and the result JSON.

    ``out_dir`` defaults to ``run_dir / "extract"`` (``run_dir / "extract" /
    "step_<step>"`` for a snapshot). ``step``: measure the field as it was at
    that evaluation step (its snapshot) instead of the checkpoint's. Everything
    is computed before anything is written, and each file is written atomically.
    """
    run_dir = Path(run_dir)
    if out_dir is None:
        out_dir = run_dir / "extract" if step is None else run_dir / "extract" / f"step_{step}"
    result = measure_run(run_dir, config=config, device=device, out_dir=Path(out_dir),
                         progress=progress, step=step)
    write_result(out_dir, result)
    return result


def measure_run(run_dir: Path, *, config: ExtractConfig, device: torch.device, out_dir: Path,
                progress: bool = False, step: int | None = None) -> MethodResult:
    """:func:`extract_run` without the result file: writes ``mesh.ply`` and
    ``footprint.geojson`` into ``out_dir`` and returns the result (the comparison writes it
    once, with its provenance, into its results folder)."""
    from neural3d.field.trained import load_trained_field

    if not Path(run_dir).is_dir():
        raise ValueError(f"run folder {run_dir} does not exist")
    out_dir = Path(out_dir)
    try:
        trained = load_trained_field(run_dir, device=device, step=step)
    except RuntimeError as exc:  # torch's answer to a checkpoint of another code version
        first_line = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"cannot load the run in {run_dir}: {first_line} (was it trained "
                         "with another version of neural3d?)") from exc
    result, mesh = measure_field(trained, config, device=device, progress=progress)
    widest = widest_outline(trained, config, device=device)
    write_semantic_ply(out_dir / "mesh.ply", mesh.vertices_m, mesh.faces, mesh.vertex_labels,
                       mesh.vertex_rgb)
    for name, outline in (("footprint", result.footprint), ("footprint_widest", widest)):
        path = out_dir / f"{name}.geojson"
        if outline is not None:
            write_json_atomic(path, outline)
        else:  # an outline from an earlier extraction would contradict this one
            path.unlink(missing_ok=True)
    return result


def widest_outline(trained, config: ExtractConfig, *, device: torch.device
                   ) -> dict | None:
    """The field's widest outline as a GeoJSON Polygon (world x/y m)
    (:func:`neural3d.extraction.footprint.widest_outline_from_sdf` from the lowest footprint
    plane, ``footprint_widest_step_m`` apart, straightened as the footprint is); None where
    no plane meets the building."""
    try:
        polygon = widest_outline_from_sdf(
            field_sdf_fn(trained, device, config.chunk_points), trained.box_min_m,
            trained.box_max_m, from_height_m=min(footprint_heights_m(trained.box_max_m, config)),
            step_m=config.footprint_widest_step_m,
            cell_m=footprint_cell_m(trained.box_min_m, trained.box_max_m, config),
            min_area_m2=config.footprint_min_area_m2)
    except ValueError:
        return None
    if config.straight_walls:
        polygon = straighten_footprint(polygon, tolerance_m=config.footprint_wall_tolerance_m,
                                       min_wall_m=config.footprint_min_wall_m)
    return polygon_to_geojson(polygon)


def facade_estimates(measurement: MeshMeasurement) -> tuple[FacadeEstimate, ...]:
    """The mesh's facade groups as result entries: ids 1..K, figures, normal and centre."""
    return tuple(
        FacadeEstimate(id=f.index + 1, wwr=f.wwr, window_area_m2=f.window_area_m2,
                       facade_area_m2=f.facade_area_m2, width_m=f.width_m,
                       height_m=f.height_m, normal=f.normal, centre_m=f.centre_m)
        for f in measurement.facades
    )


def _class_ids_of(class_names) -> np.ndarray:
    ids = np.array([int(class_id_from_name(n)) for n in class_names], dtype=np.int64)
    if len(ids) == 0 or ids.max() >= NUM_CLASSES:
        raise ValueError(f"the run's class names {class_names} do not map onto dataset classes")
    return ids


def _tensor(points: np.ndarray, device: torch.device) -> torch.Tensor:
    return torch.as_tensor(points, dtype=torch.float32, device=device)


def _numpy(values: torch.Tensor) -> np.ndarray:
    return values.detach().float().cpu().numpy()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m neural3d.extract",
        description="Mesh a trained neural3d run and measure it: writes mesh.ply (per-vertex "
                    "label and colour), footprint.geojson and the result JSON "
                    "(<scene>__neural3d__train.json).",
    )
    parser.add_argument("--run", type=Path, required=True, help="trained run folder")
    parser.add_argument("--resolution", type=int, default=ExtractConfig.resolution,
                        help="marching-cubes samples along the scene box's longest side "
                             f"(default {ExtractConfig.resolution})")
    parser.add_argument("--out", type=Path, default=None,
                        help="output folder (default: RUN/extract)")
    parser.add_argument("--device", choices=("cpu", "cuda"), default="cpu",
                        help="where to evaluate the field (default cpu)")
    parser.add_argument("--step", type=int, default=None,
                        help="measure the field as it was at this evaluation step (its "
                             "snapshot in RUN/snapshots/) instead of the final one; output "
                             "to RUN/extract/step_<STEP> unless --out")
    parser.add_argument("--without", default="", metavar="STAGE[,STAGE]",
                        help="measure with these stages off (and the stages that need them; "
                             f"docs/neural3d-extract.md): {', '.join(STAGES)}")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        off = [s.strip() for s in args.without.split(",") if s.strip()]
        config = without_stages(ExtractConfig(resolution=args.resolution), *off)
        check_mesh_resources(config.resolution)
        if args.out is not None:
            check_output_folder(args.out)
        result = extract_run(args.run, config=config, device=resolve_device(args.device),
                             out_dir=args.out, progress=True, step=args.step)
        wwr = "n/a" if result.wwr is None else f"{result.wwr:.3f}"
        facade = "n/a" if result.facade_area_m2 is None else f"{result.facade_area_m2:.1f}"
        window = "n/a" if result.window_area_m2 is None else f"{result.window_area_m2:.1f}"
        print(f"{result.scene}: WWR {wwr}, facade {facade} m², window {window} m², "
              f"{result.wall_time_s:.1f} s")
        return 0

    return run_cli("neural3d.extract", body, debug=args.debug)


if __name__ == "__main__":
    exit_cli(main())
