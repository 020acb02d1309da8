"""Screenshots of report.html's main views into docs/images/, with its size and load time.

    python scripts/report_screenshots.py --out DIR [--images docs/images]

DIR is a comparison's output folder holding report.html (``python -m
metrics.compare`` writes it). Opens the report in headless Chromium with the
network blocked (metrics.report.report_browser), saves the tables, the charts and one
building's details with its neural3d mesh, and prints the file size, the time
to the load event and the time until the charts are drawn.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from metrics.report.html_report import REPORT_FILE
from metrics.report.report_browser import open_report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="comparison output folder")
    parser.add_argument("--images", type=Path, default=Path("docs/images"),
                        help="where the PNGs go (default: docs/images)")
    args = parser.parse_args(argv)
    report = args.out / REPORT_FILE
    if not report.is_file():
        print(f"error: {report} does not exist; run `python -m metrics.compare` first",
              file=sys.stderr)
        return 2
    from playwright.sync_api import sync_playwright

    args.images.mkdir(parents=True, exist_ok=True)
    with sync_playwright() as p, tempfile.TemporaryDirectory() as profile:
        start = time.perf_counter()
        context, page, errors, blocked = open_report(p, report, Path(profile), (1280, 1000))
        loaded_s = time.perf_counter() - start
        page.wait_for_selector("#chart-errors .main-svg")
        drawn_s = time.perf_counter() - start
        page.locator("#table2").screenshot(path=str(args.images / "report_tables.png"))
        page.locator("#chart-errors").screenshot(path=str(args.images / "report_charts.png"))
        buttons = page.locator("nav.buildings button")
        scene = None
        for i in range(buttons.count()):  # the first building with a neural3d mesh
            name = buttons.nth(i).get_attribute("data-scene")
            if page.locator(f'section.building[data-scene="{name}"] .mesh-wrap').count():
                scene = name
                buttons.nth(i).click()
                break
        if scene is not None:
            section = page.locator(f'section.building[data-scene="{scene}"]')
            page.wait_for_selector(f'section.building[data-scene="{scene}"] .mesh-wrap canvas')
            page.wait_for_timeout(1000)
            section.screenshot(path=str(args.images / "report_building.png"))
        context.close()
    size_mb = report.stat().st_size / 1e6
    print(f"{report}: {size_mb:.1f} MB; load event {loaded_s:.2f} s, charts drawn "
          f"{drawn_s:.2f} s; console errors {len(errors)}, blocked requests {len(blocked)}")
    for e in errors:
        print(f"console error: {e}")
    return 0 if not errors and not blocked else 1


if __name__ == "__main__":
    sys.exit(main())
