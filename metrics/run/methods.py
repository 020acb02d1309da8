"""The methods the comparison runs, all through :class:`envelope.method.Method`.

The built-in ones are found where :data:`envelope.method.BUILT_IN` says
they are declared; any other name is looked up among the installed plugins
(entry point group ``envelope_bench.methods``). Each becomes a
:class:`~metrics.run.runner.MethodSpec` whose ``run`` reads a scene folder as the
method's :class:`~envelope.method_input.MethodInput` (no truth: metrics alone
reads ``building.json``) and returns the method's result. A built-in
method whose package cannot be imported still gets a spec: its runs fail with
the import error as the reason, and the other methods go on.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any

from envelope.method import BUILT_IN, Method, built_in_method, installed_methods
from envelope.protocols import PROTOCOLS
from metrics.run.runner import MethodSpec, config_seed, folder_spec, run_on_folder

METHODS: tuple[str, ...] = tuple(BUILT_IN)


def method_specs(
    names: tuple[str, ...],
    views: tuple[str, ...],
    results_dir: Path,
    *,
    configs: Mapping[str, Any] | None = None,
    seeds: tuple[int, ...] = (0,),
) -> list[MethodSpec]:
    """Specs of the named methods, each run with ``configs[name]`` (default: its config
    type's default instance); view methods run on ``views``. A method whose config has a
    ``seed`` field (neural3d: the training seed) gets one spec per seed of ``seeds``.

    Raises
    ------
    ValueError
        If a method name or a views protocol is unknown.
    """
    plugins = _check_names(names, views)
    configs = configs or {}
    specs = []
    for name in names:
        try:
            method = built_in_method(name) if name in BUILT_IN else plugins[name]
        except ImportError as exc:
            specs.append(_unavailable(name, views, exc))
            continue
        config = configs.get(name)
        config = method.config_type() if config is None else config
        if config_seed(config) is not None:
            specs += [spec_from_method(method, views, results_dir, replace(config, seed=s))
                      for s in seeds]
        else:
            specs.append(spec_from_method(method, views, results_dir, config))
    return specs


def spec_from_method(method: Method, views: tuple[str, ...], results_dir: Path,
                     config: Any = None) -> MethodSpec:
    """The spec of ``method`` run with ``config`` (``None``: its config type's default).

    It runs on the protocols it declares that ``views`` names (ideal, multi, train: the
    orbit views, street). A method with an ``artefacts`` folder
    keeps it under ``results_dir`` (a seed other than 0 in ``seed<k>/`` below it).
    """
    config = method.config_type() if config is None else config
    protocols = tuple(p for p in method.protocols if p in views)
    seed = config_seed(config)
    artefacts_dir = results_dir / method.artefacts if method.artefacts else None
    if artefacts_dir is not None and seed:
        artefacts_dir = artefacts_dir / f"seed{seed}"
    run = partial(run_on_folder, method, config)
    if artefacts_dir is not None:
        run = partial(run, artefacts_dir=artefacts_dir)
    return MethodSpec(method, config, protocols, run, artefacts_dir=artefacts_dir)


def list_methods() -> list[str]:
    """One line per available method: name, where it comes from, inputs, protocols, resources."""
    lines = []
    found = {name: "built-in" for name in METHODS}
    plugins = installed_methods()
    found.update({name: "plugin" for name in plugins if name not in BUILT_IN})
    for name, origin in found.items():
        try:
            m = built_in_method(name) if origin == "built-in" else plugins[name]
        except ImportError as exc:
            lines.append(f"{name:10s} {origin:10s} not available: {exc}")
            continue
        lines.append(f"{name:10s} {origin:10s} inputs {','.join(m.inputs)}; protocols "
                     f"{','.join(m.protocols)}; {m.resources}"
                     + (f"; {m.description}" if m.description else ""))
    return lines


def _check_names(names: tuple[str, ...], views: tuple[str, ...]) -> dict[str, Method]:
    """Check the names and views; returns the installed plugins (loaded only when needed)."""
    if not names:
        raise ValueError(f"no method given; choose from {', '.join(METHODS)}")
    for view in views:
        if view not in PROTOCOLS:
            raise ValueError(f"unknown views {view!r}; choose from {', '.join(PROTOCOLS)}")
    plugins = installed_methods() if any(n not in METHODS for n in names) else {}
    for name in names:
        if name not in METHODS and name not in plugins:
            known = ", ".join((*METHODS, *sorted(plugins)))
            raise ValueError(f"unknown method {name!r}; choose from {known} "
                             "(`--list-methods` lists the installed ones)")
    return plugins


def _unavailable(name: str, protocols: tuple[str, ...], exc: ImportError) -> MethodSpec:
    reason = f"method {name} is not available: {exc}"

    def run(scene_dir: Path, protocol: str, **_: Any):
        raise RuntimeError(reason)

    # An empty config matches any stored result, so earlier results are still used.
    return folder_spec(name, protocols, {}, run)
