"""What a comparison writes besides its tables: plots, footprints, one facade's pipeline
images and ``report.html``. Each replaces its folder or file whole, and none of them can fail
the comparison: a plot or image that cannot be made is skipped with a message.
"""

from __future__ import annotations

import shutil
import sys
from collections.abc import Sequence
from pathlib import Path

from envelope.atomic import atomic_directory, write_json_atomic
from metrics.report.html_report import write_report
from metrics.report.plots import plot_errors_by_family, plot_iou_per_building, plot_wwr_scatter
from metrics.report.report_data import ReportData
from metrics.run.runner import MethodSpec, Outcome


def write_html_report(data: ReportData) -> None:
    """``report.html`` of a comparison, in its output folder; a failure warns, the comparison
    stands."""
    try:
        write_report(data)
    except Exception as exc:  # the page is a view of the outputs, not one of them
        print(f"warning: report.html not written: {type(exc).__name__}: {exc}", file=sys.stderr)


def write_plots(groups, rows, folder: Path) -> None:
    """Replace ``folder`` with this comparison's plots (a skipped plot leaves no stale file)."""
    with atomic_directory(folder) as tmp:
        for plot, data, stem in (
            (plot_errors_by_family, groups, "errors_by_family"),
            (plot_wwr_scatter, rows, "wwr_scatter"),
            (plot_iou_per_building, rows, "iou_per_building"),
        ):
            try:
                plot(data, tmp / stem)
            except ValueError as exc:
                print(f"plot {stem} skipped: {exc}", file=sys.stderr)


def write_footprints(outcomes: Sequence[Outcome], folder: Path) -> None:
    """Replace ``folder`` with the estimated footprints of this comparison's results."""
    with atomic_directory(folder) as tmp:
        for o in outcomes:
            if o.result is not None and o.result.footprint is not None:
                write_json_atomic(tmp / f"{o.scene}__{o.method}__{o.protocol}.geojson",
                                  o.result.footprint)


def keep_pipeline_images(scene_dirs: Sequence[Path], spec: MethodSpec, folder: Path) -> None:
    """Keep ``spec``'s debug images (2D-SS's) of one facade (the first view of the first
    scene's facade 1)."""
    if folder.is_dir() and any(folder.glob("*.png")):
        return
    assert spec.debug_images is not None
    protocol = spec.protocols[0]
    for scene_dir in scene_dirs:
        if not (scene_dir / "transforms.json").is_file():
            continue
        tmp = folder.with_name(f".{folder.name}.tmp")
        shutil.rmtree(tmp, ignore_errors=True)
        try:
            spec.debug_images(scene_dir, protocol, tmp)
        except Exception as exc:  # the figure is optional; the comparison is not
            print(f"{spec.name} pipeline images skipped: {type(exc).__name__}: {exc}",
                  file=sys.stderr)
            shutil.rmtree(tmp, ignore_errors=True)
            return
        images = sorted(tmp.glob("*.png"))
        if images:
            # One facade: the images sharing the first file's <scene>__<protocol>__f<id>__v<k> stem.
            stem = images[0].name.rsplit("__", 1)[0]
            folder.mkdir(parents=True, exist_ok=True)
            for image in images:
                if image.name.startswith(stem + "__"):
                    shutil.copy2(image, folder / image.name)
        shutil.rmtree(tmp, ignore_errors=True)
        return
