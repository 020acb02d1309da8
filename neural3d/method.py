"""neural3d as a benchmark method (:class:`envelope.method.Method`): train, then extract.

Its config, :class:`Neural3dBudget`, is the step budget and the few settings a
comparison chooses; the training and extraction configs follow from it
(:func:`train_config`, :func:`extract_config`), and its results record all three.
It declares its command-line options (:data:`OPTIONS`: ``--neural3d-steps``,
``--device``, ...) and the budget of a short run (:data:`SHORT_RUN`). Training
(and torch) is imported only when a run is needed.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any, Literal

from envelope.method import Method, artefacts_folder
from envelope.method_input import MethodInput, require_method_input
from envelope.method_options import Option
from envelope.protocols import STREET_PROTOCOL, TRAIN_PROTOCOL
from envelope.results import MethodResult
from envelope.scene_record import scene_name
from neural3d.config import TrainConfig, config_to_dict, preset_config
from neural3d.extract import METHOD_NAME, measure_run
from neural3d.extraction.extract_config import ExtractConfig

RUNS_FOLDER = "neural3d_runs"  # under the results folder: one run folder per scene
EXTRACT_FOLDER = "extract"  # in a run folder: mesh.ply, footprint.geojson
LIBRARIES = ("numpy", "torch", "scipy", "scikit-image", "shapely", "trimesh", "pillow")


@dataclass(frozen=True)
class Neural3dBudget:
    """How neural3d runs inside a comparison.

    ``steps``: training steps per building (``None``: the preset's own
    ``iterations``), the budget that fixes the result; ``max_minutes``: a
    wall-clock safety cap per building (a run it stops is marked cut short);
    ``threads``: torch CPU threads (recorded, since reductions depend on it);
    ``resolution``, ``eval_frames``: marching-cubes resolution and eval frames
    (``None``: neural3d's / the preset's own); ``device``: cpu or cuda; ``seed``:
    the training seed (weights, ray batches), so that repeated trainings differ only by it.
    ``runs_per_gpu``: how many runs share one GPU at once under a scheduler (the
    ``processes`` and ``ray`` executors); not recorded, since it changes no result.
    """

    preset: Literal["paper", "fast", "tiny"] = "fast"
    steps: int | None = None
    max_minutes: float = 60.0
    threads: int = 2
    resolution: int | None = None
    eval_frames: int | None = None
    device: str = "cpu"
    seed: int = 0
    runs_per_gpu: int = 8

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
        if self.runs_per_gpu < 1:
            raise ValueError(f"neural3d runs per GPU must be >= 1, got {self.runs_per_gpu}")


OPTIONS = (
    Option("--neural3d-steps", "steps", "training steps per building: the budget that fixes "
           "the result (default: the preset's own iterations)"),
    Option("--neural3d-max-minutes", "max_minutes", "safety cap on the training time per "
           "building, minutes; a run it stops is marked 'cut short' in every table"),
    Option("--neural3d-threads", "threads", "torch CPU threads (recorded with the result)"),
    Option("--neural3d-preset", "preset", "training preset (neural3d.config.preset_config)"),
    Option("--neural3d-resolution", "resolution", "marching-cubes samples along the scene "
           f"box's longest side (default: the extraction's own, {ExtractConfig.resolution})"),
    Option("--device", "device", "torch device: cpu, cuda or cuda:N"),
    Option("--neural3d-runs-per-gpu", "runs_per_gpu", "with --device cuda, how many "
           "trainings share one GPU at once under --executor processes or ray (each "
           "reserves that fraction of it; 8 fill an H100)"),
)
# The built-in default comparison (tiny benchmark) and the robustness study: the smallest
# step budget measured with every building within WWR error 5 % and footprint IoU 0.96
# (docs/decisions.md, 2026-11-24 "neural3d default budget"), marching cubes at 128, one
# eval frame (rendering the preset's four costs about a minute of CPU per building) and one
# torch thread, so that the comparison trains two buildings at once on two cores, each
# in its own process, which gets more steps out of a core than two threads on one building
# (docs/decisions.md, 2026-11-27 "neural3d one thread a building").
SHORT_RUN = {"steps": 2000, "resolution": 128, "eval_frames": 1, "threads": 1}


def trained_runs(results_dir: Path, scenes: list[str] | None = None) -> list[Path]:
    """The run folders a comparison kept under ``results_dir / RUNS_FOLDER`` that hold a
    trained field (``checkpoint.pt``), sorted; only ``scenes`` when given. Empty when
    there is no such folder."""
    runs_dir = Path(results_dir) / RUNS_FOLDER
    if not runs_dir.is_dir():
        return []
    return sorted(p for p in runs_dir.iterdir() if (p / "checkpoint.pt").is_file()
                  and (scenes is None or p.name in scenes))


def trained_scene_dirs(runs: list[Path]) -> list[Path]:
    """The scene folder each run folder of :func:`trained_runs` was trained on (its
    ``run.json``); runs without a readable record are skipped."""
    out = []
    for run in runs:
        try:
            out.append(Path(json.loads((Path(run) / "run.json").read_text())["scene_dir"]))
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return out


def check_budget(budget: Neural3dBudget, runs_here: bool) -> None:
    """Refuse a device that is not a torch CPU/CUDA device, or (``runs_here``) not here."""
    from envelope.device import resolve_device

    resolve_device(budget.device, available=runs_here)


def train_config(budget: Neural3dBudget) -> TrainConfig:
    """The preset's training config with the budget's steps, eval frames and seed."""
    config = replace(preset_config(budget.preset), seed=budget.seed)
    if budget.steps is not None:
        config = replace(config, iterations=budget.steps)
    if budget.eval_frames is not None:
        # Rendering the eval frames costs about as much as a minute of CPU training.
        config = replace(config, eval_max_frames=budget.eval_frames)
    return config


def extract_config(budget: Neural3dBudget) -> ExtractConfig:
    """The extraction config: neural3d's own, at the budget's resolution if it gives one."""
    return ExtractConfig() if budget.resolution is None else ExtractConfig(
        resolution=budget.resolution)


def record_config(budget: Neural3dBudget) -> dict[str, Any]:
    """What a result records: the whole extraction config (resolution, footprint planes,
    measurement), the training config (its ``iterations`` = the step budget) and a
    ``budget`` entry (preset, steps, safety cap, threads, device), so a result trained,
    meshed or measured otherwise is recomputed."""
    train = train_config(budget)
    return {
        **asdict(extract_config(budget)),
        "budget": {"preset": budget.preset, "steps": train.iterations,
                   "max_seconds": budget.max_minutes * 60.0, "threads": budget.threads,
                   "device": budget.device},
        "train": config_to_dict(train),
    }


def run_neural3d(scene: MethodInput, protocol: str, budget: Neural3dBudget, *,
                 artefacts_dir: Path) -> MethodResult:
    """Train for ``budget.steps`` steps (``neural3d.train``, on ``scene`` as read here, on the
    frames of ``protocol``: ``train``, the orbit, or ``street``) into the run folder that
    :func:`envelope.method.artefacts_folder` names, then mesh and measure it
    (``neural3d.extract``) into its ``extract`` folder; the result is returned, not written
    (the runner writes it).

    A run folder already there with the same training provenance
    (:func:`neural3d.training.run_folder.training_provenance`: training code, config,
    scene, device, threads, libraries) is not trained again: a finished one is only
    extracted again (after a change to meshing or measuring), a partial one (a comparison
    stopped mid-building) is resumed. The result records the steps trained, whether the
    time cap cut training short, and, when training was reused, says so in ``warnings``
    with ``wall_time_s`` = the stored training and evaluation seconds + this extraction.
    Its config is :func:`record_config`'s.
    """
    require_method_input(scene, "neural3d")
    import torch

    # isort sees a module as first-party only once its file exists: keep this block as is.
    from neural3d.field.checkpoint import CHECKPOINT_NAME, read_checkpoint
    from neural3d.train import train
    from neural3d.training.run_folder import prior_run, training_provenance

    config = train_config(budget)
    torch.set_num_threads(budget.threads)
    device = torch.device(budget.device)
    run_dir = artefacts_folder(Path(artefacts_dir), scene_name(scene.root), protocol)
    prior = prior_run(run_dir, training_provenance(scene.root, config, device, split=protocol),
                      config.iterations)
    if prior != "finished":
        run_dir = train(scene, config, run_dir.parent, device=device, split=protocol,
                        resume=prior == "partial", max_seconds=budget.max_minutes * 60.0)
    state = read_checkpoint(run_dir / CHECKPOINT_NAME, torch.device("cpu"))
    steps = int(state["step"])
    tic = time.perf_counter()
    result = measure_run(run_dir, config=extract_config(budget), device=device,
                         out_dir=run_dir / EXTRACT_FOLDER)
    reused = ()
    wall_time_s = 0.0  # the runner times the whole run
    if prior == "finished":
        trained_s = float(state["train_s"]) + float(state.get("eval_s", 0.0))
        reused = (f"training reused: {run_dir} was trained earlier with the same training "
                  f"code, config and scene ({trained_s:.0f} s); only extraction ran",)
        wall_time_s = trained_s + time.perf_counter() - tic
    return replace(result, config=record_config(budget), steps=steps,
                   cut_short=steps < config.iterations, wall_time_s=wall_time_s,
                   warnings=result.warnings + reused, seed=budget.seed)


def reserve(budget: Neural3dBudget) -> tuple[float, float]:
    """(CPUs, GPUs) one run reserves on a cluster node or this machine: on CUDA a core to
    feed the GPU and ``1 / runs_per_gpu`` of it (a `fast` step leaves a large GPU mostly
    idle, so several runs share one); on CPU a core per torch thread."""
    if budget.device.startswith("cuda"):
        return 1.0, 1.0 / budget.runs_per_gpu
    return float(budget.threads), 0.0


METHOD_NEURAL3D = Method(
    name=METHOD_NAME, inputs=("rgb", "semantics", "depth", "poses"),
    protocols=(TRAIN_PROTOCOL, STREET_PROTOCOL),
    config_type=Neural3dBudget, run=run_neural3d, has_footprint=True,
    packages=("neural3d",), libraries=LIBRARIES,
    description="semantic neural SDF trained on the orbit (train) or street views; WWR, areas "
                "and footprint measured on its mesh (cpu or gpu: --device)",
    record_config=record_config, reserve=reserve, artefacts=RUNS_FOLDER,
    mesh_file=f"{EXTRACT_FOLDER}/mesh.ply", heavy=True,
    options=OPTIONS, short_run=SHORT_RUN, check_config=check_budget, paper_name="BuildNet3D",
)
