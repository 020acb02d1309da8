"""Scene folders that share their files: a copy whose unchanged files are hard links to the
original (a degraded copy, a copy with predicted masks, a scene on other cameras), so that
the original is never modified and no image is stored twice."""

from __future__ import annotations

import os
import shutil
from pathlib import Path


def link_tree(src: Path, dst: Path) -> None:
    """Hard-link every file of ``src`` into ``dst`` (copy where linking is impossible)."""
    for path in sorted(src.rglob("*")):
        target = dst / path.relative_to(src)
        if path.is_dir():
            target.mkdir(parents=True, exist_ok=True)
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.link(path, target)
        except OSError:
            shutil.copy2(path, target)
