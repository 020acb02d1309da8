"""Named, seeded degradation specs and their ``NAME[:SEVERITY],...`` text form.

Names and severities:

- ``mask_erode`` (k px): window regions of the semantic masks eroded by k px
  (square kernel); lost pixels become wall. ``mask_dilate`` (k px): grown into wall.
- ``mask_miss`` (probability p): each window (connected region) becomes wall.
- ``mask_false`` (probability p): per window, a copy of its box pasted onto plain wall.
- ``mask_bleed`` (k px): pixels within k px of a window/wall edge take the label
  of a random neighbour within k px (frames smeared into the wall).
- ``mask_noise`` (level s): all four: erode ``int(s)`` px, miss ``0.1 s``,
  false ``0.05 s``, bleed ``int(s)`` px.
- ``occluders`` (n per facade): trees, cars and people (boxes on the ground
  1.5-5 m in front of each facade) ray-cast into RGB, depth, masks (as
  background) and normals of every view (:mod:`dataset.degrade.occluders`).
- ``pose`` (degrees): every camera rotated by exactly s degrees about a random
  axis through its centre and moved by exactly 0.1 m per degree in a random
  direction (:mod:`dataset.degrade.poses`).
- ``depth_noise`` (level s): z-depth + Gaussian noise of 0.01 s x depth, window
  (glass) pixels lose their depth with probability 0.25 s, values quantised to
  0.01 s metres (:mod:`dataset.degrade.depth_noise`).

Severity 0 leaves every input bit-identical. Every random draw comes from
``(seed, name, frame index)``, so a spec gives the same files on every run.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

DegradationName = Literal[
    "occluders", "mask_erode", "mask_dilate", "mask_miss", "mask_false", "mask_bleed",
    "mask_noise", "depth_noise", "pose",
]
# Application order: occluders change what is seen, masks and depth are then corrupted,
# poses last (images stay rendered from the true pose; only the recorded pose is wrong).
DEGRADATIONS: tuple[str, ...] = (
    "occluders", "mask_erode", "mask_dilate", "mask_miss", "mask_false", "mask_bleed",
    "mask_noise", "depth_noise", "pose",
)
DEFAULT_SEVERITY: dict[str, float] = {
    "occluders": 1.0, "mask_erode": 1.0, "mask_dilate": 1.0, "mask_miss": 0.2,
    "mask_false": 0.1, "mask_bleed": 1.0, "mask_noise": 1.0, "depth_noise": 1.0, "pose": 0.3,
}
_PROBABILITY = ("mask_miss", "mask_false")
_WHOLE_PIXELS = ("mask_erode", "mask_dilate", "mask_bleed")


@dataclass(frozen=True)
class DegradeSpec:
    """One degradation: ``name`` (see the module table), ``severity`` (>= 0, 0 = none), ``seed``."""

    name: DegradationName
    severity: float
    seed: int = 0

    def __post_init__(self) -> None:
        if self.name not in DEGRADATIONS:
            raise ValueError(f"unknown degradation {self.name!r}; choose from "
                             f"{', '.join(DEGRADATIONS)}")
        if not np.isfinite(self.severity) or self.severity < 0:
            raise ValueError(f"{self.name}: severity must be a number >= 0, got {self.severity}")
        if self.name in _PROBABILITY and self.severity > 1:
            raise ValueError(f"{self.name}: severity is a probability in [0, 1], "
                             f"got {self.severity}")
        if self.name in _WHOLE_PIXELS and self.severity != int(self.severity):
            raise ValueError(f"{self.name}: severity is a whole number of pixels, "
                             f"got {self.severity}")

    @property
    def text(self) -> str:
        """``NAME:SEVERITY`` as :func:`parse_specs` reads it."""
        return f"{self.name}:{self.severity:g}"

    def rng(self, *stream: int) -> np.random.Generator:
        """Random numbers of this spec for one stream (a frame index, say); reproducible."""
        return np.random.default_rng([int(self.seed), zlib.crc32(self.name.encode()), *stream])

    def to_json(self) -> dict[str, Any]:
        return {"name": self.name, "severity": float(self.severity), "seed": int(self.seed)}


def parse_specs(text: str, *, seed: int = 0) -> tuple[DegradeSpec, ...]:
    """``"occluders:2,pose"`` -> specs in application order (a missing severity: the default).

    Raises
    ------
    ValueError
        Unknown name, bad severity, or a name given twice.
    """
    specs: dict[str, DegradeSpec] = {}
    for item in (t.strip() for t in text.split(",")):
        if not item:
            continue
        name, _, value = item.partition(":")
        name = name.strip()
        if name not in DEGRADATIONS:
            raise ValueError(f"unknown degradation {name!r} in {text!r}; choose from "
                             f"{', '.join(DEGRADATIONS)}")
        try:
            severity = float(value) if value.strip() else DEFAULT_SEVERITY[name]
        except ValueError:
            raise ValueError(f"{name}: severity {value!r} is not a number "
                             f"(write NAME:SEVERITY, e.g. {name}:1)") from None
        if name in specs:
            raise ValueError(f"degradation {name!r} given twice in {text!r}")
        specs[name] = DegradeSpec(name, severity, seed)  # type: ignore[arg-type]
    if not specs:
        raise ValueError(f"no degradation in {text!r}; write NAME[:SEVERITY],... with NAME "
                         f"from {', '.join(DEGRADATIONS)}")
    return tuple(specs[n] for n in DEGRADATIONS if n in specs)


def specs_key(specs: tuple[DegradeSpec, ...]) -> str:
    """A folder name for a set of specs, e.g. ``occluders-2_pose-0.3_seed0``."""
    parts = [f"{s.name}-{s.severity:g}" for s in specs]
    seeds = sorted({s.seed for s in specs})
    return "_".join(parts + [f"seed{'-'.join(str(s) for s in seeds)}"])
