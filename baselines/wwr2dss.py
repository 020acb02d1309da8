"""2D-SS: the improved 2D method with scale (Szczesniak et al. 2022), on ideal or multi views.

Per view (see each module for the details):

1. isolate the target facade with the semantic mask and depth
   (:func:`baselines.facade_mask.isolate_facade_on_plane`);
2. the four corners of the quadrilateral that best encloses it
   (:func:`baselines.corners.enclosing_quadrilateral`);
3. the corners' rays meet the facade plane: facade length L, height H, alpha = L / H
   (:mod:`baselines.backproject`). If that 3D quadrilateral is not a rectangle
   (a corner angle off 90 degrees by more than ``max_corner_angle_error_deg``:
   a gable, an occluded corner), the facade's upright bounding rectangle in its
   plane replaces it;
4. a homography maps the quadrilateral onto a fronto-parallel rectangle of
   aspect alpha; all views of a run are warped with kornia in batches and the
   WWR is window / facade pixels inside the rectangle (:mod:`baselines.rectify`).

Per facade, WWR, L and H are the mean (or median) over its views; facade area
= L H, or, when the mask's outline on the plane fills less than
``min_rectangle_fill`` of L H (a gable, a stepped facade), the outline's area
(:func:`baselines.backproject.outline_area_on_plane_m2`); window area = WWR x area.
Building WWR = sum(WWR_i alpha_i) / sum(alpha_i) as in the paper, or with
``weighting="area"`` sum(WWR_i A_i) / sum(A_i).

    python -m baselines.wwr2dss --views ideal --data DIR [--weighting alpha|area] [--out DIR]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
import torch

from baselines.aggregate import COMBINES, Combine, building_result, combine_values, missing_facade
from baselines.backproject import (
    corner_angles_deg,
    corners_camera_m,
    facade_size_m,
    image_from_camera_uv,
    outline_area_on_plane_m2,
    upright_rectangle_m,
)
from baselines.cli import add_common_arguments, main_guarded, run_scenes
from baselines.corners import corners_inside_image, enclosing_quadrilateral, outer_contour_uv
from baselines.debug import colour_labels, draw_corners, write_debug_image
from baselines.facade_mask import (
    PlaneIsolationConfig,
    isolate_facade_on_plane,
    tolerance_for_depth_steps,
)
from baselines.own_facades import OwnFacadesConfig, run_2dss_own
from baselines.posed_views import finds_own_facades
from baselines.rectify import (
    OUTSIDE,
    quadrilateral_area_px,
    rectangle_size_px,
    rectified_wwr,
    rectify_labels,
)
from baselines.views import FacadeView, Protocol, ViewError, load_views
from envelope.camera import Intrinsics
from envelope.cli_errors import check_output_folder
from envelope.device import resolve_device
from envelope.method_input import MethodInput
from envelope.results import FacadeEstimate, MethodResult
from envelope.scene_record import scene_name
from envelope.scenes.images import read_rgb

METHOD = "2D-SS"  # its name, spelled only here: its Method (baselines.methods) takes it


@dataclass(frozen=True)
class Wwr2dssConfig:
    """2D-SS options.

    ``weighting``: building WWR weights, "alpha" (L/H, the paper) or "area" (L H).
    ``combine``: how the views of one facade are combined. ``rectified_scale``:
    rectified pixels per image pixel (the rectangle has about as many pixels as
    the facade's quadrilateral in the photo, times its square);
    ``max_rectified_px``: cap on the rectangle's longer side. ``batch_size``:
    views warped per kornia call. ``corner_margin_px``: a corner closer than this to
    the image border (or outside) means the facade is cut off; the view is
    skipped, unless it is a bottom corner on the bottom border whose point (depth
    and pose) lies within ``ground_contact_px`` pixels (at its depth) of the ground,
    world z = 0: that is the facade's foot on a tightly framed photo, not a cut.
    ``max_corner_angle_error_deg``: largest deviation from 90 degrees
    of a corner of the back-projected quadrilateral before the upright bounding
    rectangle replaces it. ``min_rectangle_fill``: a facade whose mask outline covers
    less than this share of its L x H rectangle is measured by the outline's area
    (0 keeps L x H always). ``seed``: RANSAC randomness. ``own_facades``: how facades are
    found and measured on views without facade ids (:mod:`baselines.own_facades`).
    """

    weighting: Literal["alpha", "area"] = "alpha"
    combine: Combine = "mean"
    isolation: PlaneIsolationConfig = field(default_factory=PlaneIsolationConfig)
    rectified_scale: float = 1.0
    max_rectified_px: int = 1024
    batch_size: int = 8
    corner_margin_px: float = 1.0
    ground_contact_px: float = 2.0
    max_corner_angle_error_deg: float = 5.0
    min_rectangle_fill: float = 0.95
    seed: int = 0
    own_facades: OwnFacadesConfig = field(default_factory=OwnFacadesConfig)

    def __post_init__(self) -> None:
        if self.weighting not in ("alpha", "area"):
            raise ValueError(f"weighting must be 'alpha' or 'area', got {self.weighting!r}")
        if self.combine not in COMBINES:
            raise ValueError(f"combine must be one of {COMBINES}, got {self.combine!r}")
        if not self.rectified_scale > 0 or self.max_rectified_px < 8 or self.batch_size < 1:
            raise ValueError("rectified_scale must be > 0, max_rectified_px >= 8 and "
                             "batch_size >= 1")
        if not 0 < self.max_corner_angle_error_deg <= 90:
            raise ValueError("max_corner_angle_error_deg must be in (0, 90]")
        if not 0 <= self.min_rectangle_fill <= 1:
            raise ValueError("min_rectangle_fill must be in [0, 1]")
        if not self.ground_contact_px >= 0:
            raise ValueError("ground_contact_px must be >= 0 (0: every border corner is a cut)")


@dataclass(frozen=True)
class ViewGeometry:
    """The geometric half of 2D-SS on one view (before rectification).

    ``mask`` (H, W) bool; ``corners_uv`` (4, 2) image corners TL, TR, BR, BL;
    ``corners_m`` (4, 3) the same in the camera frame (m); ``corners_from``
    says whether they come from the enclosing quadrilateral or the upright
    bounding rectangle; ``outline_area_m2`` the area inside the mask's outline on
    the facade plane (NaN where a pixel's ray misses the plane).
    """

    view: FacadeView
    mask: np.ndarray
    corners_uv: np.ndarray
    corners_m: np.ndarray
    length_m: float
    height_m: float
    corners_from: Literal["quadrilateral", "upright_rectangle"] = "quadrilateral"
    outline_area_m2: float = float("nan")


def measure_view_geometry(view: FacadeView, config: Wwr2dssConfig,
                          rng: np.random.Generator, *,
                          depth_relative_step: float = 0.0) -> ViewGeometry:
    """Facade mask, corners, and the facade's length and height in one view.

    ``depth_relative_step``: the scene's depth quantisation relative to the depth
    (``transforms.json`` key ``depth_relative_step``; 0 = exact to its unit), which
    widens the wall tolerance (:func:`baselines.facade_mask.tolerance_for_depth_steps`).

    Raises
    ------
    ViewError
        If the view has no facade pixels, no depth on them, corners outside the
        image, or a facade plane seen edge-on.
    """
    if view.depth_z_m is None:
        raise ViewError("2D-SS needs a depth image")
    k = view.intrinsics
    isolation = tolerance_for_depth_steps(config.isolation, view.labels, view.depth_z_m,
                                          depth_relative_step)
    mask, plane = isolate_facade_on_plane(view.labels, view.depth_z_m, k, isolation, rng)
    corners = enclosing_quadrilateral(mask)
    try:
        corners_m = corners_camera_m(corners, plane, k)
        angle_error = np.max(np.abs(corner_angles_deg(corners_m) - 90.0))
    except ViewError:  # a corner of a skewed quadrilateral beyond the plane's horizon
        angle_error = np.inf
    source = "quadrilateral"
    if angle_error > config.max_corner_angle_error_deg:
        up_camera = view.frame.world_from_camera[:3, :3].T @ np.array([0.0, 0.0, 1.0])
        corners_m = upright_rectangle_m(outer_contour_uv(mask), plane, k, up_camera)
        corners = image_from_camera_uv(corners_m, k)
        source = "upright_rectangle"
    corners_inside_image(corners, k.width, k.height, config.corner_margin_px,
                         on_ground=corners_on_ground(corners_m, view.frame.world_from_camera,
                                                     k, config.ground_contact_px))
    length, height = facade_size_m(corners_m)
    try:
        outline = outline_area_on_plane_m2(mask, plane, k)
    except ViewError:
        outline = float("nan")
    return ViewGeometry(view, mask, corners, corners_m, length, height, source, outline)


def corners_on_ground(corners_m: np.ndarray, world_from_camera: np.ndarray,
                      intrinsics: Intrinsics, contact_px: float) -> np.ndarray:
    """(4,) bool: the bottom corners (BR, BL) of (4, 3) camera-frame corners (TL, TR, BR,
    BL; OpenGL camera) whose world z is within ``contact_px`` pixel footprints (their
    depth / fy) of the ground, z = 0."""
    c = np.asarray(corners_m, dtype=np.float64)
    pose = np.asarray(world_from_camera, dtype=np.float64)
    z_world = c @ pose[2, :3] + pose[2, 3]
    footprint_m = np.abs(c[:, 2]) / intrinsics.fy
    return (np.abs(z_world) <= contact_px * footprint_m) & np.array([False, False, True, True])


def rectify_views(geometries: list[ViewGeometry], config: Wwr2dssConfig,
                  device: torch.device | str = "cpu", *, keep_images: bool = False
                  ) -> tuple[np.ndarray, list[np.ndarray | None]]:
    """WWR of each view measured in its rectified label image (batched kornia warps).

    Returns
    -------
    wwr : (N,) float, NaN where the rectangle holds no facade pixel
    rectified : N (h_i, w_i) uint8 label images cropped to their rectangles
        when ``keep_images``, else N ``None``
    """
    wwr = np.full(len(geometries), np.nan)
    images: list[np.ndarray | None] = [None] * len(geometries)
    sizes = np.array([
        rectangle_size_px(g.length_m / g.height_m,
                          quadrilateral_area_px(g.corners_uv) * config.rectified_scale**2,
                          config.max_rectified_px)
        for g in geometries]).reshape(-1, 2)
    # Batches of similar size (sorted by area) share one canvas with little padding.
    by_shape: dict[tuple[int, int], list[int]] = {}
    for i in np.argsort(sizes.prod(axis=1), kind="stable"):
        by_shape.setdefault(geometries[i].view.labels.shape, []).append(int(i))
    for idx in by_shape.values():
        for start in range(0, len(idx), config.batch_size):
            batch = idx[start:start + config.batch_size]
            rect = rectify_labels(
                np.stack([geometries[i].view.labels for i in batch]),
                np.stack([geometries[i].corners_uv for i in batch]),
                sizes[batch], device,
            )
            wwr[batch] = rectified_wwr(rect)
            if keep_images:
                for j, i in enumerate(batch):
                    images[i] = rect[j, : sizes[i, 1], : sizes[i, 0]]
    return wwr, images


def run_2dss(scene: MethodInput, protocol: Protocol, config: Wwr2dssConfig = Wwr2dssConfig(), *,
             debug_dir: Path | None = None, device: torch.device | str = "cpu") -> MethodResult:
    """2D-SS on one scene's ideal or multi views; on views without facade ids (``train``)
    it finds its own facades (:func:`baselines.own_facades.run_2dss_own`, no debug images).

    Raises
    ------
    ValueError
        If the protocol is unknown, the scene has no such views, or no view is usable.
    """
    if finds_own_facades(scene, protocol):
        return run_2dss_own(scene, protocol, config.own_facades, seed=config.seed,
                            method=METHOD, method_config=asdict(config))
    start = time.perf_counter()
    loaded = load_views(scene, protocol, depth="required")
    geometries: list[ViewGeometry] = []
    step = scene.depth_relative_step
    for n, view in enumerate(loaded.views):
        try:
            geometries.append(measure_view_geometry(
                view, config, np.random.default_rng((config.seed, n)), depth_relative_step=step))
        except ViewError as exc:
            loaded.skip(view.name, view.facade_id, str(exc))
    wwr, rectified = rectify_views(geometries, config, device, keep_images=debug_dir is not None)
    per_facade: dict[int, list[tuple[ViewGeometry, float]]] = {f: [] for f in loaded.facade_ids}
    for g, r in zip(geometries, wwr):
        if np.isnan(r):
            loaded.skip(g.view.name, g.view.facade_id, "no facade pixels in the rectified facade")
            continue
        per_facade[g.view.facade_id].append((g, float(r)))
    if debug_dir is not None:
        _write_debug(debug_dir, scene, protocol, geometries, rectified)
    facades = [
        _facade_estimate(fid, ms, config) if ms
        else missing_facade(fid, loaded.skipped.get(fid, []))
        for fid, ms in per_facade.items()
    ]
    return building_result(
        scene=scene_name(scene), method=METHOD, protocol=protocol, facades=facades,
        weighting=config.weighting, config=asdict(config),
        wall_time_s=time.perf_counter() - start, warnings=loaded.warnings,
    )


def _facade_estimate(fid: int, ms: list[tuple[ViewGeometry, float]],
                     config: Wwr2dssConfig) -> FacadeEstimate:
    wwr = combine_values([r for _, r in ms], config.combine)
    length = combine_values([g.length_m for g, _ in ms], config.combine)
    height = combine_values([g.height_m for g, _ in ms], config.combine)
    area = length * height
    outlines = [g.outline_area_m2 for g, _ in ms if np.isfinite(g.outline_area_m2)]
    if outlines:
        outline = combine_values(outlines, config.combine)
        if outline < config.min_rectangle_fill * area:  # a gable, a step: not a rectangle
            area = outline
    return FacadeEstimate(id=fid, wwr=wwr, window_area_m2=wwr * area, facade_area_m2=area,
                          width_m=length, height_m=height, views_used=len(ms))


def _write_debug(folder: Path, scene: MethodInput, protocol: str, geometries: list[ViewGeometry],
                 rectified: list[np.ndarray | None]) -> None:
    for g, rect in zip(geometries, rectified):
        v = g.view
        try:
            base = read_rgb(scene.path(v.frame.file_path))
        except ValueError:  # the RGB photo is only decoration here; the labels will do
            base = colour_labels(v.labels)
        args = (folder, v.scene, protocol, v.facade_id, v.view_index)
        write_debug_image(*args, "mask", colour_labels(v.labels, g.mask))
        write_debug_image(*args, "corners", draw_corners(base, g.corners_uv))
        if rect is not None:
            write_debug_image(*args, "rectified", colour_labels(np.where(
                rect == OUTSIDE, 0, rect)))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m baselines.wwr2dss",
        description="2D-SS baseline: facade corners from the semantic mask, back-projected "
                    "with depth to get facade length L and height H; the facade is rectified "
                    "to an L:H rectangle and its WWR measured there; building WWR weighted by "
                    "L/H (paper) or by area. Writes <scene>__2D-SS__<views>.json per scene.",
    )
    add_common_arguments(parser)
    parser.add_argument("--weighting", choices=("alpha", "area"),
                        default=Wwr2dssConfig.weighting,
                        help="building WWR weights: alpha = L/H as in the paper (default), "
                             "area = L*H")
    parser.add_argument("--combine", choices=COMBINES, default=Wwr2dssConfig.combine,
                        help="how the views of one facade are combined (default: mean)")
    parser.add_argument("--device", default="cpu", help="torch device for the warps (cpu, cuda)")
    parser.add_argument("--threads", type=int, default=None,
                        help="torch CPU threads (default: torch's choice; 1 is faster on a "
                             "machine busy with other jobs)")
    args = parser.parse_args(argv)

    def body() -> int:
        if args.debug_images is not None:
            check_output_folder(args.debug_images, "--debug-images")
        device = resolve_device(args.device)
        if args.threads is not None:
            if args.threads < 1:
                raise ValueError(f"--threads must be >= 1, got {args.threads}")
            torch.set_num_threads(args.threads)
        config = Wwr2dssConfig(weighting=args.weighting, combine=args.combine)
        return run_scenes(args.data, args.out, lambda s: run_2dss(
            s, args.views, config, debug_dir=args.debug_images, device=device))

    return main_guarded(parser.prog, body, debug=args.debug)


if __name__ == "__main__":
    raise SystemExit(main())
