"""One building's section of the report: its truth, each method's estimates and errors, the
first ideal view and the kept pipeline images, the footprints and the semantic meshes.

The rows come in memory; the scene (``data/<scene>``: its ``building.json`` and first ideal
view) and what the comparison left in its output folder (``footprints/``,
``2dss_pipeline/``, ``<method>_runs.json``) are read here, where the page embeds them.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from markupsafe import Markup

from envelope.footprint import geojson_to_polygon
from envelope.protocols import IDEAL_PROTOCOL
from envelope.semantic_ply import read_semantic_ply
from metrics.report.html_sections import footprint_svg, mesh_figure_json, number_cell, png_base64
from metrics.report.mesh_decimate import decimate_vertex_clustering
from metrics.report.report_data import FOOTPRINTS_FOLDER, PIPELINE_FOLDER
from metrics.report.templating import render
from metrics.run.mesh_pointers import MeshRun, read_mesh_pointers
from metrics.score.aggregate import method_rank, protocol_rank
from metrics.score.errors import NO_TRUTH_FAMILY, BuildingErrors

MAX_MESH_FACES = 20_000  # plotly's mesh3d stays smooth in a browser well beyond this
COLUMNS = ("Method", "Views", "Status", "WWR", "WWR error (%)", "Window (m²)",
           "Window error (%)", "Facade (m²)", "Facade error (%)", "Footprint IoU", "Why / marks")
ESTIMATE_COLUMNS = ("Method", "Views", "Status", "WWR", "Window (m²)", "Facade (m²)",
                    "Why / marks")  # a building without truth: nothing to score


def building_section(scene: str, rows: Sequence[BuildingErrors], data: Path,
                     out_dir: Path) -> Markup:
    """One building: truth, each method's estimates and errors, images, footprints, mesh;
    a building without truth (family :data:`~metrics.score.errors.NO_TRUTH_FAMILY`): says so,
    and its estimates without error columns."""
    scene_dir = data / scene if (data / scene).is_dir() else data
    first = rows[0]
    scored = first.family != NO_TRUTH_FAMILY
    truth = ([("family", first.family),
              ("WWR", number_cell(first.wwr_true, ".4f")[0]),
              ("window area (m²)", number_cell(first.window_true_m2, ".2f")[0]),
              ("facade area (m²)", number_cell(first.facade_true_m2, ".2f")[0])] if scored
             else [("ground truth", "none (no building.json): estimates only, no errors")])
    ordered = sorted(rows, key=lambda r: (method_rank(r.method), protocol_rank(r.protocol)))
    cells = []
    for r in ordered:
        note = "; ".join(x for x in (r.reason, r.marks) if x)
        errors = ([number_cell(r.wwr_ape, ".2f"), number_cell(r.window_ape, ".2f"),
                   number_cell(r.facade_ape, ".2f")] if scored else [])
        row = [(r.method, r.method), (r.protocol, r.protocol), (r.status, r.status),
               number_cell(r.wwr_est, ".4f"), *errors[:1], number_cell(r.window_est_m2, ".2f"),
               *errors[1:2], number_cell(r.facade_est_m2, ".2f"), *errors[2:]]
        if scored:
            row.append(number_cell(r.footprint_iou, ".3f"))
        cells.append([*row, (note, note)])
    footprints, footprints_error = _footprints(scene, scene_dir, out_dir)
    return render("building.html.j2", scene=scene, truth=truth,
                  columns=COLUMNS if scored else ESTIMATE_COLUMNS, rows=cells,
                  attrs=[{"status": r.status} for r in ordered], footprints=footprints,
                  footprints_error=footprints_error, images=_images(scene, scene_dir, out_dir),
                  meshes=[_mesh(run, i) for i, run in enumerate(
                      r for r in read_mesh_pointers(out_dir) if r.scene == scene)])


def _images(scene: str, scene_dir: Path, out_dir: Path) -> list[dict[str, str]]:
    """The first ideal view's image and the 2D-SS pipeline images kept for this scene."""
    out = []
    transforms = scene_dir / "transforms.json"
    if transforms.is_file():
        frames = json.loads(transforms.read_text()).get("frames", [])
        ideal = [f for f in frames if f.get("split") == IDEAL_PROTOCOL] or frames[:1]
        if ideal and (scene_dir / ideal[0]["file_path"]).is_file():
            out.append({"png_base64": png_base64(scene_dir / ideal[0]["file_path"]),
                        "caption": "render (first ideal view)"})
    for png in sorted((out_dir / PIPELINE_FOLDER).glob(f"{scene}__*.png")):
        out.append({"png_base64": png_base64(png),
                    "caption": "2D-SS: " + png.stem.split("__")[-1]})
    return out


def _footprints(scene: str, scene_dir: Path, out_dir: Path) -> tuple[Markup | None, str | None]:
    """The footprints' SVG, or why they could not be read."""
    truth = None
    building = scene_dir / "building.json"
    try:
        if building.is_file():
            truth = geojson_to_polygon(json.loads(building.read_text())["footprint"])
        estimates = [(p.stem.split("__", 1)[1].replace("__", " "),
                      geojson_to_polygon(json.loads(p.read_text())))
                     for p in sorted((out_dir / FOOTPRINTS_FOLDER).glob(f"{scene}__*.geojson"))]
    except (ValueError, KeyError) as exc:
        return None, str(exc)
    return footprint_svg(truth, estimates), None


def _mesh(run: MeshRun, index: int) -> dict[str, str | None]:
    """A semantic mesh (decimated), drawn when the building is opened."""
    try:
        vertices, faces, labels, _ = read_semantic_ply(run.mesh)
    except ValueError as exc:
        return {"method": run.method, "error": str(exc)}
    n_faces = len(faces)
    vertices, faces, labels = decimate_vertex_clustering(vertices, faces, labels, MAX_MESH_FACES)
    title = (f"{run.method} semantic mesh, {run.protocol} views "
             f"({len(faces)} of {n_faces} faces)")
    return {"method": run.method, "error": None,
            "chart_id": f"mesh-{run.scene}" + (f"-{index}" if index else ""),
            "figure_json": mesh_figure_json(vertices, faces, labels, title)}
