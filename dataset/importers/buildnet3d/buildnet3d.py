"""The BuildNet3D-dataset Blender generator's output as a source of scenes.

``python -m dataset.generate --buildnet3d PATH --out DIR`` reads PATH with
:data:`BUILDNET3D_SOURCE` when it holds this layout (:func:`find_buildings`): the generator's
output root (``images/building{i}/meta_data.json`` for every building) or one
``images/building{i}`` folder. One scene folder ``DIR/building{i}`` per building
(:func:`import_building` writes it); the facts of the format and where they come from are in
docs/importing.md.

- labels: colour masks ``masks/building{i}/building_{i}_{v}_mask0001.png``, colours
  resolved through ``segmentation_data.json`` and the generator palette
  (:func:`envelope.scenes.labels.class_mapping`); an unknown colour is an error;
- depth: Radiance HDR z-depth in metres ``depths/…_depth0001.hdr`` (background 1e10),
  read with OpenCV, written as our 16-bit PNG;
- poses: ``camtoworld`` is Blender's ``matrix_world`` (OpenGL camera, z-up world metres),
  our convention already, despite ``camera_model: OPEN_CV``;
- facade ids per pixel: from the per-wall ground truth (``wwr_information``) with the
  depth: a wall/window pixel belongs to the wall whose plane and extent it lies on;
- split: every view is ``train``; for each wall the view that sees most of it head-on is
  also its ``ideal`` view and the next best up to five are its ``multi`` views;
- ``building.json`` from ``wwr_information`` (window area = the wall's ``wwr`` times its
  opaque ``area``; the generator's WWR divides by the opaque wall, ours by the gross facade;
  horizontal faces listed as walls are dropped);
- ``mesh.ply`` from the segmented model ``model/{i}_segmented.ply`` when it is there
  (:mod:`dataset.importers.buildnet3d.buildnet3d_model`).
"""

from __future__ import annotations

import re
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import shapely
from shapely.geometry import LineString
from shapely.ops import polygonize, unary_union

from dataset.importers.buildnet3d.buildnet3d_model import read_segmented_model
from dataset.importers.buildnet3d.meta_data_file import (
    META_DATA_FILE,
    read_json_file,
    read_meta_data_file,
)
from dataset.importers.source import NoOptions, SceneEntry, Source
from dataset.rendering.section import SNAP_GRID_M
from envelope.camera import Intrinsics, pixel_centres, unproject_depth_to_world
from envelope.classes import NO_FACADE, SemanticClass
from envelope.footprint import polygon_to_geojson
from envelope.mesh import LabelledMesh, write_labelled_ply
from envelope.protocols import IDEAL_PROTOCOL, MULTI_PROTOCOL, TRAIN_PROTOCOL
from envelope.scene_record import DEPTH_RELATIVE_STEP_KEY, Frame, Scene
from envelope.scenes.images import (
    DEPTH_MAX_UNITS,
    read_rgb,
    write_depth_m,
    write_facade_ids,
    write_labels,
    write_rgb,
)
from envelope.scenes.labels import class_mapping, read_remapped_labels
from envelope.scenes.scene import write_transforms
from envelope.truth import BuildingTruth, FacadeTruth, write_building
from envelope.wwr import ClassAreas

HDR_BACKGROUND_M = 1e9
"""HDR depths at or beyond this are background (the generator writes 1e10)."""
HDR_RELATIVE_STEP = 1.0 / 128.0
"""Radiance RGBE keeps an 8-bit mantissa in [128, 256): a depth in [2^k, 2^(k+1)) comes in
steps of 2^k / 128, at most 1/128 of the depth (recorded as the scene's
``depth_relative_step``)."""
PLANE_TOLERANCE_M = 0.3
"""A pixel lies on a wall if its point is this close to the wall's plane and extent
(windows sit in shallow reveals; the HDR depth is good to about 0.4 % of the depth)."""
MULTI_VIEWS = 5
_INCOMPLETE = ": not a complete BuildNet3D-dataset output"
HORIZONTAL_Z = 0.5
"""A listed wall whose direction has |z| above this (of its length) is a horizontal face."""


def find_buildings(path: str | Path) -> list[tuple[Path, int]]:
    """(dataset root, building index) of every BuildNet3D-dataset building under ``path``.

    Raises
    ------
    ValueError
        ``path`` holds neither layout of the generator.
    """
    found = _buildings_under(Path(path))
    if not found:
        raise ValueError(
            f"{path} holds no BuildNet3D building: expected images/building<i>/meta_data.json "
            "under it or an images/building<i> folder (BuildNet3D-dataset generator), or "
            "meta_data.json with images/ and semantic/ or semantics/ beside it, in it or in "
            "its sub-folders (BlenderProc generator or dataparser)"
        )
    return found


def _buildings_under(path: Path) -> list[tuple[Path, int]]:
    match = re.fullmatch(r"building(\d+)", path.name)
    if match and (path / META_DATA_FILE).is_file():
        return [(path.parent.parent, int(match.group(1)))]
    found = sorted(
        int(m.group(1)) for p in (path / "images").glob(f"building*/{META_DATA_FILE}")
        if (m := re.fullmatch(r"building(\d+)", p.parent.name)))
    return [(path, index) for index in found]


def read_buildnet3d(path: str | Path, options: NoOptions) -> tuple[SceneEntry, ...]:
    """One scene entry per building of this generator's layout under ``path``, named
    ``building{i}`` (:func:`find_buildings`'s errors)."""
    return tuple(SceneEntry(f"building{index}", partial(import_building, root, index))
                 for root, index in find_buildings(path))


def write_atomically(final: Path, write: Callable[[Path], object], *,
                     overwrite: bool = False) -> Path:
    """``write(tmp)`` a scene into a temporary sibling of ``final``, then rename it ``final``.

    An existing ``final`` is kept unless ``overwrite``; a failed or interrupted write
    leaves nothing behind.
    """
    if final.exists() and not overwrite:
        return final
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = final.parent / f".{final.name}.partial"
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        write(tmp)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    shutil.rmtree(final, ignore_errors=True)
    tmp.rename(final)
    return final


def import_building(root: Path, index: int, out_dir: Path) -> Scene:
    """Write building ``index`` of the generator output ``root`` as a scene in ``out_dir``.

    Raises
    ------
    ValueError
        A file is missing or malformed (the message names it).
    """
    images = root / "images" / f"building{index}"
    seg = images / "segmentation_data.json"
    _check_segmentation_colours(read_json_file(seg, _INCOMPLETE), seg)
    meta = read_meta_data_file(images / META_DATA_FILE)
    walls = read_walls(root / "wwr_information" / f"building{index}_wwr.json")
    views = []
    for fr in meta.frames:
        stem = Path(fr.rgb_path).stem  # building_{i}_{v}
        intr, pose = meta.intrinsics(fr), fr.camera_to_world
        labels = read_remapped_labels(root / "masks" / f"building{index}" /
                                      f"{stem}_mask0001.png", class_mapping("generator"))
        depth = read_hdr_depth_m(root / "depths" / f"building{index}" / f"{stem}_depth0001.hdr")
        views.append(ImportedView(stem, images / f"{stem}.png", intr, pose, TRAIN_PROTOCOL, labels,
                                  depth, facade_ids_from_walls(labels, depth, intr, pose, walls)))
    scene = write_scene_views(out_dir, views, [w["normal"] for w in walls],
                              {"source": "BuildNet3D-dataset", "source_building": index,
                               DEPTH_RELATIVE_STEP_KEY: HDR_RELATIVE_STEP})
    model_path = root / "model" / f"{index}_segmented.ply"
    model = read_segmented_model(model_path, walls) if model_path.is_file() else None
    write_building(out_dir / "building.json", building_truth(walls, f"building{index}", model))
    if model is not None:
        write_labelled_ply(out_dir / "mesh.ply", model)
    return scene


@dataclass(frozen=True)
class ImportedView:
    """One official view, read: labels (H, W) uint8 ours, depth (H, W) float z-depth m
    (0 = none), facade ids (H, W) int32 (0 = none); ``split`` train or eval."""

    stem: str
    rgb_path: Path
    intrinsics: Intrinsics
    world_from_camera: np.ndarray
    split: str
    labels: np.ndarray
    depth_z_m: np.ndarray
    facade_ids: np.ndarray


def write_scene_views(out_dir: Path, views: list[ImportedView], normals: list[np.ndarray],
                      extra: dict[str, Any]) -> Scene:
    """Write imported views as a scene in ``out_dir``; return it (without truth).

    Every view is a frame of its split; for each facade ``f`` (``normals[f - 1]`` its
    outward unit normal) the view that sees most of it head-on (pixels times the cosine
    between the camera's back axis and the normal) is also its ``ideal`` view and the next
    :data:`MULTI_VIEWS` its ``multi`` views.
    """
    for sub in ("images", "semantics", "depth", "instances"):
        (out_dir / sub).mkdir(parents=True, exist_ok=True)
    unit = _depth_unit_m(max(float(v.depth_z_m.max(initial=0.0)) for v in views))
    frames: list[Frame] = []
    for v in views:
        write_rgb(out_dir / "images" / f"{v.stem}.png", read_rgb(v.rgb_path))
        write_labels(out_dir / "semantics" / f"{v.stem}.png", v.labels)
        write_depth_m(out_dir / "depth" / f"{v.stem}.png", v.depth_z_m, unit)
        write_facade_ids(out_dir / "instances" / f"{v.stem}.png", v.facade_ids)
        frames.append(_frame(v.stem, v.intrinsics, v.world_from_camera, v.split, None))
    score = np.array([[np.count_nonzero(v.facade_ids == f + 1)
                       * max(0.0, float(v.world_from_camera[:3, 2] @ n))
                       for f, n in enumerate(normals)] for v in views]).reshape(len(views), -1)
    for f in range(score.shape[1]):
        order = [i for i in np.argsort(-score[:, f], kind="stable") if score[i, f] > 0]
        for rank, i in enumerate(order[: 1 + MULTI_VIEWS]):
            v = views[i]
            frames.append(_frame(v.stem, v.intrinsics, v.world_from_camera,
                                 IDEAL_PROTOCOL if rank == 0 else MULTI_PROTOCOL, f + 1))
    scene = Scene(root=out_dir, frames=tuple(frames), depth_unit_scale_factor=unit, extra=extra)
    write_transforms(out_dir, scene)
    return scene


def read_walls(path: Path) -> list[dict[str, Any]]:
    """The per-wall ground truth of a ``building{i}_wwr.json``, outward normals added.

    Each wall: ``center`` (3,), ``normal`` (3,) outward unit, ``domain`` (3, 2) min/max
    x/y/z, ``wwr`` (window / opaque wall), ``area`` (opaque wall, m²); plus ``overall_wwr``.
    """
    data = read_json_file(path, _INCOMPLETE)
    walls = []
    for key, w in data.items():
        if key == "overall":
            continue
        try:
            walls.append({"center": np.asarray(w["center"], float),
                          "direction": np.asarray(w["direction"], float),
                          "domain": np.asarray(w["domain"], float).reshape(3, 2),
                          "wwr": float(w["wwr"]), "area": float(w["area"])})
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{path}: wall {key} is malformed: {exc!r}") from None
    # The generator drops horizontal faces by comparing their normal's z with +-1 exactly
    # (segmented_3D_model.py:372-376): one that rounding lets through is listed as a wall.
    walls = [w for w in walls
             if abs(w["direction"][2]) <= HORIZONTAL_Z * np.linalg.norm(w["direction"])]
    if not walls:
        raise ValueError(f"{path} lists no vertical walls")
    centre = np.mean([w["center"] for w in walls], axis=0)
    for w in walls:
        n = w["direction"] / np.linalg.norm(w["direction"])
        # The generator's direction is a face normal whose sign varies; ours points out.
        w["normal"] = n if float((w["center"] - centre)[:2] @ n[:2]) >= 0 else -n
        w["overall_wwr"] = float(data.get("overall", {}).get("wwr", np.nan))
    return walls


def read_hdr_depth_m(path: Path) -> np.ndarray:
    """(H, W) float32 z-depth in metres of a Radiance HDR depth image (0 = background)."""
    if not path.is_file():
        raise ValueError(f"depth image {path} does not exist")
    img = cv2.imread(str(path), cv2.IMREAD_ANYDEPTH | cv2.IMREAD_ANYCOLOR)
    if img is None:
        raise ValueError(f"{path} is not a readable Radiance HDR image")
    depth = (img[..., 0] if img.ndim == 3 else img).astype(np.float32)
    depth[~np.isfinite(depth) | (depth >= HDR_BACKGROUND_M)] = 0.0
    return depth


def facade_ids_from_walls(labels: np.ndarray, depth_z_m: np.ndarray, intrinsics: Intrinsics,
                          world_from_camera: np.ndarray,
                          walls: list[dict[str, Any]]) -> np.ndarray:
    """(H, W) int32 facade id (wall index + 1, 0 = none) of every wall/window pixel.

    A pixel's point (from its depth) belongs to the wall whose plane is nearest, if it is
    within :data:`PLANE_TOLERANCE_M` of that plane and of the wall's extent.
    """
    facade = np.isin(labels, [SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.DOOR])
    facade &= depth_z_m > 0
    out = np.full(labels.shape, NO_FACADE, dtype=np.int32)
    if not facade.any():
        return out
    uv = pixel_centres(intrinsics)[facade]
    points = unproject_depth_to_world(uv, depth_z_m[facade], intrinsics, world_from_camera)
    best = np.full(len(points), np.inf)
    ids = np.zeros(len(points), dtype=np.int32)
    t = PLANE_TOLERANCE_M
    for w, wall in enumerate(walls):
        dist = np.abs((points - wall["center"]) @ wall["normal"])
        lo, hi = wall["domain"][:, 0] - t, wall["domain"][:, 1] + t
        ok = (dist < t) & np.all((points >= lo) & (points <= hi), axis=1) & (dist < best)
        best[ok], ids[ok] = dist[ok], w + 1
    out[facade] = ids
    return out


def building_truth(walls: list[dict[str, Any]], building_id: str,
                   model: LabelledMesh | None = None) -> BuildingTruth:
    """Our ``building.json`` truth from the generator's walls (no doors: it has none).

    A wall's gross facade is its rectangle, the horizontal extent of its ``domain`` times
    its height: the generator's wall faces are whole rectangles with the window modules
    set through them (its ``area`` is that rectangle, and its ``wwr`` window / gross like
    ours); a wall cut around its windows has the same rectangle. Its window area is
    ``wwr * area``, or, with the segmented ``model``, the area of the window faces on that
    wall (:func:`dataset.importers.buildnet3d.buildnet3d_model.facade_ids_of_faces`): the
    generator's
    per-wall list can count a window on two walls (one that reaches across a neighbouring
    wall's plane), its overall WWR counts it once, and so does the model. Opaque wall =
    gross - window.
    """
    model_window = None
    if model is not None:
        on_window = model.face_label == SemanticClass.WINDOW
        model_window = np.bincount(model.face_facade[on_window],
                                   weights=model.face_areas_m2()[on_window],
                                   minlength=len(walls) + 1)
    facades = []
    for w, wall in enumerate(walls):
        d = wall["domain"]
        width = float(np.hypot(d[0, 1] - d[0, 0], d[1, 1] - d[1, 0]))
        height = float(d[2, 1] - d[2, 0])
        window = (wall["wwr"] * wall["area"] if model_window is None
                  else float(model_window[w + 1]))
        areas = ClassAreas(window, max(0.0, width * height - window), 0.0)
        facades.append(FacadeTruth(
            id=w + 1, normal=tuple(float(x) for x in wall["normal"]), width_m=width,
            height_m=height, window_area_m2=window, wall_area_m2=areas.wall_m2,
            door_area_m2=0.0, facade_area_m2=areas.gross_m2, wwr=areas.wwr))
    window = sum(f.window_area_m2 for f in facades)
    wall_area = sum(f.wall_area_m2 for f in facades)
    areas = ClassAreas(window, wall_area, 0.0)
    z0 = min(float(w["domain"][2, 0]) for w in walls)
    height = max(float(w["domain"][2, 1]) for w in walls) - z0
    footprint = _footprint(walls)
    return BuildingTruth(
        id=building_id, type="imported", floors=max(1, round(height / 3.0)), height_m=height,
        window_area_m2=window, facade_area_m2=areas.gross_m2, wall_area_m2=wall_area,
        door_area_m2=0.0, wwr=areas.wwr, footprint=polygon_to_geojson(footprint),
        footprint_area_m2=float(footprint.area), facades=tuple(facades),
        extra={"source": "BuildNet3D-dataset wwr_information"
               + ("" if model is None else " and the segmented model's window faces"),
               "generator_wall_window_area_m2": [w["wwr"] * w["area"] for w in walls],
               "generator_overall_wwr": walls[0]["overall_wwr"],
               "floors_estimated_from_height_3m": True, "ground_z_m": z0})


def _footprint(walls: list[dict[str, Any]]):
    """The footprint polygon closed by the walls' ground lines (the largest face)."""
    lines = []
    for wall in walls:
        d, n = wall["domain"], wall["normal"]
        along = np.array([-n[1], n[0]])
        c = wall["center"][:2]
        half = 0.5 * float(np.hypot(d[0, 1] - d[0, 0], d[1, 1] - d[1, 0]))
        lines.append(LineString([c - half * along, c + half * along]))
    # The generator's coordinates are float32 (-1.4999998807907104 for -1.5): snap the ends.
    faces = list(polygonize(shapely.set_precision(unary_union(lines), SNAP_GRID_M)))
    if not faces:
        raise ValueError("the walls of wwr_information do not close a footprint")
    return unary_union(faces)


def _check_segmentation_colours(seg: dict[str, Any], path: Path) -> None:
    palette = {tuple(c) for c in class_mapping("generator").colours or ()}
    unknown = [v for v in seg.values() if tuple(int(x) for x in v) not in palette]
    if unknown:
        raise ValueError(
            f"{path} lists colours {unknown} that the generator's palette "
            f"{sorted(palette)} does not define; the data was made with another "
            "segmentation_config.json"
        )


def _frame(stem: str, intr: Intrinsics, pose: np.ndarray, split: str,
           facade_id: int | None) -> Frame:
    return Frame(file_path=f"images/{stem}.png", world_from_camera=pose, intrinsics=intr,
                 split=split, facade_id=facade_id, depth_file_path=f"depth/{stem}.png",
                 semantic_file_path=f"semantics/{stem}.png",
                 instance_file_path=f"instances/{stem}.png")


def _depth_unit_m(max_depth_m: float) -> float:
    """1 mm, or the next 1-2-5 step that holds ``max_depth_m`` in 16 bits."""
    unit = 0.001
    while max_depth_m / unit > DEPTH_MAX_UNITS:
        unit *= 2.0 if str(unit)[0] in "15" else 2.5
    return unit


BUILDNET3D_SOURCE = Source(
    name="buildnet3d-blender", flag="--buildnet3d",
    help="the official BuildNet3D-dataset Blender generator's output root or one "
         "images/building<i> folder: one scene per building, as rendered",
    detect=lambda path: bool(_buildings_under(Path(path))), read=read_buildnet3d,
)
