"""A training run's folder: ``config.json``, ``run.json``, ``log.csv`` and ``eval.json``.

``neural3d.train`` starts, resumes and logs a run through these; the
checkpoint itself is :mod:`neural3d.field.checkpoint`.
"""

from __future__ import annotations

import csv
import io
import json
import shutil
from pathlib import Path
from typing import Literal

import torch

from envelope.atomic import write_json_atomic, write_text_atomic
from envelope.protocols import TRAIN_PROTOCOL, Split
from envelope.provenance import (
    Provenance,
    file_fingerprint,
    make_provenance,
    provenance_changes,
)
from envelope.results import code_version
from envelope.scene_record import scene_name
from neural3d.config import TrainConfig, config_from_dict, config_to_dict
from neural3d.field.checkpoint import CHECKPOINT_NAME, SNAPSHOT_FOLDER, read_checkpoint
from neural3d.field.normalisation import Normalisation

TRAINING_CODE = ("envelope", "neural3d.config", "neural3d.field", "neural3d.rendering",
                 "neural3d.training", "neural3d.train")
"""The modules whose source a trained field depends on: extraction is not among them, so
a change to meshing or measuring keeps a finished training (tests/neural3d/test_neural3d_reuse.py
checks that ``neural3d.train`` imports nothing of neural3d outside them)."""
TRAINING_LIBRARIES = ("numpy", "torch")
PriorRun = Literal["none", "partial", "finished"]
"""What a run folder holds for a given training provenance: nothing usable, a checkpoint
before the step budget (resume it), or a finished training (reuse it)."""

LOG_FIELDS = ("step", "train_s", "loss", "rgb", "eikonal", "semantic", "mask", "depth", "psnr",
              "inv_s", "lr", "dropped_samples")
"""log.csv's columns; ``dropped_samples`` (candidates the fixed-shape step had no slot for,
over the steps since the previous row) is empty unless ``sample_buffer`` is on."""


def training_provenance(scene_dir: Path, config: TrainConfig, device: torch.device, *,
                        split: Split = TRAIN_PROTOCOL) -> Provenance:
    """What a training depends on: its config, the frames it reads (``split``), device and
    torch thread count (reductions depend on them), the source of :data:`TRAINING_CODE`, the
    scene's ``transforms.json`` and the versions of :data:`TRAINING_LIBRARIES`."""
    transforms = Path(scene_dir) / "transforms.json"
    return make_provenance(
        {"train": config_to_dict(config), "split": split, "device": str(device),
         "threads": torch.get_num_threads()},
        modules=TRAINING_CODE,
        inputs={"scene": file_fingerprint(transforms) if transforms.is_file() else "absent"},
        libraries=TRAINING_LIBRARIES)


def prior_run(run_dir: Path, expected: Provenance, iterations: int) -> PriorRun:
    """Whether ``run_dir`` holds a training with provenance ``expected``, and how far it got.

    ``"finished"``: its checkpoint reached ``iterations`` steps; ``"partial"``: an earlier
    step (a run stopped by Ctrl-C, SIGTERM or a crash after a checkpoint; resuming it
    matches an uninterrupted run); ``"none"``: no checkpoint, no or another provenance
    (other training code, config, scene, device, threads or libraries), or a damaged file.
    """
    run_dir = Path(run_dir)
    try:
        stored = json.loads((run_dir / "run.json").read_text()).get("provenance")
        if stored is None or provenance_changes(Provenance.from_json_dict(stored), expected):
            return "none"
        step = int(read_checkpoint(run_dir / CHECKPOINT_NAME, torch.device("cpu"))["step"])
    except (OSError, ValueError, TypeError, KeyError, AttributeError):
        return "none"
    return "finished" if step >= iterations else "partial"


def start_run_folder(run_dir: Path, scene_dir: Path, classes: tuple[str, ...], bg: int,
                     norm: Normalisation, config: TrainConfig, device: torch.device,
                     n_train: int, *, split: Split = TRAIN_PROTOCOL) -> None:
    """Start ``run_dir`` afresh: remove a previous run's checkpoint and logs, write the config
    and ``run.json`` (scene, the split trained on, classes, background class, normalisation,
    device, versions and the :func:`training_provenance`)."""
    run_dir.mkdir(parents=True, exist_ok=True)
    for stale in (CHECKPOINT_NAME, "log.csv", "eval.json"):
        (run_dir / stale).unlink(missing_ok=True)
    shutil.rmtree(run_dir / SNAPSHOT_FOLDER, ignore_errors=True)
    write_json_atomic(run_dir / "config.json", config_to_dict(config))
    write_json_atomic(run_dir / "run.json", {
        "scene_dir": str(scene_dir.resolve()), "scene_name": scene_name(scene_dir),
        "class_names": list(classes), "background_class": bg,
        "normalisation": norm.to_json_dict(), "device": str(device),
        "code_version": code_version(), "torch_version": torch.__version__,
        "split": split, "train_frames": n_train,
        "provenance": training_provenance(scene_dir, config, device,
                                          split=split).to_json_dict(),
    })


def check_resumable(run_dir: Path, config: TrainConfig, *,
                    split: Split = TRAIN_PROTOCOL) -> Normalisation:
    """The normalisation of a run that can resume with ``config`` on ``split``; ValueError with
    the reason (a file missing, another config or split, a damaged ``run.json``) otherwise."""
    for name in ("config.json", "run.json", CHECKPOINT_NAME):
        if not (run_dir / name).is_file():
            raise ValueError(f"cannot resume: {run_dir / name} does not exist (train without "
                             "--resume first)")
    saved = read_run_config(run_dir)
    if saved != config:
        raise ValueError(f"cannot resume: {run_dir} was trained with another config; resume "
                         "with the config in its config.json")
    try:
        run = json.loads((run_dir / "run.json").read_text())
        norm = Normalisation.from_json_dict(run["normalisation"])
        trained_split = run.get("split", TRAIN_PROTOCOL)
    except (json.JSONDecodeError, UnicodeDecodeError, TypeError, KeyError, AttributeError,
            ValueError) as exc:
        raise ValueError(f"cannot resume: {run_dir / 'run.json'} is damaged ({exc}); train "
                         "again without --resume") from exc
    if trained_split != split:
        raise ValueError(f"cannot resume: {run_dir} was trained on the {trained_split!r} frames, "
                         f"not {split!r}; resume with --split {trained_split}")
    return norm


def write_log(run_dir: Path, rows: list[dict]) -> None:
    """Write ``log.csv`` (columns :data:`LOG_FIELDS`), atomically."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=LOG_FIELDS, restval="", extrasaction="ignore")
    writer.writeheader()
    writer.writerows(rows)
    write_text_atomic(run_dir / "log.csv", buf.getvalue())


def read_log(run_dir: Path) -> list[dict]:
    """The rows of ``log.csv`` (none when absent)."""
    path = run_dir / "log.csv"
    if not path.is_file():
        return []
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def read_evals(run_dir: Path) -> list[dict]:
    """The evaluations in ``eval.json`` (none when absent; ValueError when damaged)."""
    path = run_dir / "eval.json"
    if not path.is_file():
        return []
    try:
        return list(json.loads(path.read_text())["evaluations"])
    except (json.JSONDecodeError, UnicodeDecodeError, TypeError, KeyError) as exc:
        raise ValueError(f"cannot resume: {path} is damaged ({exc}); delete it to resume "
                         "without the evaluation history") from exc


def read_run_config(run_dir: Path) -> TrainConfig:
    """The config a run folder was trained with (ValueError if its config.json is unreadable)."""
    path = Path(run_dir) / "config.json"
    try:
        return config_from_dict(json.loads(path.read_text()))
    except (json.JSONDecodeError, UnicodeDecodeError, TypeError, KeyError, AttributeError) as exc:
        raise ValueError(f"{path} is not a valid neural3d config: {exc}; train again without "
                         "--resume") from exc
