"""Provenance records: what made a scene, a trained run or a result, so that caches can trust it.

A :class:`Provenance` holds the config, a fingerprint of the code (a SHA-256 of
the source files of every module involved), a fingerprint of the inputs (a
scene's own record for a result; the recipe and seed for a scene) and the
versions of the libraries the computation ran with. :func:`make_provenance`
builds one; :func:`provenance_changes` compares a stored record with the one
the current code would write and says, in words, which parts differ. A cache
entry is reused only when that list is empty.

``code_version`` (git commit or package version) is shown to people but not
compared: the source fingerprints are exact and do not change with edits to
documentation or to packages the computation does not use.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import platform
import subprocess
from dataclasses import asdict, dataclass, field
from functools import cache
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any, Literal

DIGEST_CHARS = 16  # hex characters kept of a SHA-256: 64 bits, ample to tell versions apart


@dataclass(frozen=True)
class Provenance:
    """What produced a file, as JSON-ready fields.

    ``config``: the settings it ran with; ``code``: module name -> source
    fingerprint; ``inputs``: what it read (e.g. ``{"scene": <fingerprint>}``);
    ``environment``: library -> version (and ``python``); ``code_version``:
    the git commit or package version, informational only.
    """

    config: dict[str, Any]
    code: dict[str, str]
    inputs: dict[str, Any]
    environment: dict[str, str]
    code_version: str = ""
    notes: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("config", "inputs", "notes"):
            object.__setattr__(self, name, _as_json(getattr(self, name)))

    def to_json_dict(self) -> dict[str, Any]:
        return asdict(self)

    @staticmethod
    def from_json_dict(d: dict[str, Any]) -> Provenance:
        """Read a record back; raises ``ValueError`` if ``d`` is not one."""
        try:
            return Provenance(**d)
        except TypeError as exc:
            raise ValueError(f"not a provenance record: {exc}") from exc

    def digest(self) -> str:
        """A fingerprint of the compared parts (``code_version`` and ``notes`` left out)."""
        compared = {k: v for k, v in self.to_json_dict().items()
                    if k not in ("code_version", "notes")}
        return _sha256(json.dumps(compared, sort_keys=True).encode())


def make_provenance(
    config: dict[str, Any], *, modules: tuple[str, ...], inputs: dict[str, Any],
    libraries: tuple[str, ...] = ("numpy",), notes: dict[str, Any] | None = None,
) -> Provenance:
    """The record the current code writes for a computation.

    ``modules`` are importable module or package names whose source files the
    computation depends on (a package counts with every ``.py`` file under it);
    ``libraries`` are distribution names whose installed versions it depends on.
    ``notes`` are recorded but not compared (e.g. the time a run took).
    """
    return Provenance(
        config=config,
        code={m: code_fingerprint(m) for m in modules},
        inputs=inputs,
        environment={"python": platform.python_version(),
                     **{lib: library_version(lib) for lib in libraries}},
        code_version=code_version(),
        notes=notes or {},
    )


ChangedPart = Literal["record", "code", "inputs", "config", "environment"]


@dataclass(frozen=True)
class ProvenanceChange:
    """One difference between a stored record and the current one: which part, in words."""

    part: ChangedPart
    message: str

    def __str__(self) -> str:
        return self.message


def provenance_changes(
    stored: Provenance | None, current: Provenance
) -> list[ProvenanceChange]:
    """What differs between a stored record and the current one; ``[]``: nothing.

    Messages read e.g. ``"code of neural3d changed"``, ``"inputs changed (scene
    re-rendered)"``, ``"config changed: iterations 2000 -> 500"``, ``"torch
    2.13.0 -> 2.14.1"``, ``"no provenance record (made by older code)"``.
    """
    if stored is None:
        return [ProvenanceChange("record", "no provenance record (made by older code)")]
    changes = []
    for module in sorted(set(stored.code) | set(current.code)):
        if stored.code.get(module) != current.code.get(module):
            changes.append(ProvenanceChange("code", f"code of {module} changed"))
    if stored.inputs != current.inputs:
        changes.append(ProvenanceChange("inputs", _inputs_change(stored.inputs, current.inputs)))
    if stored.config != current.config:
        changes.append(ProvenanceChange(
            "config", "config changed: " + _diff_keys(stored.config, current.config)))
    for lib in sorted(set(stored.environment) | set(current.environment)):
        old, new = stored.environment.get(lib), current.environment.get(lib)
        if old != new:
            changes.append(ProvenanceChange("environment", f"{lib} {old} -> {new}"))
    return changes


@cache
def code_fingerprint(module: str) -> str:
    """SHA-256 (first :data:`DIGEST_CHARS` hex) of a module's or package's ``.py`` source files.

    Files are hashed in sorted relative-path order with their paths, so a
    renamed file changes the fingerprint too. Computed once per process.

    Raises
    ------
    ValueError
        If the module cannot be found.
    """
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        raise ValueError(f"cannot fingerprint module {module!r}: not importable")
    origin = Path(spec.origin)
    if spec.submodule_search_locations:
        root = origin.parent
        files = sorted(p for p in root.rglob("*.py") if "__pycache__" not in p.parts)
    else:
        root, files = origin.parent, [origin]
    h = hashlib.sha256()
    for path in files:
        h.update(path.relative_to(root).as_posix().encode() + b"\0")
        h.update(path.read_bytes() + b"\0")
    return h.hexdigest()[:DIGEST_CHARS]


def file_fingerprint(path: str | Path) -> str:
    """SHA-256 (first :data:`DIGEST_CHARS` hex) of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:DIGEST_CHARS]


def library_version(distribution: str) -> str:
    """Installed version of a distribution (no import), or ``"absent"``."""
    try:
        return version(distribution)
    except PackageNotFoundError:
        return "absent"


@cache
def code_version() -> str:
    """The git commit of the code (with ``-dirty`` for local changes), or the package version."""
    here = Path(__file__).resolve().parent.parent
    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            cwd=here, capture_output=True, text=True, timeout=5, check=True,
        )
        return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        try:
            return "envelope-bench " + version("envelope-bench")
        except PackageNotFoundError:
            return "unknown"


def _inputs_change(old: dict[str, Any], new: dict[str, Any]) -> str:
    if set(old) == set(new) == {"scene"}:
        return "inputs changed (scene re-rendered)"
    return "inputs changed: " + _diff_keys(old, new)


def _diff_keys(old: dict[str, Any], new: dict[str, Any], prefix: str = "") -> str:
    parts = []
    for key in sorted(set(old) | set(new)):
        a, b = old.get(key), new.get(key)
        if a == b:
            continue
        if isinstance(a, dict) and isinstance(b, dict):
            parts.append(_diff_keys(a, b, f"{prefix}{key}."))
        else:
            parts.append(f"{prefix}{key} {_short(a)} -> {_short(b)}")
    return ", ".join(parts)


def _short(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:DIGEST_CHARS]


def _as_json(obj: Any) -> Any:
    return json.loads(json.dumps(obj, default=str))
