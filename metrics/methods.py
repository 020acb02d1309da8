"""The methods the comparison knows, wired explicitly: 2D-S, 2D-SS and neural3d.

Each builder returns a :class:`~metrics.runner.MethodSpec` whose ``run`` reads a
scene folder and returns the method's :class:`~dataset.results.MethodResult`.
A method whose package cannot be imported still gets a spec: its runs fail
with the import error as the reason, and the other methods go on.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any, Literal

from dataset.method import Method, installed_methods
from dataset.protocols import TRAIN_PROTOCOL, VIEW_PROTOCOLS
from dataset.ray_tasks import TaskResources
from dataset.scene import read_scene
from metrics.runner import MethodSpec

MethodName = Literal["2D-S", "2D-SS", "neural3d"]
METHODS: tuple[str, ...] = ("2D-S", "2D-SS", "neural3d")
NEURAL3D_PROTOCOL = TRAIN_PROTOCOL
NEURAL3D_RUNS_FOLDER = "neural3d_runs"  # under the results folder: one run folder per scene
NEURAL3D_EXTRACT_FOLDER = "extract"  # in a run folder: mesh.ply, footprint.geojson, result
# What neural3d's results depend on, for their provenance records (dataset.provenance).
NEURAL3D_CODE = ("dataset", "neural3d")
NEURAL3D_LIBRARIES = ("numpy", "torch", "scipy", "scikit-image", "shapely", "trimesh", "pillow")


@dataclass(frozen=True)
class Neural3dBudget:
    """How neural3d runs inside a comparison.

    ``steps``: training steps per building (``None``: the preset's own
    ``iterations``), the budget that fixes the result; ``max_minutes``: a
    wall-clock safety cap per building (a run it stops is marked cut short);
    ``threads``: torch CPU threads (recorded, since reductions depend on it);
    ``resolution``, ``eval_frames``: marching-cubes resolution and eval frames
    (``None``: neural3d's / the preset's own); ``device``: cpu or cuda.
    """

    preset: Literal["paper", "fast", "tiny"] = "fast"
    steps: int | None = None
    max_minutes: float = 60.0
    threads: int = 2
    resolution: int | None = None
    eval_frames: int | None = None
    device: str = "cpu"

    def __post_init__(self) -> None:
        if self.steps is not None and self.steps < 1:
            raise ValueError(f"neural3d steps must be >= 1, got {self.steps}")
        if not self.max_minutes > 0:
            raise ValueError(f"neural3d max minutes must be > 0, got {self.max_minutes}")
        if self.threads < 1:
            raise ValueError(f"neural3d threads must be >= 1, got {self.threads}")
        if self.resolution is not None and self.resolution < 8:
            raise ValueError(f"neural3d resolution must be >= 8, got {self.resolution}")
        if self.eval_frames is not None and self.eval_frames < 1:
            raise ValueError(f"neural3d eval frames must be >= 1, got {self.eval_frames}")


def method_specs(
    names: tuple[str, ...],
    views: tuple[str, ...],
    results_dir: Path,
    *,
    neural3d: Neural3dBudget = Neural3dBudget(),
) -> list[MethodSpec]:
    """Specs of the named methods; view methods run on ``views``, neural3d on its train views.

    Names other than the built-in ones are looked up among the installed
    plugins (entry point group ``envelope_bench.methods``, :mod:`dataset.method`).

    Raises
    ------
    ValueError
        If a method name or a views protocol is unknown.
    """
    plugins = _check_names(names, views)
    builders = {
        "2D-S": lambda: spec_2ds(views),
        "2D-SS": lambda: spec_2dss(views),
        "neural3d": lambda: spec_neural3d(results_dir / NEURAL3D_RUNS_FOLDER, neural3d),
    }
    return [builders[name]() if name in builders else spec_from_method(plugins[name], views)
            for name in names]


def spec_from_method(method: Method, views: tuple[str, ...]) -> MethodSpec:
    """The spec of a :class:`~dataset.method.Method` run with its default config.

    It runs on the protocols it declares: of the view protocols, those in
    ``views``; others (``train``) always.
    """
    config = method.config_type()
    protocols = tuple(p for p in method.protocols if p not in VIEW_PROTOCOLS or p in views)

    def run(scene_dir: Path, protocol: str):
        return method.run(read_scene(scene_dir), protocol, config)

    resources = TaskResources(cpus=1.0, gpus=1.0 if method.resources == "gpu" else 0.0)
    return MethodSpec(method.name, protocols, _config_dict(config), run,
                      has_footprint=method.has_footprint, resources=resources,
                      code=("dataset", *method.packages), libraries=method.libraries)


def list_methods() -> list[str]:
    """One line per available method: name, inputs, protocols, resources, where it comes from."""
    lines = []
    for name in METHODS:
        lines.append(f"{name:10s} built-in   {_BUILT_IN_SUMMARY[name]}")
    for name, m in installed_methods().items():
        if name in METHODS:
            continue
        lines.append(f"{name:10s} plugin     inputs {','.join(m.inputs)}; protocols "
                     f"{','.join(m.protocols)}; {m.resources}"
                     + (f"; {m.description}" if m.description else ""))
    return lines


_BUILT_IN_SUMMARY = {
    "2D-S": "inputs semantics,depth,poses; protocols ideal,multi; cpu",
    "2D-SS": "inputs rgb,semantics,depth,poses; protocols ideal,multi; cpu",
    "neural3d": "inputs rgb,semantics,depth,poses; protocols train; cpu or gpu (--device)",
}


def spec_2ds(views: tuple[str, ...]) -> MethodSpec:
    """2D-S with its default config (``baselines.methods.METHOD_2DS``)."""
    try:
        from baselines.methods import METHOD_2DS
    except ImportError as exc:
        return _unavailable("2D-S", views, exc)
    return spec_from_method(METHOD_2DS, views)


def spec_2dss(views: tuple[str, ...]) -> MethodSpec:
    """2D-SS with its default config (``baselines.methods.METHOD_2DSS``)."""
    try:
        from baselines.methods import METHOD_2DSS
    except ImportError as exc:
        return _unavailable("2D-SS", views, exc)
    return spec_from_method(METHOD_2DSS, views)


def debug_images_2dss(scene_dir: Path, protocol: str, debug_dir: Path) -> None:
    """Run 2D-SS once more on one scene only to write its pipeline images into ``debug_dir``."""
    from baselines.wwr2dss import Wwr2dssConfig, run_2dss

    run_2dss(read_scene(scene_dir), protocol, Wwr2dssConfig(), debug_dir=debug_dir)


def spec_neural3d(runs_dir: Path, budget: Neural3dBudget) -> MethodSpec:
    """neural3d: training for ``budget.steps`` steps (``neural3d.train``) then extraction
    (``neural3d.extract``).

    The spec's config is the whole extraction config
    (``neural3d.extract_config.ExtractConfig``: resolution, footprint planes,
    measurement) plus the training config (its ``iterations`` = the step
    budget) and a ``budget`` entry (preset, steps, safety cap, threads, device),
    so a result trained, meshed or measured otherwise is recomputed. The result
    records the steps trained and whether the time cap cut training short.
    Training (and torch) is imported only when a run is needed.
    """
    from neural3d.config import config_to_dict, preset_config
    from neural3d.extract_config import ExtractConfig

    train_config = preset_config(budget.preset)
    if budget.steps is not None:
        train_config = replace(train_config, iterations=budget.steps)
    if budget.eval_frames is not None:
        # Rendering the eval frames costs about as much as a minute of CPU training.
        train_config = replace(train_config, eval_max_frames=budget.eval_frames)
    extra = {
        "budget": {"preset": budget.preset, "steps": train_config.iterations,
                   "max_seconds": budget.max_minutes * 60.0, "threads": budget.threads,
                   "device": budget.device},
        "train": config_to_dict(train_config),
    }
    extract = ExtractConfig() if budget.resolution is None else ExtractConfig(
        resolution=budget.resolution)

    def run(scene_dir: Path, protocol: str, artefacts_dir: Path = runs_dir):
        import torch

        from neural3d.checkpoint import CHECKPOINT_NAME, read_checkpoint

        # isort sees a module as first-party only once its file exists: keep this block as is.
        from neural3d.extract import extract_run  # noqa: I001
        from neural3d.train import train

        torch.set_num_threads(budget.threads)
        device = torch.device(budget.device)
        run_dir = train(scene_dir, train_config, artefacts_dir, device=device,
                        max_seconds=budget.max_minutes * 60.0)
        state = read_checkpoint(run_dir / CHECKPOINT_NAME, torch.device("cpu"))
        steps = int(state["step"])
        result = extract_run(run_dir, config=extract, device=device,
                             out_dir=run_dir / NEURAL3D_EXTRACT_FOLDER)
        return replace(result, config={**result.config, **extra}, steps=steps,
                       cut_short=steps < train_config.iterations,
                       wall_time_s=0.0)  # the runner times the whole run

    requested = {**asdict(extract), **extra}
    return MethodSpec("neural3d", (NEURAL3D_PROTOCOL,), requested, run, has_footprint=True,
                      resources=neural3d_resources(budget.device), artefacts_dir=runs_dir,
                      code=NEURAL3D_CODE, libraries=NEURAL3D_LIBRARIES)


def neural3d_resources(device: str) -> TaskResources:
    """What one neural3d run reserves on a cluster node: a GPU (and a core to feed it) on
    CUDA; on CPU two cores (torch trains with as many threads as the task has cores)."""
    if device.startswith("cuda"):
        return TaskResources(cpus=1.0, gpus=1.0)
    return TaskResources(cpus=2.0)


def neural3d_extract_dir(results_dir: Path, scene: str) -> Path:
    """Where neural3d's mesh.ply and footprint.geojson of a scene are (inside its run folder)."""
    return results_dir / NEURAL3D_RUNS_FOLDER / scene / NEURAL3D_EXTRACT_FOLDER


def _check_names(names: tuple[str, ...], views: tuple[str, ...]) -> dict[str, Method]:
    """Check the names and views; returns the installed plugins (loaded only when needed)."""
    if not names:
        raise ValueError(f"no method given; choose from {', '.join(METHODS)}")
    for view in views:
        if view not in VIEW_PROTOCOLS:
            raise ValueError(f"unknown views {view!r}; choose from {', '.join(VIEW_PROTOCOLS)}")
    plugins = installed_methods() if any(n not in METHODS for n in names) else {}
    for name in names:
        if name not in METHODS and name not in plugins:
            known = ", ".join((*METHODS, *sorted(plugins)))
            raise ValueError(f"unknown method {name!r}; choose from {known} "
                             "(`--list-methods` lists the installed ones)")
    return plugins


def _config_dict(config: Any) -> dict[str, Any]:
    return asdict(config) if hasattr(config, "__dataclass_fields__") else dict(config)


def _unavailable(name: str, protocols: tuple[str, ...], exc: ImportError) -> MethodSpec:
    reason = f"method {name} is not available: {exc}"

    def run(scene_dir: Path, protocol: str):
        raise RuntimeError(reason)

    # An empty config matches any stored result, so earlier results are still used.
    return MethodSpec(name, protocols, {}, run)
