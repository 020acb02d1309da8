"""The worked plugin example of docs/segment.md, installed as a throwaway distribution."""

import re
import sys
from pathlib import Path

from segment.segmenter import ENTRY_POINT_GROUP

DOC = Path(__file__).resolve().parent.parent / "docs" / "segment.md"


def doc_blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", DOC.read_text(), flags=re.S)


def install_toy_plugin(root: Path, monkeypatch, source: str | None = None,
                       entry: str | None = None) -> str:
    """The documented module (or ``source``) as a throwaway distribution on sys.path, with the
    documented entry point (or ``entry``); returns the entry point's name."""
    root.mkdir(parents=True, exist_ok=True)
    (root / "toy_masks_plugin.py").write_text(source or doc_blocks("python")[0])
    (table,) = [b for b in doc_blocks("toml") if ENTRY_POINT_GROUP in b]
    entries = re.findall(r'^(\S+) = "(\S+)"$', table, flags=re.M)
    assert entries == [("toy-masks", "toy_masks_plugin:segment")]
    info = root / "toy_masks_plugin-0.1.dist-info"
    info.mkdir(exist_ok=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-masks-plugin\nVersion: 0.1\n")
    name, value = entries[0] if entry is None else entry.split(" = ")
    (info / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\n{name} = {value}\n")
    monkeypatch.syspath_prepend(str(root))
    sys.modules.pop("toy_masks_plugin", None)
    return name
