"""The segmenter's weights file: network shape, weights, classes and training record in one.

A weights file is a ``torch.save`` archive of plain values (read back with
``weights_only=True``: no code runs on load, nothing is downloaded) holding the
format tag, the class names it was trained for, the :class:`UNetConfig`, the weights
(float16, to keep the committed file small) and the training record as JSON text.
A copy of the record is written beside it as ``<name>.json`` for people to read.
:func:`load_network` refuses, with a message that says what to do, a missing,
truncated or foreign file and weights trained for other classes than
:data:`envelope.classes.CLASS_NAMES`.
"""

from __future__ import annotations

import io
import json
import pickle
import zipfile
from dataclasses import asdict
from pathlib import Path
from typing import Any

import torch

from envelope.atomic import write_bytes_atomic, write_json_atomic
from envelope.classes import CLASS_NAMES
from segment.network import UNet, UNetConfig

WEIGHTS_FORMAT = "envelope-bench-segmenter-1"
WEIGHTS_DIR = Path(__file__).resolve().parent / "weights"
BUILT_IN_WEIGHTS: dict[str, Path] = {
    "photos": WEIGHTS_DIR / "photos.pt",
    "renders": WEIGHTS_DIR / "renders.pt",
}
"""The committed weights by name (each with its training record beside it as ``.json``):
``renders`` trained on the ``segtrain`` renders alone, with its window calibration;
``photos`` on labelled real facade photos (LabelMeFacade, CMP; non-commercial research use,
see the record) and the renders. docs/segment.md says what each gives on real photos."""
DEFAULT_WEIGHTS_NAME = "renders"
DEFAULT_WEIGHTS = BUILT_IN_WEIGHTS[DEFAULT_WEIGHTS_NAME]
"""What ``--masks predicted`` and every segmenter command use unless told otherwise: the
render-trained weights; the photo-trained ones gave a larger WWR error on the CMP validation
facades (docs/decisions.md, 2026-11-29)."""
RENDER_WEIGHTS = BUILT_IN_WEIGHTS["renders"]
_TRAIN_HINT = "train weights with `python -m segment.train` (docs/segment.md)"


def save_weights(path: str | Path, model: UNet, record: dict[str, Any]) -> None:
    """Write ``model`` with its training ``record`` to ``path`` (atomically), and the
    record to ``path`` with suffix ``.json``."""
    path = Path(path)
    state = {k: (v.detach().to(torch.float16) if v.is_floating_point() else v.detach()).cpu()
             for k, v in model.state_dict().items()}
    archive = {
        "format": WEIGHTS_FORMAT,
        "classes": list(CLASS_NAMES),
        "network": asdict(model.config),
        "state": state,
        "record_json": json.dumps(record, sort_keys=True),
    }
    buf = io.BytesIO()
    torch.save(archive, buf)
    write_bytes_atomic(path, buf.getvalue())
    write_json_atomic(path.with_suffix(".json"), record)


def load_network(path: str | Path = DEFAULT_WEIGHTS) -> tuple[UNet, dict[str, Any]]:
    """The network of a weights file, in eval mode on the CPU, and its training record.

    Raises
    ------
    ValueError
        If the file is missing, unreadable (truncated, corrupt, not a weights file),
        trained for other classes, or its weights do not fit its network shape.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"segmenter weights {path} not found; give an existing file or "
                         f"{_TRAIN_HINT}")
    try:
        archive = torch.load(path, map_location="cpu", weights_only=True)
    except (RuntimeError, EOFError, OSError, pickle.UnpicklingError, zipfile.BadZipFile,
            ValueError) as exc:
        raise ValueError(f"{path} is not a readable segmenter weights file (truncated or "
                         f"corrupt: {type(exc).__name__}); restore it (git checkout) or "
                         f"{_TRAIN_HINT}") from None
    if not isinstance(archive, dict) or archive.get("format") != WEIGHTS_FORMAT:
        raise ValueError(f"{path} is not an envelope-bench segmenter weights file "
                         f"(format {WEIGHTS_FORMAT}); {_TRAIN_HINT}")
    classes = tuple(archive.get("classes") or ())
    if classes != CLASS_NAMES:
        raise ValueError(f"{path} was trained for the classes {list(classes)}, but this project "
                         f"segments {list(CLASS_NAMES)} (envelope.classes); {_TRAIN_HINT}")
    try:
        model = UNet(UNetConfig(**archive["network"]))
        model.load_state_dict({k: v.float() if v.is_floating_point() else v
                               for k, v in archive["state"].items()})
        record = json.loads(archive["record_json"])
    except (KeyError, TypeError, RuntimeError, ValueError, AttributeError) as exc:
        raise ValueError(f"{path}: weights do not fit the network they declare "
                         f"({type(exc).__name__}: {str(exc)[:200]}); {_TRAIN_HINT}") from None
    if model.config.num_classes != len(CLASS_NAMES):
        raise ValueError(f"{path}: network has {model.config.num_classes} outputs for "
                         f"{len(CLASS_NAMES)} classes; {_TRAIN_HINT}")
    return model.eval(), record
