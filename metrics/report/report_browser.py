"""Open ``report.html`` in Debian's headless Chromium through Playwright, with the network blocked.

Used by the report's browser test and ``scripts/report_screenshots.py``.
Playwright's own browser download cannot work offline, so the system
``chromium`` (``apt-get install chromium``; scripts/setup.sh) is driven instead.
"""

from __future__ import annotations

from pathlib import Path

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync")


def open_report(playwright, report: Path, user_data_dir: Path,
                viewport: tuple[int, int] = (1280, 900)):
    """A page showing ``report`` in a fresh Chromium profile under ``user_data_dir``.

    Every request other than ``file://`` and ``data:`` is aborted and recorded.
    Returns (context, page, console errors, blocked URLs); close the context when done.
    """
    context = playwright.chromium.launch_persistent_context(
        str(user_data_dir), executable_path=str(CHROMIUM), args=list(CHROMIUM_ARGS),
        headless=True, viewport={"width": viewport[0], "height": viewport[1]})
    page = context.new_page()
    errors: list[str] = []
    blocked: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))

    def route(r):
        if r.request.url.startswith(("file://", "data:")):
            return r.continue_()
        blocked.append(r.request.url)
        return r.abort()

    page.route("**/*", route)
    page.goto(report.resolve().as_uri(), wait_until="load")
    return context, page, errors, blocked
