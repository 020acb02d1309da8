"""report.html: built from a real comparison and checked in headless Chromium (network blocked).

The comparison runs 2D-S, 2D-SS and a 20-step neural3d on one tiny scene, so
a neural3d mesh exists. The browser part needs Debian's ``chromium`` and the
``playwright`` client (scripts/setup.sh installs both); it skips without them
unless ``CI`` is set, where it fails instead.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

from metrics.compare import main as compare_main
from metrics.report.html_report import REPORT_FILE, main
from metrics.report.mesh_decimate import decimate_vertex_clustering
from metrics.report.report import TABLE2_NAME, TABLE3_NAME
from metrics.report.report_browser import CHROMIUM, open_report
from metrics.report.tables import format_cell, read_csv_rows, read_summary

MAX_REPORT_BYTES = 15_000_000


def test_vertex_clustering_keeps_a_small_mesh_and_shrinks_a_large_one():
    # A 100 x 100 grid of squares (20,000 triangles), left half label 1, right half label 2.
    n = 101
    xs, ys = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    vertices = np.stack([xs.ravel(), ys.ravel(), np.zeros(n * n)], 1)
    idx = np.arange(n * n).reshape(n, n)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    labels = np.where(vertices[:, 0] < 50, 1, 2)
    same = decimate_vertex_clustering(vertices, faces, labels, len(faces))
    assert same[1] is faces or np.array_equal(same[1], faces)
    v, f, lab = decimate_vertex_clustering(vertices, faces, labels, 2000)
    assert 0 < len(f) <= 2000 and len(lab) == len(v)
    assert f.max() < len(v)
    # Clusters keep their side's label: x of a cluster's centre decides it (cells straddling
    # x = 50 may go either way).
    assert set(lab[v[:, 0] < 45].tolist()) == {1} and set(lab[v[:, 0] > 55].tolist()) == {2}
    # The decimated surface still spans the square (to within a grid cell, a few units).
    assert np.ptp(v[:, 0]) > 90 and np.ptp(v[:, 1]) > 90
    with pytest.raises(ValueError, match="positive"):
        decimate_vertex_clustering(vertices, faces, labels, 0)


def test_cli_says_what_is_missing(tmp_path, capsys):
    assert main(["--out", str(tmp_path)]) == 2
    assert "run `python -m metrics.compare" in capsys.readouterr().err


@pytest.fixture(scope="module")
def compared(tiny_benchmark, tmp_path_factory) -> Path:
    """The comparison's out folder (with report.html) of every method on one tiny scene."""
    root = tmp_path_factory.mktemp("report")
    # The skyscraper: its 20-step neural3d mesh has walls, so every chart has data.
    scene = next(p for p in tiny_benchmark.iterdir() if "skyscraper" in p.name)
    out = root / "out"
    code = compare_main(["--data", str(scene), "--results", str(root / "results"), "--out",
                         str(out), "--methods", "2D-S,2D-SS,neural3d", "--neural3d-preset",
                         "tiny", "--neural3d-steps", "20", "--neural3d-resolution", "24"])
    assert code == 0
    return out


@pytest.mark.slow
def test_compare_writes_a_self_contained_report(compared):
    text = (compared / REPORT_FILE).read_text()
    assert len(text.encode()) < MAX_REPORT_BYTES
    # Offline: no element loads a script, stylesheet, image or frame from elsewhere (the
    # browser test also aborts and records any request that is not file:// or data:).
    # Plain booleans: a failed `in` on a 5 MB string makes pytest's diff crawl.
    external = re.findall(r'<(?:script|link|img|iframe)\b[^>]*\s(?:src|href)="(?!data:)[^"]*',
                          text)
    assert external == []
    found = {k: k in text for k in ("Plotly.newPlot", "data:image/png;base64,",
                                     'data-chart="mesh-')}  # the last: the mesh viewer
    assert all(found.values()), found


def _browser_or_skip():
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        sync_playwright = None
    if sync_playwright is None or not CHROMIUM.is_file():
        why = "needs /usr/bin/chromium and playwright (scripts/setup.sh installs them)"
        if os.environ.get("CI"):
            pytest.fail(f"CI is set but the report's browser test cannot run: {why}")
        pytest.skip(why)
    return sync_playwright


def _not_blank(png: bytes) -> bool:
    from io import BytesIO

    from PIL import Image

    pixels = np.asarray(Image.open(BytesIO(png)).convert("L"), dtype=float)
    return pixels.std() > 5.0  # a blank (white) region has std 0


@pytest.mark.slow
def test_report_in_headless_chromium(compared, tmp_path):
    sync_playwright = _browser_or_skip()
    with sync_playwright() as p:
        context, page, errors, blocked = open_report(p, compared / REPORT_FILE, tmp_path)
        try:
            page.wait_for_selector("#chart-errors .main-svg", timeout=30_000)
            # Tables: one row per CSV row, with the CSV's numbers as the report shows them.
            for name, table_id, key, decimals in ((TABLE2_NAME, "table2", "wwr_ape", 2),
                                                  (TABLE3_NAME, "table3", "footprint_iou", 3)):
                csv_rows = read_csv_rows((compared / f"{name}.csv").read_text())
                shown = page.eval_on_selector_all(
                    f"#{table_id} tbody tr",
                    "rows => rows.map(r => [r.dataset.family, r.dataset.method, "
                    "r.dataset.protocol, Array.from(r.cells).map(c => c.textContent)])")
                assert len(shown) == len(csv_rows) > 0
                by_key = {(f, m, v): cells for f, m, v, cells in shown}
                column = 5  # the first figure column of both tables
                for r in csv_rows:
                    s = read_summary(r, key)
                    cells = by_key[(r["family"], r["method"], r["protocol"])]
                    assert cells[column] == format_cell(s, decimals)
                    assert cells[3] == r["buildings"] and cells[4] == r["failed"]
            methods = {m for _, m, _, _ in shown} | {
                r["method"] for r in read_csv_rows((compared / f"{TABLE2_NAME}.csv").read_text())}
            assert methods == {"2D-S", "2D-SS", "neural3d"}
            for chart_id in ("#chart-errors", "#chart-iou"):
                assert _not_blank(page.locator(chart_id).screenshot())
            # Clicking a building shows its details, then its mesh viewer draws.
            button = page.locator("nav.buildings button").first
            scene = button.get_attribute("data-scene")
            section = page.locator(f'section.building[data-scene="{scene}"]')
            assert not section.is_visible()
            button.click()
            assert section.is_visible()
            # 2D-S, 2D-SS x 3 views (ideal, multi, train); neural3d (train)
            assert section.locator("table tbody tr").count() == 7
            assert section.locator("svg path").count() >= 2  # truth + an estimate
            page.wait_for_selector(f'section.building[data-scene="{scene}"] .mesh-wrap canvas',
                                   timeout=30_000)
            page.wait_for_timeout(500)
            assert _not_blank(section.locator(".mesh-wrap").screenshot())
            assert errors == [], errors
            assert blocked == [], blocked
        finally:
            context.close()
