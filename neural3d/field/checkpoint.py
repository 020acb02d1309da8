"""Training checkpoints: one ``checkpoint.pt`` per run, written atomically, and snapshots.

It holds only tensors and plain types, so it loads with ``weights_only=True``:
the step, the field's weights, the optimizer and scheduler states, the random
generator's state and the training time spent so far. A snapshot
(``snapshots/step_<step>.pt``, one per evaluation step) holds only the step and
the measured field's weights, so a run can be measured as it was at each check.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import torch

from envelope.atomic import write_bytes_atomic

CHECKPOINT_NAME = "checkpoint.pt"
SNAPSHOT_FOLDER = "snapshots"


def snapshot_path(run_dir: Path, step: int) -> Path:
    """Where the snapshot of ``step`` lives in a run folder."""
    return Path(run_dir) / SNAPSHOT_FOLDER / f"step_{step:06d}.pt"


def snapshot_steps(run_dir: Path) -> list[int]:
    """The steps of the snapshots in a run folder, increasing (none: ``[]``)."""
    folder = Path(run_dir) / SNAPSHOT_FOLDER
    return sorted(int(p.stem.removeprefix("step_")) for p in folder.glob("step_*.pt")
                  if p.stem.removeprefix("step_").isdigit())


def write_checkpoint(path: Path, state: dict[str, Any]) -> None:
    """Save ``state`` to ``path`` through a temporary file and a rename."""
    buf = io.BytesIO()
    torch.save(state, buf)
    write_bytes_atomic(path, buf.getvalue())


def read_checkpoint(path: Path, device: torch.device) -> dict[str, Any]:
    """Load a checkpoint with tensors mapped onto ``device``.

    Raises
    ------
    ValueError
        If the file is missing or not a readable checkpoint.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"checkpoint {path} does not exist: nothing to resume or load")
    try:
        state = torch.load(path, map_location=device, weights_only=True)
    except Exception as exc:  # torch raises several types for a corrupt file
        raise ValueError(f"checkpoint {path} cannot be read: {exc}") from exc
    for key in ("step", "field"):
        if key not in state:
            raise ValueError(f"checkpoint {path} lacks {key!r}: not a neural3d checkpoint")
    return state
