"""The method interface: what a method declares, and how packages register one.

A :class:`Method` has a name, the inputs it reads, the protocols it runs on,
the resources it needs, its config type, the command-line options that set its
config and ``run(scene, protocol, config) -> MethodResult``. 2D-S and 2D-SS are
declared in :mod:`baselines.methods`, neural3d in :mod:`neural3d.method`, and
registered in :data:`BUILT_IN` as a plugin is under its entry point; ``metrics``
runs every method through this record (``metrics.run.methods``) and knows no method
by name.

The truth is out of a method's reach: ``scene`` is a
:class:`~envelope.method_input.MethodInput` (images, poses, intrinsics, and the depth
and semantic images the method declares in ``inputs``), never the
:class:`~envelope.scene_record.Scene` with its ``building.json``; metrics reads the
truth itself. A method's results must not change when ``building.json``, ``mesh.ply`` or
the facade-id images are removed (``tests/metrics/test_truth_blind.py`` checks the built-in ones).

Another package adds a method without touching this repository by exposing a
:class:`Method` (or a zero-argument callable returning one) under the entry
point group ``envelope_bench.methods``, e.g. in its ``pyproject.toml``::

    [project.entry-points."envelope_bench.methods"]
    my-wwr = "my_package.bench:METHOD"

``python -m metrics.compare --list-methods`` lists what is installed.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any, Literal

from envelope.method_input import Input
from envelope.method_options import Option, field_type
from envelope.protocols import TRAIN_PROTOCOL, Protocol
from envelope.results import MethodResult

ENTRY_POINT_GROUP = "envelope_bench.methods"
# The project's own methods, as ``module:attribute`` like an entry point's value, in table
# order: a string, so that this core names no package later in the data flow.
BUILT_IN: dict[str, str] = {
    "2D-S": "baselines.methods:METHOD_2DS",
    "2D-SS": "baselines.methods:METHOD_2DSS",
    "neural3d": "neural3d.method:METHOD_NEURAL3D",
}
Resource = Literal["cpu", "gpu"]
RunMethod = Callable[..., MethodResult]
"""``run(scene, protocol, config) -> MethodResult`` for one scene, ``scene`` a
:class:`~envelope.method_input.MethodInput`; may raise. A method with an ``artefacts``
folder is called ``run(scene, protocol, config, artefacts_dir=FOLDER)`` and writes its folder
for the scene and protocol at :func:`artefacts_folder` ``(FOLDER, scene, protocol)``."""


def artefacts_folder(artefacts_dir: Path, scene: str, protocol: Protocol) -> Path:
    """Where a method keeps what one run on ``scene``'s ``protocol`` views made (a trained
    method's run folder, its mesh): ``<artefacts>/<scene>`` for the orbit (``train``),
    ``<artefacts>/<protocol>/<scene>`` for every other protocol, so that two captures of one
    scene never share a folder. The one definition that methods, executors (which move the
    folder between machines) and the report (which draws the mesh in it) read."""
    if protocol == TRAIN_PROTOCOL:
        return artefacts_dir / scene
    return artefacts_dir / protocol / scene


@dataclass(frozen=True)
class Method:
    """A benchmark method.

    ``inputs``: what it reads from a scene (never the truth): its
    :class:`~envelope.method_input.MethodInput` holds the depth and semantic images
    only if they are declared here. ``protocols``:
    the view protocols it runs on (``envelope.protocols``). ``resources``:
    ``"gpu"`` if it needs one. ``config_type``: a frozen dataclass whose default
    instance is the config it runs with (its fields go into the result's
    provenance). ``packages``: importable packages whose source its results
    depend on, besides ``envelope`` (a change there recomputes its results);
    ``libraries``: distributions whose versions matter. ``has_footprint``:
    whether it estimates a footprint (it is then listed in Table 3). ``paper_name``:
    its name in the BuildNet3D paper's Tables 2 and 3, whose published figures the
    comparison shows beside its rows (``None``: the paper has no such method).

    Its config on a command line: ``options``, the flags that set its config's
    fields (:class:`~envelope.method_options.Option`; any field is also set with
    ``--set NAME.KEY=VALUE``); ``short_run``, field values of a short run (the
    comparison's built-in default run and its robustness study), under the ones a
    user gives; ``check_config(config, runs_here)``: raises ``ValueError`` when the
    config cannot run (``runs_here``: it is about to run in this process, so e.g. its
    device must exist here).

    Optional, for methods that need more: ``record_config(config)``: the config
    as its results record it (default: the dataclass's fields; the comparison writes it into
    each result and keys the result's provenance on it);
    ``reserve(config)``: ``(cpus, gpus)`` one run reserves on a cluster node
    (default: 1 CPU, and 1 GPU if ``resources`` is ``"gpu"``); ``artefacts``: the
    folder under the results folder where it keeps one folder per scene (see
    :data:`RunMethod`, :func:`artefacts_folder`); ``mesh_file``: a semantic mesh inside that folder
    (a PLY with per-vertex class ids), drawn by the figures and the HTML report;
    ``heavy``: a robustness study runs it only at each degradation's highest
    severity unless asked otherwise; ``debug_images(scene, protocol, config,
    folder)``: writes its pipeline images of one scene into ``folder`` (the
    comparison keeps one facade's for the figures and the report).
    """

    name: str
    inputs: tuple[Input, ...]
    protocols: tuple[Protocol, ...]
    config_type: type
    run: RunMethod
    resources: Resource = "cpu"
    has_footprint: bool = False
    packages: tuple[str, ...] = ()
    libraries: tuple[str, ...] = ("numpy",)
    description: str = ""
    record_config: Callable[[Any], dict[str, Any]] | None = None
    reserve: Callable[[Any], tuple[float, float]] | None = None
    artefacts: str | None = None
    mesh_file: str | None = None
    heavy: bool = False
    debug_images: Callable[..., None] | None = None
    options: tuple[Option, ...] = ()
    short_run: Mapping[str, Any] = field(default_factory=dict, hash=False)
    check_config: Callable[[Any, bool], None] | None = None
    paper_name: str | None = None

    def config_record(self, config: Any) -> dict[str, Any]:
        """``config`` as this method's results record it."""
        if self.record_config is not None:
            return self.record_config(config)
        return asdict(config) if hasattr(config, "__dataclass_fields__") else dict(config)

    def cpus_gpus(self, config: Any) -> tuple[float, float]:
        """What one run with ``config`` reserves on a cluster node: (CPUs, GPUs)."""
        if self.reserve is not None:
            return self.reserve(config)
        return 1.0, 1.0 if self.resources == "gpu" else 0.0

    def __post_init__(self) -> None:
        if not self.name or "__" in self.name or "/" in self.name:
            raise ValueError(f"method name {self.name!r} must be non-empty, without '__' or '/'")
        if not self.protocols:
            raise ValueError(f"method {self.name} runs on no protocol")
        if self.mesh_file is not None and self.artefacts is None:
            raise ValueError(f"method {self.name}: a mesh_file needs an artefacts folder")
        for key in (*(o.key for o in self.options), *self.short_run):
            try:
                field_type(self.config_type, key)
            except ValueError as exc:
                raise ValueError(f"method {self.name}: option or short-run setting {key!r}: "
                                 f"{exc}") from exc


def built_in_method(name: str) -> Method:
    """The built-in method ``name`` (imports its package; may raise ``ImportError``)."""
    module, attribute = BUILT_IN[name].split(":")
    return getattr(importlib.import_module(module), attribute)


def available_methods(warn: Callable[[str], None] | None = None) -> dict[str, Method]:
    """The built-in methods whose packages import, then the installed plugins, by name."""
    found: dict[str, Method] = {}
    for name in BUILT_IN:
        try:
            found[name] = built_in_method(name)
        except ImportError:  # the comparison reports it when the method is asked for
            continue
    for name, method in installed_methods(warn).items():
        found.setdefault(name, method)
    return found


def installed_methods(warn: Callable[[str], None] | None = None) -> dict[str, Method]:
    """Methods registered under ``envelope_bench.methods``, by name.

    An entry point that fails to load or is not a :class:`Method` is skipped
    with a line to ``warn`` (stderr by default); the others load.
    """
    warn = warn or (lambda line: print(line, file=sys.stderr))
    found: dict[str, Method] = {}
    for ep in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
        try:
            obj = ep.load()
            method = obj if isinstance(obj, Method) else obj()
        except Exception as exc:  # a broken plugin must not stop the benchmark
            warn(f"method plugin {ep.name} ({ep.value}) skipped: {type(exc).__name__}: {exc}")
            continue
        if not isinstance(method, Method):
            warn(f"method plugin {ep.name} ({ep.value}) skipped: not a envelope.method.Method")
            continue
        found.setdefault(method.name, method)
    return found
