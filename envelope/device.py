"""The torch device a run uses, checked once with a message a user can act on."""

from __future__ import annotations

import torch


def resolve_device(device: str | torch.device, *, available: bool = True) -> torch.device:
    """``"cpu"``, ``"cuda"`` or ``"cuda:N"`` as a checked :class:`torch.device`.

    ``available=False`` checks the name only, for a command that records a device
    without running on it (reading results made on a GPU machine, say).

    Raises
    ------
    ValueError
        If the name is not a device, is neither CPU nor CUDA, or (``available``) CUDA
        is not available.
    """
    try:
        dev = torch.device(device)
    except (RuntimeError, TypeError) as exc:
        raise ValueError(f"unknown device {device!r}: it is not a torch device; use 'cpu' or 'cuda'"
                         ) from exc
    if dev.type not in ("cpu", "cuda"):
        raise ValueError(f"unsupported device {device!r}; use 'cpu' or 'cuda'")
    if dev.type == "cuda" and available:
        if not torch.cuda.is_available():
            raise ValueError(f"device {device!r} asked for, but CUDA is not available: torch "
                             "sees no CUDA GPU on this machine (or this build); use cpu")
        if dev.index is not None and dev.index >= torch.cuda.device_count():
            raise ValueError(f"device {device!r} does not exist: torch sees "
                             f"{torch.cuda.device_count()} CUDA device(s)")
    return dev
