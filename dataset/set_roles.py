"""What each building set may be used for: tuning, approval or report only.

- **tuning** (``tiny``, ``paper``, ``segtrain``): thresholds, rules and budgets are chosen here;
- **approval** (``approval``): new seeds of every procedural family and of the held-out designs,
  the place to ask "does this change do harm?";
- **report** (``heldout``, ``lod3``): run once, by the command that writes the committed
  results (``python -m metrics.compare``); never looked at to choose or approve. A bench
  script that chooses settings refuses them (:func:`refuse_report_only`).

A scene knows its set from the generator's record in ``transforms.json``
(``generator.provenance.inputs.preset``); a scene from any other source (a user's mesh,
IFC, CityGML or photos) belongs to no preset and is the user's to use.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

SetRole = Literal["tuning", "approval", "report"]
PRESET_ROLES: dict[str, SetRole] = {
    "tiny": "tuning", "paper": "tuning", "segtrain": "tuning",
    "approval": "approval",
    "heldout": "report", "lod3": "report",
}


def scene_preset(scene_dir: str | Path) -> str | None:
    """The preset a scene folder was generated from; ``None`` for any other source or a
    folder without a readable generator record."""
    try:
        record = json.loads((Path(scene_dir) / "transforms.json").read_text())
        preset = record["generator"]["provenance"]["inputs"].get("preset")
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    return preset if isinstance(preset, str) else None


def report_only_presets(scene_dirs: list[Path]) -> dict[str, list[str]]:
    """Per report-only preset, the scenes of ``scene_dirs`` that belong to it."""
    out: dict[str, list[str]] = {}
    for d in scene_dirs:
        preset = scene_preset(d)
        if preset is not None and PRESET_ROLES.get(preset) == "report":
            out.setdefault(preset, []).append(Path(d).name)
    return out


def refuse_report_only(scene_dirs: list[Path], purpose: str) -> None:
    """Raise if any scene belongs to a report-only set.

    ``purpose``: what the caller does with the scenes (e.g. "choose the straight-walls
    settings"), for the message.

    Raises
    ------
    ValueError
        Naming the report-only presets and a few of their scenes, and the sets to use.
    """
    found = report_only_presets(scene_dirs)
    if found:
        named = "; ".join(f"{p}: {', '.join(sorted(s)[:3])}{' ...' if len(s) > 3 else ''}"
                          for p, s in sorted(found.items()))
        tuning = ", ".join(p for p, r in PRESET_ROLES.items() if r == "tuning")
        raise ValueError(
            f"refusing to {purpose} on report-only scenes ({named}); report-only sets are run "
            "only by the command that writes the committed results. Use a tuning set "
            f"({tuning}) or the approval preset")
