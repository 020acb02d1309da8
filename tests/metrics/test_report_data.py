"""report.html from a comparison in memory, the same page rebuilt from the folder it wrote,
and names that hold markup escaped (the templates autoescape)."""

from __future__ import annotations

import ast
import fnmatch
import json
from html.parser import HTMLParser
from pathlib import Path

from paths import REPO_ROOT

import metrics.report
from metrics.report.html_report import REPORT_FILE, build_report, main
from metrics.report.report import per_building_table, table2_errors, table3_footprint_iou
from metrics.report.report_data import (
    PROVENANCE_FILE,
    read_report_data,
    read_table_records,
    report_data,
    table_records,
)
from metrics.report.report_orientation import orientation_table
from metrics.report.report_visible import table2_visible_errors
from metrics.report.tables import to_csv, write_table
from metrics.score.aggregate import Summary, aggregate_by_family
from metrics.score.errors import BuildingErrors

SCENE = "<script>alert('scene')</script>"
METHOD = '<img src=x onerror="alert(1)">'
FAMILY = "skyscraper"


def _rows() -> list[BuildingErrors]:
    return [BuildingErrors(scene, FAMILY, method, "ideal", wwr_est=0.3, wwr_true=0.25,
                           wwr_ape=ape, window_ape=ape, facade_ape=0.0, footprint_iou=0.8,
                           reason="<b>not bold</b>")
            for scene in (SCENE, "plain") for method, ape in ((METHOD, 20.0), ("2D-S", 4.0))]


def _comparison(out_dir):
    """The tables, rows and provenance of a small comparison, written as compare writes them."""
    rows = _rows()
    groups = aggregate_by_family(rows)
    tables = (table2_errors(groups), table3_footprint_iou(groups, {METHOD}),
              table2_visible_errors(groups), orientation_table(()))
    provenance = {"produced_by": f"python -m metrics.compare --data '{SCENE}'",
                  "methods": {METHOD: {"config": {"note": "</pre><script>x()</script>"}}},
                  "runs": [{"status": "ran"}]}
    out_dir.mkdir(parents=True, exist_ok=True)
    for table in tables:
        write_table(table, out_dir)
    (out_dir / "per_building.csv").write_text(to_csv(per_building_table(rows)))
    (out_dir / PROVENANCE_FILE).write_text(json.dumps(provenance))
    return tables, rows, provenance


def test_records_of_a_table_and_of_its_csv_are_the_same():
    table = table2_errors(aggregate_by_family(_rows()))
    in_memory, read_back = table_records(table), read_table_records(to_csv(table))
    assert len(in_memory) == len(read_back) == 4  # 2 methods x (skyscraper, all families)
    for mine, theirs in zip(in_memory, read_back):
        assert mine.keys() == theirs.keys()
        for key, cell in mine.items():
            if isinstance(cell, Summary):  # the CSV does not keep the count
                assert (cell.mean, cell.std, cell.low, cell.high) == (
                    theirs[key].mean, theirs[key].std, theirs[key].low, theirs[key].high)
            else:
                assert cell == theirs[key], key


class _Tags(HTMLParser):
    """Every start tag with its attributes, and the text outside scripts."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self.text: list[str] = []
        self._in_script = False

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        self._in_script = tag == "script"

    def handle_endtag(self, tag):
        self._in_script = False

    def handle_data(self, data):
        if not self._in_script:
            self.text.append(data)


def test_the_page_from_memory_is_the_page_rebuilt_from_the_folder_and_escapes_names(tmp_path):
    out = tmp_path / "out"
    tables, rows, provenance = _comparison(out)
    page = build_report(report_data(tables, rows, provenance, out))
    assert build_report(read_report_data(out)) == page
    assert main(["--out", str(out)]) == 0 and (out / REPORT_FILE).read_text() == page
    parser = _Tags()
    parser.feed(page)
    tags = {t for t, _ in parser.tags}
    assert "img" not in tags and "b" not in tags  # no image here; the reason's <b> is text
    scripts = [a for t, a in parser.tags if t == "script"]
    # plotly.js, the page's JS, then one JSON payload per chart: no script from a name
    assert scripts[:2] == [{}, {}] and all(
        a.get("type") == "application/json" and "data-chart" in a for a in scripts[2:])
    assert not any(k.startswith("on") for _, a in parser.tags for k in a)
    text = "".join(parser.text)
    assert SCENE in text and METHOD in text and "<b>not bold</b>" in text  # shown as text
    assert "</pre><script>x()</script>" in text  # in the provenance, as text
    assert [a["data-scene"] for t, a in parser.tags if t == "button"] == [SCENE, "plain"]



def test_the_templates_ship_as_package_data():
    line = next(x for x in (REPO_ROOT / "pyproject.toml").read_text().splitlines()
                if x.startswith('"metrics.report" = '))
    globs = ast.literal_eval(line.split("=", 1)[1].strip())
    folder = Path(metrics.report.__file__).parent
    files = sorted(p.relative_to(folder).as_posix() for p in (folder / "templates").iterdir())
    assert "templates/report.html.j2" in files and "templates/report.css" in files
    assert all(any(fnmatch.fnmatch(f, g) for g in globs) for f in files), (files, globs)
