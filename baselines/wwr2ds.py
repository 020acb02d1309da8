"""2D-S: window-to-wall ratio from semantic masks, after Szczesniak et al. (2022).

Per view, WWR = window pixels / facade (wall + window + door) pixels of the
target facade (:func:`baselines.facade_mask.isolate_facade_2ds`). Per facade,
the mean over its views; for the building, the unweighted mean over facades.

Areas use one scale per view, the pixel footprint (z / f)² at the facade's
median depth: a pixel's true footprint varies with depth and obliquity, so
oblique views and tall facades are mis-scaled. This is the inconsistent
scaling the paper criticises, kept on purpose; depth is used for nothing else.

    python -m baselines.wwr2ds --views ideal --data DIR [--out DIR] [--debug-images DIR]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from baselines.aggregate import COMBINES, Combine, building_result, combine_values, missing_facade
from baselines.cli import add_common_arguments, main_guarded, run_scenes
from baselines.debug import colour_labels, write_debug_image
from baselines.facade_mask import facade_class_mask, isolate_facade_2ds
from baselines.own_facades import OwnFacadesConfig, run_2ds_own
from baselines.posed_views import finds_own_facades
from baselines.views import FacadeView, Protocol, ViewError, load_views
from envelope.classes import SemanticClass
from envelope.cli_errors import check_output_folder
from envelope.method_input import MethodInput
from envelope.results import FacadeEstimate, MethodResult
from envelope.scene_record import scene_name
from envelope.wwr import wwr_from_areas

METHOD = "2D-S"  # its name, spelled only here: its Method (baselines.methods) takes it


@dataclass(frozen=True)
class Wwr2dsConfig:
    """2D-S options.

    ``isolation``: "centre_component" keeps the facade component at the image
    centre; "all" counts every facade pixel of the view. ``combine``: how the
    views of one facade are combined ("mean" as in the paper, or "median"). ``own_facades``:
    how facades are found on views without facade ids (:mod:`baselines.own_facades`).
    """

    isolation: Literal["centre_component", "all"] = "centre_component"
    combine: Combine = "mean"
    own_facades: OwnFacadesConfig = field(default_factory=OwnFacadesConfig)

    def __post_init__(self) -> None:
        if self.isolation not in ("centre_component", "all"):
            raise ValueError(f"isolation must be 'centre_component' or 'all', "
                             f"got {self.isolation!r}")
        if self.combine not in COMBINES:
            raise ValueError(f"combine must be one of {COMBINES}, got {self.combine!r}")


@dataclass(frozen=True)
class ViewPixels2ds:
    """2D-S figures of one view; areas are ``None`` without depth."""

    wwr: float
    window_px: int
    facade_px: int
    pixel_area_m2: float | None
    mask: np.ndarray  # (H, W) bool

    @property
    def window_area_m2(self) -> float | None:
        return None if self.pixel_area_m2 is None else self.window_px * self.pixel_area_m2

    @property
    def facade_area_m2(self) -> float | None:
        return None if self.pixel_area_m2 is None else self.facade_px * self.pixel_area_m2


def measure_view_2ds(view: FacadeView, config: Wwr2dsConfig) -> tuple[ViewPixels2ds, str | None]:
    """2D-S on one view, plus a warning when the view has no area scale.

    Raises
    ------
    ViewError
        If the view has no facade pixels.
    """
    labels = view.labels
    if config.isolation == "centre_component":
        mask = isolate_facade_2ds(labels)
    else:
        mask = facade_class_mask(labels)
        if not mask.any():
            raise ViewError("no facade pixels (wall, window or door) in the semantic mask")
    window_px = int(np.count_nonzero(mask & (labels == SemanticClass.WINDOW)))
    door_px = int(np.count_nonzero(mask & (labels == SemanticClass.DOOR)))
    facade_px = int(np.count_nonzero(mask))
    pixel_area, warning = None, None
    if view.depth_z_m is not None:
        d = view.depth_z_m[mask]
        d = d[d > 0]
        if len(d):
            k = view.intrinsics
            pixel_area = float(np.median(d)) ** 2 / (k.fx * k.fy)
        else:
            warning = f"{view.name}: no valid depth on the facade, so no area scale"
    wwr = wwr_from_areas(window_px, facade_px - window_px - door_px, door_px)
    return ViewPixels2ds(wwr, window_px, facade_px, pixel_area, mask), warning


def run_2ds(scene: MethodInput, protocol: Protocol, config: Wwr2dsConfig = Wwr2dsConfig(), *,
            debug_dir: Path | None = None) -> MethodResult:
    """2D-S on one scene's ideal or multi views; on views without facade ids (``train``) it
    groups the views into its own facades (:func:`baselines.own_facades.run_2ds_own`).

    Raises
    ------
    ValueError
        If the protocol is unknown, the scene has no such views, or no view is usable.
    """
    if finds_own_facades(scene, protocol):
        return run_2ds_own(scene, protocol, config.own_facades, combine=config.combine,
                           method=METHOD, method_config=asdict(config))
    start = time.perf_counter()
    loaded = load_views(scene, protocol, depth="optional")
    per_facade: dict[int, list[ViewPixels2ds]] = {fid: [] for fid in loaded.facade_ids}
    for view in loaded.views:
        try:
            m, warning = measure_view_2ds(view, config)
        except ViewError as exc:
            loaded.skip(view.name, view.facade_id, str(exc))
            continue
        if warning:
            loaded.warnings.append(warning)
        per_facade[view.facade_id].append(m)
        if debug_dir is not None:
            write_debug_image(debug_dir, view.scene, protocol, view.facade_id, view.view_index,
                              "mask", colour_labels(view.labels, m.mask))
    facades = [
        _facade_estimate(fid, ms, config) if ms
        else missing_facade(fid, loaded.skipped.get(fid, []))
        for fid, ms in per_facade.items()
    ]
    return building_result(
        scene=scene_name(scene), method=METHOD, protocol=protocol, facades=facades,
        weighting="equal", config=asdict(config), wall_time_s=time.perf_counter() - start,
        warnings=loaded.warnings,
    )


def _facade_estimate(fid: int, ms: list[ViewPixels2ds], config: Wwr2dsConfig) -> FacadeEstimate:
    return FacadeEstimate(
        id=fid,
        wwr=combine_values([m.wwr for m in ms], config.combine),
        window_area_m2=combine_values([m.window_area_m2 for m in ms], config.combine),
        facade_area_m2=combine_values([m.facade_area_m2 for m in ms], config.combine),
        views_used=len(ms),
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m baselines.wwr2ds",
        description="2D-S baseline: per-view window/facade pixel ratio of the semantic mask, "
                    "mean per facade, unweighted mean over facades; areas from one pixel "
                    "footprint (z/f)^2 per view. Writes <scene>__2D-S__<views>.json per scene.",
    )
    add_common_arguments(parser)
    parser.add_argument("--isolation", choices=("centre_component", "all"),
                        default=Wwr2dsConfig.isolation,
                        help="which facade pixels count: the component at the image centre "
                             "(default) or all of them")
    parser.add_argument("--combine", choices=COMBINES, default=Wwr2dsConfig.combine,
                        help="how the views of one facade are combined (default: mean)")
    args = parser.parse_args(argv)

    def body() -> int:
        if args.debug_images is not None:
            check_output_folder(args.debug_images, "--debug-images")
        config = Wwr2dsConfig(isolation=args.isolation, combine=args.combine)
        return run_scenes(args.data, args.out, lambda s: run_2ds(
            s, args.views, config, debug_dir=args.debug_images))

    return main_guarded(parser.prog, body, debug=args.debug)


if __name__ == "__main__":
    raise SystemExit(main())
