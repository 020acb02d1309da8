"""The 2D-SS pipeline on one facade: facade mask, fitted corners, rectified facade.

Reads the debug images that ``metrics.compare`` keeps in its output folder
(``2dss_pipeline/<scene>__<protocol>__f<facade>__v<k>__{mask,corners,rectified}.png``).
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from envelope.scenes.images import read_rgb
from figures.style import MissingInput
from metrics.report.plots import save_figure

STEPS = (("mask", "facade mask"), ("corners", "corners"), ("rectified", "rectified facade"))


def plot_2dss_pipeline(folder: str | Path, stem: str | Path) -> list[Path]:
    """Three panels from the first complete set of debug images in ``folder``.

    Raises
    ------
    MissingInput
        If the folder has no complete mask / corners / rectified set.
    """
    folder = Path(folder)
    masks = sorted(folder.glob("*__mask.png")) if folder.is_dir() else []
    for mask in masks:
        base = mask.name[: -len("__mask.png")]
        paths = [folder / f"{base}__{kind}.png" for kind, _ in STEPS]
        if all(p.is_file() for p in paths):
            break
    else:
        raise MissingInput(
            f"no 2D-SS debug images in {folder}; run `python -m metrics.compare` with 2D-SS"
        )
    images = [read_rgb(p) for p in paths]
    widths = [img.shape[1] / img.shape[0] for img in images]
    fig = Figure(figsize=(2.6 * sum(widths), 2.9), layout="constrained")
    axes = fig.subplots(1, len(STEPS), width_ratios=widths)
    for ax, img, (_, title) in zip(axes, images, STEPS):
        ax.imshow(img, interpolation="nearest")
        ax.set_title(title, fontsize="small")
        ax.set_xticks([])
        ax.set_yticks([])
    scene, protocol, facade, view = base.rsplit("__", 3)
    fig.suptitle(f"2D-SS on {scene}, facade {facade[1:]}, {protocol} view {view[1:]}",
                 fontsize="small")
    return save_figure(fig, stem)
