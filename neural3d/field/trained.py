"""A trained semantic SDF seen in world metres: what meshing, measuring and the bench use."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch
from torch import Tensor

from envelope.device import resolve_device
from envelope.protocols import SPLITS, TRAIN_PROTOCOL, Split
from envelope.scene_record import scene_name
from neural3d.config import FieldConfig, config_from_dict
from neural3d.field.checkpoint import read_checkpoint, snapshot_path, snapshot_steps
from neural3d.field.chunks import DEFAULT_CHUNK_POINTS
from neural3d.field.fields import SemanticSDF
from neural3d.field.normalisation import Normalisation


class TrainedField:
    """A :class:`SemanticSDF` with its normalisation; every input and output in world metres.

    Queries run without gradients, in calls of at most ``chunk_points`` points (the one
    place a field is evaluated in chunks, :mod:`neural3d.field.chunks`), on the field's
    device; inputs are moved there and outputs stay there.
    """

    def __init__(self, field: SemanticSDF, normalisation: Normalisation, *, scene_dir: Path,
                 class_names: tuple[str, ...], split: Split = TRAIN_PROTOCOL) -> None:
        self.field = field
        self.normalisation = normalisation
        self.scene_dir = Path(scene_dir)
        self.scene_name = scene_name(self.scene_dir)
        self.class_names = tuple(class_names)
        self.split = split  # the frames it was trained on: the protocol of its results
        self.box_min_m = np.asarray(normalisation.box_min_m, dtype=np.float64)
        self.box_max_m = np.asarray(normalisation.box_max_m, dtype=np.float64)

    @property
    def device(self) -> torch.device:
        return self.field.log_inv_s.device

    def sdf_m(self, points_world_m: Tensor, *,
              chunk_points: int = DEFAULT_CHUNK_POINTS) -> Tensor:
        """"(N, 3)" world points (m) -> "(N,)" signed distance in metres, positive outside."""
        x = self._unit(points_world_m)
        with torch.no_grad():
            out = [self.field.sdf(c) for c in x.split(_checked(chunk_points))]
        return _cat(out, x) * self.normalisation.scale_m

    def semantic_logits(self, points_world_m: Tensor, *,
                        chunk_points: int = DEFAULT_CHUNK_POINTS) -> Tensor:
        """"(N, 3)" world points (m) -> "(N, C)" class logits (view-independent)."""
        x = self._unit(points_world_m)
        with torch.no_grad():
            out = [self.field.semantic_logits(self.field.sdf_net(c)[1])
                   for c in x.split(_checked(chunk_points))]
        return _cat(out, x, self.field.num_classes)

    def rgb(self, points_world_m: Tensor, view_dirs_world: Tensor, *,
            chunk_points: int = DEFAULT_CHUNK_POINTS) -> Tensor:
        """"(N, 3)" points (m) and "(N, 3)" view directions -> "(N, 3)" colour in [0, 1]."""
        x = self._unit(points_world_m)
        d = view_dirs_world.to(device=self.device, dtype=torch.float32)
        if d.shape != x.shape:
            raise ValueError(f"view_dirs_world must be (N, 3) like the points, got "
                             f"{tuple(d.shape)}")
        d = d / d.norm(dim=-1, keepdim=True).clamp(min=1e-12)
        out = []
        for xc, dc in zip(x.split(_checked(chunk_points)), d.split(chunk_points)):
            _, feature, grad = self.field.sdf_feature_gradient(xc, create_graph=False)
            with torch.no_grad():
                out.append(self.field.colour(xc, dc, grad, feature))
        return _cat(out, x, 3)

    def _unit(self, points_world_m: Tensor) -> Tensor:
        p = torch.as_tensor(points_world_m)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points_world_m must be (N, 3), got {tuple(p.shape)}")
        p = p.to(device=self.device, dtype=torch.float64)
        return self.normalisation.unit_from_world(p).to(torch.float32)


def _checked(chunk_points: int) -> int:
    if chunk_points < 1:
        raise ValueError(f"chunk_points must be >= 1, got {chunk_points}")
    return int(chunk_points)


def _cat(chunks: list[Tensor], x: Tensor, *trailing: int) -> Tensor:
    if not chunks:
        return torch.zeros((0, *trailing), device=x.device)
    return torch.cat(chunks)


def load_trained_field(run_dir: Path, *, device: torch.device,
                       step: int | None = None) -> TrainedField:
    """The field of a finished (or checkpointed) run folder, on ``device``.

    ``step``: the field as it was at that evaluation step (its snapshot,
    :func:`neural3d.field.checkpoint.snapshot_path`) instead of the checkpoint's.

    Raises
    ------
    ValueError
        If the folder lacks ``config.json``, ``run.json`` or ``checkpoint.pt``, or
        ``step`` has no snapshot.
    """
    run_dir = Path(run_dir)
    device = resolve_device(device)
    for name in ("config.json", "run.json", "checkpoint.pt"):
        if not (run_dir / name).is_file():
            raise ValueError(f"{run_dir} is not a neural3d run folder: {name} is missing "
                             "(train one with `python -m neural3d.train`)")
    try:
        config = config_from_dict(json.loads((run_dir / "config.json").read_text()))
        run = json.loads((run_dir / "run.json").read_text())
        norm = Normalisation.from_json_dict(run["normalisation"])
        class_names = tuple(str(c) for c in run["class_names"])
        scene_dir = Path(run["scene_dir"])
        split = run.get("split", TRAIN_PROTOCOL)  # runs before 2026-11-29 trained on train
        if split not in SPLITS:
            raise ValueError(f"unknown split {split!r}")
    except (json.JSONDecodeError, UnicodeDecodeError, TypeError, KeyError, AttributeError,
            ValueError) as exc:
        raise ValueError(f"{run_dir} holds a damaged config.json or run.json ({exc}); train "
                         "the run again") from exc
    field = build_field(config.model, len(class_names), norm).to(device)
    if step is not None and not snapshot_path(run_dir, step).is_file():
        raise ValueError(f"{run_dir} has no snapshot of step {step}; it has "
                         f"{snapshot_steps(run_dir) or 'none'}")
    state = read_checkpoint(
        run_dir / "checkpoint.pt" if step is None else snapshot_path(run_dir, step), device)
    field.load_state_dict(state.get("ema", state["field"]))  # the averaged weights if any
    field.set_step(int(state["step"]))
    field.eval()
    return TrainedField(field, norm, scene_dir=scene_dir, class_names=class_names, split=split)


def build_field(model_config: FieldConfig, num_classes: int, norm: Normalisation) -> SemanticSDF:
    """A fresh :class:`SemanticSDF` for a scene box (same seed -> same weights)."""
    return SemanticSDF(model_config, num_classes, norm.box_min_unit, norm.box_max_unit)
