"""The result file every method writes: one JSON per (scene, method, protocol) (docs/DESIGN.md).

Methods (``baselines``, ``neural3d``) write these; ``metrics.compare`` reads
only these and the scenes' ground truth.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Literal

from envelope.atomic import write_json_atomic
from envelope.orientation import OrientationBin, orientation_bin
from envelope.protocols import VIEW_PROTOCOLS
from envelope.provenance import Provenance, code_version

__all__ = ["FacadeEstimate", "MethodResult", "code_version", "read_result", "result_filename",
           "write_result"]

RESULT_SCHEMA_VERSION = 1
FacadeIdentity = Literal["truth_id", "geometry"]
"""How a result's facades relate to the truth's: ``truth_id``, its ids are the truth's
(methods run on views that carry facade ids); ``geometry``, it numbers its own facades
and gives each a ``normal`` and ``centre_m`` to be matched by
(:mod:`metrics.score.facade_match`)."""


@dataclass(frozen=True)
class FacadeEstimate:
    """A method's figures for one facade; ``missing`` + ``reason`` when it had no usable view.

    ``normal`` (outward unit vector) and ``centre_m`` (area-weighted centroid of
    the facade's surface) are in the world frame, for methods whose ids are
    their own (neural3d): evaluation matches such facades to the truth's by
    them (:mod:`metrics.score.facade_match`). ``None`` where the method does not say.
    ``azimuth_deg`` is the facade's outward azimuth, degrees clockwise from true
    north (:mod:`envelope.orientation`); methods leave it ``None`` (they do not
    know north) and evaluation fills it (:mod:`metrics.export.table`).
    """

    id: int
    wwr: float | None
    window_area_m2: float | None = None
    facade_area_m2: float | None = None
    width_m: float | None = None
    height_m: float | None = None
    views_used: int = 0
    missing: bool = False
    reason: str = ""
    normal: tuple[float, float, float] | None = None
    centre_m: tuple[float, float, float] | None = None
    azimuth_deg: float | None = None

    @property
    def orientation(self) -> OrientationBin | None:
        """EnergyPlus bin (N, E, S, W) of ``azimuth_deg``; ``None`` without one."""
        return None if self.azimuth_deg is None else orientation_bin(self.azimuth_deg)

    @staticmethod
    def from_json_dict(d: dict[str, Any]) -> FacadeEstimate:
        """From JSON, where vectors are lists; files without ``normal``/``centre_m`` load too."""
        vectors = {k: tuple(float(x) for x in d[k]) for k in ("normal", "centre_m")
                   if d.get(k) is not None}
        return FacadeEstimate(**{**d, **vectors})


@dataclass(frozen=True)
class MethodResult:
    """A method's estimate for one building under one protocol.

    ``footprint`` is a GeoJSON Polygon in world x/y metres, or ``None`` for
    methods that do not estimate one. ``config`` is the method's full config;
    ``code_version`` the git commit (or package version) that produced it.
    ``config`` is kept as it reads back from JSON (tuples become lists), so a
    result equals itself after a write and a read. ``provenance`` is the full
    record of what made it (:mod:`envelope.provenance`; the runner attaches it,
    and compares it to decide reuse). ``steps`` is the number of optimisation
    steps an iterative method took (``None`` for the others); ``cut_short``
    says a safety time cap stopped it before its step budget.
    ``facade_identity`` says how its facades are matched to the truth's.
    ``seed``: the seed of a method trained from random weights (neural3d), so that
    runs with several seeds keep one file each (:func:`result_filename`); ``None``
    for a method without one.
    """

    scene: str
    method: str  # "2D-S" | "2D-SS" | "neural3d" | a variant name
    protocol: str  # "ideal" | "multi" | "train"
    wwr: float | None
    window_area_m2: float | None
    facade_area_m2: float | None
    facades: tuple[FacadeEstimate, ...] = ()
    footprint: dict[str, Any] | None = None
    config: dict[str, Any] = field(default_factory=dict)
    code_version: str = ""
    wall_time_s: float = 0.0
    warnings: tuple[str, ...] = ()
    steps: int | None = None
    cut_short: bool = False
    provenance: Provenance | None = None
    facade_identity: FacadeIdentity = "truth_id"
    seed: int | None = None
    schema_version: int = RESULT_SCHEMA_VERSION

    def __post_init__(self) -> None:
        object.__setattr__(self, "config", json.loads(json.dumps(self.config)))

    def to_json_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["facades"] = [asdict(f) for f in self.facades]
        d["warnings"] = list(self.warnings)
        return d

    @staticmethod
    def from_json_dict(d: dict[str, Any]) -> MethodResult:
        return MethodResult(
            **{
                **d,
                "facades": tuple(FacadeEstimate.from_json_dict(f) for f in d.get("facades", ())),
                "warnings": tuple(d.get("warnings", ())),
                # Files written before the field existed: ideal/multi results carry truth ids.
                "facade_identity": d.get("facade_identity") or (
                    "truth_id" if d.get("protocol") in VIEW_PROTOCOLS else "geometry"),
                "provenance": None if d.get("provenance") is None
                else Provenance.from_json_dict(d["provenance"]),
            }
        )


def result_filename(scene: str, method: str, protocol: str, seed: int | None = None) -> str:
    """File name of a result, e.g. ``tiny_skyscraper_0__2D-SS__ideal.json``; a seed other than
    0 (the default one, whose files keep the plain name) adds ``__seed<k>``."""
    suffix = f"__seed{seed}" if seed else ""
    return f"{scene}__{method}__{protocol}{suffix}.json"


def write_result(folder: str | Path, result: MethodResult) -> Path:
    """Write ``result`` atomically into ``folder``; returns the file path."""
    path = Path(folder) / result_filename(result.scene, result.method, result.protocol,
                                          result.seed)
    write_json_atomic(path, result.to_json_dict())
    return path


def read_result(path: str | Path) -> MethodResult:
    """Read a result file.

    Raises
    ------
    ValueError
        If the file is missing, not JSON, or not a result of this schema.
    """
    path = Path(path)
    try:
        return MethodResult.from_json_dict(json.loads(path.read_text()))
    except FileNotFoundError as exc:
        raise ValueError(f"result file {path} does not exist") from exc
    except (ValueError, TypeError, KeyError) as exc:  # JSON and Unicode errors are ValueErrors
        raise ValueError(f"{path} is not a valid result file: {exc}") from exc
