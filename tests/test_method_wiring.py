"""metrics and figures know methods only through dataset.core.method.Method: no name checks."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# a method's name compared with a literal, e.g. `s.name == "2D-SS"` or `method != "neural3d"`
NAME_CHECK = re.compile(r"""(\bname|\bmethod)\s*[!=]=\s*["'](2D-S|2D-SS|neural3d)["']"""
                        r"""|["'](2D-S|2D-SS|neural3d)["']\s+(not\s+)?in\s+\w*(specs|names)\b""")


def test_no_method_is_special_cased_by_name():
    found = []
    for package in ("metrics", "figures"):
        for path in sorted((ROOT / package).rglob("*.py")):
            for number, line in enumerate(path.read_text().splitlines(), 1):
                if NAME_CHECK.search(line):
                    found.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert found == []


def test_the_check_sees_a_name_check():
    assert NAME_CHECK.search('if any(s.name == "2D-SS" for s in specs):')
    assert NAME_CHECK.search('specs = [s for s in specs if s.name != "neural3d"]')
    assert not NAME_CHECK.search('BUILT_IN = {"neural3d": ("neural3d.method", "METHOD")}')
