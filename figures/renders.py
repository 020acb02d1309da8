"""The dataset figure: one example view per family as colour, semantics, normals and depth."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from envelope.protocols import EVAL_SPLIT, IDEAL_PROTOCOL, MULTI_PROTOCOL, TRAIN_PROTOCOL
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import read_depth_m, read_labels, read_normals, read_rgb
from envelope.scenes.scene import read_scene
from envelope.truth import BuildingTruth
from figures.style import MissingInput, colour_depth, colour_labels, colour_normals
from metrics.report.plots import save_figure
from metrics.score.aggregate import family_rank

MODALITIES = ("colour", "semantics", "normals", "depth")
# an orbit view shows the whole building
PREFERRED_SPLITS = (EVAL_SPLIT, TRAIN_PROTOCOL, MULTI_PROTOCOL, IDEAL_PROTOCOL)


def example_views(
    truths: Sequence[tuple[Path, BuildingTruth]],
) -> list[tuple[str, Scene, Frame]]:
    """(family, scene, frame) of the first scene of each family that has images."""
    chosen: dict[str, tuple[Scene, Frame]] = {}
    for scene_dir, truth in truths:
        if truth.type in chosen or not (scene_dir / "transforms.json").is_file():
            continue
        try:
            scene = read_scene(scene_dir)
        except ValueError:
            continue
        frame = next((f for s in PREFERRED_SPLITS for f in scene.frames_in(s)), None)
        if frame is not None:
            chosen[truth.type] = (scene, frame)
    return [(fam, *chosen[fam]) for fam in sorted(chosen, key=family_rank)]


def view_images(scene: Scene, frame: Frame) -> dict[str, np.ndarray | None]:
    """The four display images of one frame (``None`` where the file is missing or unreadable)."""
    readers = {
        "colour": (frame.file_path, read_rgb),
        "semantics": (frame.semantic_file_path, lambda p: colour_labels(read_labels(p))),
        "normals": (frame.normal_file_path, lambda p: colour_normals(read_normals(p))),
        "depth": (frame.depth_file_path,
                  lambda p: colour_depth(read_depth_m(p, scene.depth_unit_scale_factor))),
    }
    out: dict[str, np.ndarray | None] = {}
    for name, (relative, reader) in readers.items():
        try:
            out[name] = reader(scene.path(relative)) if relative else None
        except ValueError:
            out[name] = None
    return out


def plot_example_renders(
    truths: Sequence[tuple[Path, BuildingTruth]], stem: str | Path
) -> list[Path]:
    """Grid: one row per family, columns colour / semantics / normals / depth.

    Raises
    ------
    MissingInput
        If no scene has images.
    """
    views = example_views(truths)
    if not views:
        raise MissingInput("no scene with images (transforms.json): no example renders")
    fig = Figure(figsize=(2.2 * len(MODALITIES), 2.2 * len(views)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(views), len(MODALITIES)))
    for row, (family, scene, frame) in zip(axes, views):
        images = view_images(scene, frame)
        for ax, name in zip(row, MODALITIES):
            image = images[name]
            if image is None:
                ax.text(0.5, 0.5, "missing", ha="center", va="center", transform=ax.transAxes)
            else:
                ax.imshow(image, interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            if ax is row[0]:
                ax.set_ylabel(f"{family}\n{scene.root.name}", fontsize="small")
    for ax, name in zip(axes[0], MODALITIES):
        ax.set_title(name)
    return save_figure(fig, stem)
