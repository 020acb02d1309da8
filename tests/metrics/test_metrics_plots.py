"""The comparison's plots: PNG + PDF written, a clear ValueError when there is nothing to plot."""

import pytest

from metrics.report.plots import plot_errors_by_family, plot_iou_per_building, plot_wwr_scatter
from metrics.score.aggregate import aggregate_by_family
from metrics.score.errors import BuildingErrors, failed_building

ROWS = [
    BuildingErrors("a", "skyscraper", "2D-S", "ideal", wwr_est=0.3, wwr_true=0.25, wwr_ape=20.0),
    BuildingErrors("b", "l_shaped", "2D-SS", "multi", wwr_est=0.2, wwr_true=0.25, wwr_ape=20.0,
                   window_ape=3.0, facade_ape=1.0),
    BuildingErrors("a", "skyscraper", "neural3d", "train", wwr_est=0.25, wwr_true=0.25,
                   wwr_ape=0.0, footprint_iou=0.8),
]


@pytest.mark.slow
@pytest.mark.parametrize("plot", [plot_wwr_scatter, plot_iou_per_building, "errors"])
def test_plots_write_png_and_pdf(tmp_path, plot):
    if plot == "errors":
        paths = plot_errors_by_family(aggregate_by_family(ROWS), tmp_path / "p")
    else:
        paths = plot(ROWS, tmp_path / "p")
    assert [p.name for p in paths] == ["p.png", "p.pdf"]
    assert paths[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert paths[1].read_bytes()[:5] == b"%PDF-"
    assert b"envelope-bench " in paths[0].read_bytes()  # the code version in the metadata


def test_nothing_to_plot_is_a_value_error(tmp_path):
    failed = [failed_building("a", "skyscraper", "2D-S", "ideal", "crashed")]
    with pytest.raises(ValueError, match="every run failed"):
        plot_errors_by_family(aggregate_by_family(failed), tmp_path / "p")
    with pytest.raises(ValueError, match="no WWR estimate with ground truth"):
        plot_wwr_scatter(failed, tmp_path / "p")
    with pytest.raises(ValueError, match="no method estimated a footprint"):
        plot_iou_per_building(ROWS[:2], tmp_path / "p")
    assert not list(tmp_path.iterdir())
