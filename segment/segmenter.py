"""A segmenter: ``rgb (H, W, 3) uint8 -> labels (H, W) uint8`` with the project's class ids.

The built-in one is the U-Net of a weights file (:func:`network_segmenter`). Another
package adds its own (a local Mask2Former, a SAM- or YOLO-based model) by exposing
the callable, or a zero-argument factory returning one, under the entry point group
``envelope_bench.segmenters``, e.g. in its ``pyproject.toml``::

    [project.entry-points."envelope_bench.segmenters"]
    my-net = "my_package.masks:segment"

:func:`resolve_segmenter` picks one by name; :func:`segment_rgb` runs it and refuses an
answer of the wrong shape, dtype or class ids. docs/segment.md has a worked example.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import torch
from torch.nn import functional as F

from envelope.classes import CLASS_NAMES, NUM_CLASSES
from envelope.photo_io import read_photo_rgb
from envelope.provenance import code_fingerprint, file_fingerprint, library_version
from segment.network import UNet
from segment.weights import BUILT_IN_WEIGHTS, DEFAULT_WEIGHTS, load_network

ENTRY_POINT_GROUP = "envelope_bench.segmenters"
DEFAULT_NAME = "default"
"""What names the default weights (:data:`segment.weights.DEFAULT_WEIGHTS`) besides their own
name in :data:`segment.weights.BUILT_IN_WEIGHTS`."""
SegmentFn = Callable[[np.ndarray], np.ndarray]
"""``rgb (H, W, 3) uint8 -> labels (H, W) uint8``, ids in ``0 .. NUM_CLASSES - 1``."""


@dataclass(frozen=True)
class Segmenter:
    """A segmenter and what identifies its output: ``identity`` (weights and code
    fingerprints, or the plugin's entry point and version) goes into the provenance of
    every mask it makes, so a changed segmenter never reuses old masks."""

    name: str
    segment: SegmentFn
    identity: dict[str, Any]


def network_segmenter(weights: str | Path = DEFAULT_WEIGHTS, *, threads: int = 2,
                      name: str | None = None) -> Segmenter:
    """The U-Net of ``weights`` on the CPU with ``threads`` torch threads.

    Raises
    ------
    ValueError
        Missing, corrupt or wrong-class weights (:func:`segment.weights.load_network`).
    """
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    model, record = load_network(weights)
    offsets = calibrated_offsets(record, weights)
    identity = {"weights": file_fingerprint(weights), "code": code_fingerprint("segment"),
                "torch": library_version("torch")}
    built_in = {path: n for n, path in BUILT_IN_WEIGHTS.items()}
    label = name or built_in.get(Path(weights), str(weights))

    def segment(rgb: np.ndarray) -> np.ndarray:
        return predict_labels(model, rgb, threads=threads, logit_offsets=offsets)

    return Segmenter(label, segment, identity)


def calibrated_offsets(record: dict[str, Any], weights: str | Path) -> tuple[float, ...] | None:
    """The logit offsets ``segment.calibrate`` wrote into a weights record (one per class),
    or ``None`` for uncalibrated weights.

    Raises
    ------
    ValueError
        If the record's offsets are not one finite number per class.
    """
    offsets = (record.get("calibration") or {}).get("logit_offsets")
    if offsets is None:
        return None
    if (not isinstance(offsets, list) or len(offsets) != NUM_CLASSES
            or not all(isinstance(v, (int, float)) and np.isfinite(v) for v in offsets)):
        raise ValueError(f"{weights}: calibration logit_offsets must be {NUM_CLASSES} finite "
                         f"numbers, got {offsets!r}; calibrate again with `python -m "
                         f"segment.calibrate`")
    return tuple(float(v) for v in offsets)


def predict_logits(model: UNet, rgb: np.ndarray, *, threads: int = 2) -> torch.Tensor:
    """The network's class scores of every pixel: (H, W, 3) uint8 RGB -> (C, H, W) float32.

    A network with a ``working_long_side_px`` sees the image scaled to that long side
    (:func:`scale_to_long_side`, area averaging when shrinking) and its scores are scaled
    back to (H, W) bilinearly."""
    previous = torch.get_num_threads()
    torch.set_num_threads(threads)
    h, w = rgb.shape[:2]
    working = scale_to_long_side(rgb, model.config.working_long_side_px)
    try:
        with torch.inference_mode():
            x = torch.from_numpy(np.ascontiguousarray(working)).permute(2, 0, 1)[None].float()
            logits = model((x / 255).contiguous(memory_format=torch.channels_last))
            if logits.shape[-2:] != (h, w):
                logits = F.interpolate(logits, size=(h, w), mode="bilinear",
                                       align_corners=False)
            return logits[0]
    finally:
        torch.set_num_threads(previous)


def scale_to_long_side(image: np.ndarray, long_side_px: int | None, *,
                       labels: bool = False) -> np.ndarray:
    """``image`` (H, W[, 3]) scaled so that its long side is ``long_side_px`` (the aspect
    kept, sides rounded); unchanged for ``None`` or when it already has that size. RGB is
    area-averaged when shrunk and bilinear when enlarged; ``labels`` (class ids) are taken
    by nearest neighbour."""
    if long_side_px is None:
        return image
    h, w = image.shape[:2]
    factor = long_side_px / max(h, w)
    size = (max(1, round(w * factor)), max(1, round(h * factor)))
    if size == (w, h):
        return image
    interp = (cv2.INTER_NEAREST if labels else
              cv2.INTER_AREA if factor < 1 else cv2.INTER_LINEAR)
    return cv2.resize(np.ascontiguousarray(image), size, interpolation=interp)


def predict_labels(model: UNet, rgb: np.ndarray, *, threads: int = 2,
                   logit_offsets: Sequence[float] | None = None) -> np.ndarray:
    """Most likely class of every pixel: (H, W, 3) uint8 RGB -> (H, W) uint8 ids, after
    adding ``logit_offsets`` (one per class; a calibration, :mod:`segment.calibrate`)."""
    logits = predict_logits(model, rgb, threads=threads)
    if logit_offsets is not None:
        logits = logits + torch.tensor(logit_offsets, dtype=logits.dtype)[:, None, None]
    return logits.argmax(0).to(torch.uint8).numpy()


def installed_segmenters() -> dict[str, EntryPoint]:
    """Entry points registered under ``envelope_bench.segmenters``, by name (not loaded)."""
    return {ep.name: ep for ep in sorted(entry_points(group=ENTRY_POINT_GROUP),
                                          key=lambda e: e.name)}


def resolve_segmenter(model: str | None = None, *, threads: int = 2) -> Segmenter:
    """The segmenter that ``model`` names: ``None`` or ``"default"`` (the default committed
    weights), a committed weights name (:data:`segment.weights.BUILT_IN_WEIGHTS`), a weights
    file (``*.pt``) or an installed plugin's entry-point name.

    Raises
    ------
    ValueError
        If ``model`` names none of these, the weights are refused, or the plugin does not
        load or is not a callable.
    """
    if model is None or model == DEFAULT_NAME:
        return network_segmenter(DEFAULT_WEIGHTS, threads=threads)
    if model in BUILT_IN_WEIGHTS:
        return network_segmenter(BUILT_IN_WEIGHTS[model], threads=threads)
    plugins = installed_segmenters()
    if model in plugins:
        return _plugin(plugins[model])
    if model.endswith(".pt") or Path(model).is_file():
        return network_segmenter(model, threads=threads)
    known = ", ".join([DEFAULT_NAME, *BUILT_IN_WEIGHTS, *plugins])
    raise ValueError(f"unknown segmenter {model!r}: give a weights file (*.pt), "
                     f"a committed name or an installed plugin ({known})")


def segment_rgb(segmenter: Segmenter, rgb: np.ndarray) -> np.ndarray:
    """Run ``segmenter`` on one image and check its answer.

    Parameters
    ----------
    rgb : (H, W, 3) uint8

    Returns
    -------
    (H, W) uint8 class ids in ``0 .. NUM_CLASSES - 1``.

    Raises
    ------
    ValueError
        If ``rgb`` is not (H, W, 3) uint8, or the answer is not an (H, W) uint8 array of
        the project's class ids.
    """
    rgb = np.asarray(rgb)
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.dtype != np.uint8:
        raise ValueError(f"a segmenter takes (H, W, 3) uint8 RGB, got {rgb.shape} {rgb.dtype}")
    labels = segmenter.segment(rgb)
    what = f"segmenter {segmenter.name!r} returned"
    if not isinstance(labels, np.ndarray):
        raise ValueError(f"{what} a {type(labels).__name__}; it must return a numpy array "
                         f"(H, W) uint8")
    if labels.shape != rgb.shape[:2]:
        raise ValueError(f"{what} shape {labels.shape} for an image of {rgb.shape[:2]}; it "
                         f"must return one class id per pixel, shape (H, W)")
    if labels.dtype != np.uint8:
        raise ValueError(f"{what} dtype {labels.dtype}; it must return uint8 class ids "
                         f"(labels.astype(np.uint8) once they are in range)")
    if labels.size and int(labels.max()) >= NUM_CLASSES:
        raise ValueError(f"{what} class id {int(labels.max())}; ids must be 0..{NUM_CLASSES - 1} "
                         f"({', '.join(f'{i} {n}' for i, n in enumerate(CLASS_NAMES))})")
    return labels


def segment_photo(segmenter: Segmenter, path: str | Path) -> np.ndarray:
    """Read the photo at ``path`` (:func:`envelope.photo_io.read_photo_rgb`: upright, 8-bit
    RGB from grey, 16-bit, CMYK, palette or alpha images) and segment it: (H, W) uint8
    class ids of the upright image.

    Raises
    ------
    ValueError
        An unreadable file (truncated, corrupt, floating-point) or a bad segmenter answer.
    """
    return segment_rgb(segmenter, read_photo_rgb(path))


def _plugin(ep: EntryPoint) -> Segmenter:
    try:
        obj = ep.load()
    except Exception as exc:  # a plugin's own failure, said in one line
        raise ValueError(f"segmenter plugin {ep.name} ({ep.value}) does not load: "
                         f"{type(exc).__name__}: {exc}") from exc
    segment = obj if _takes_an_image(obj) else obj()
    if not callable(segment):
        raise ValueError(f"segmenter plugin {ep.name} ({ep.value}) is not a callable "
                         f"rgb -> labels, nor a factory returning one")
    module = ep.value.split(":")[0].split(".")[0]
    dist = ep.dist.name if ep.dist is not None else module
    identity = {"entry_point": f"{ep.name} = {ep.value}", "version": library_version(dist),
                "code": _fingerprint_or_absent(module)}
    return Segmenter(ep.name, segment, identity)


def _takes_an_image(obj: Any) -> bool:
    """Whether ``obj`` is the segment function itself (one argument) rather than a factory."""
    import inspect

    try:
        params = inspect.signature(obj).parameters.values()
    except (TypeError, ValueError):
        return True
    required = [p for p in params if p.default is p.empty
                and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return len(required) == 1


def _fingerprint_or_absent(module: str) -> str:
    try:
        return code_fingerprint(module)
    except ValueError:
        print(f"warning: cannot fingerprint the code of {module}; its masks are cached by "
              f"entry point and version only", file=sys.stderr)
        return "absent"
