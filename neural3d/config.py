"""Typed configs of the semantic neural SDF and its three presets (the one source of defaults).

``paper`` follows the BuildNet3D / NeuS settings (8x256 MLP, for a GPU);
``fast`` is the default, tuned for a 2-core CPU; ``tiny`` is for tests.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
from typing import Any, Literal

Backbone = Literal["mlp", "grid"]
Normals = Literal["analytic", "finite_difference"]
PresetName = Literal["paper", "fast", "tiny"]
PRESETS: tuple[str, ...] = ("paper", "fast", "tiny")


@dataclass(frozen=True)
class FieldConfig:
    """Architecture of the SDF, colour, semantic and background networks.

    Lengths are in the normalised frame, where the scene box's longest half-side is 1.
    """

    backbone: Backbone = "grid"
    feature_dim: int = 32  # geometry feature passed to the colour and semantic heads
    init_radius: float = 0.5  # geometric initialisation: SDF of a sphere of this radius
    normals: Normals = "analytic"
    fd_step: float = 1e-3  # finite-difference step when normals == "finite_difference"
    # mlp backbone (NeuS / the paper)
    mlp_hidden: int = 256
    mlp_layers: int = 8
    mlp_skip: int = 4
    mlp_frequencies: int = 6
    # grid backbone: multi-resolution grid, dense while a level fits the table, hashed above
    grid_levels: int = 12
    grid_features: int = 2
    grid_min_res: int = 16
    grid_max_res: int = 256
    grid_log2_table: int = 18
    grid_hidden: int = 64
    grid_coarse_to_fine_steps: int = 1000  # iterations until every level is switched on
    grid_start_levels: int = 4
    # heads
    colour_hidden: int = 64
    colour_layers: int = 2
    semantic_hidden: int = 128
    view_frequencies: int = 4
    background_hidden: int = 64
    init_inv_s: float = 20.0  # NeuS inverse standard deviation at the start (learnt, log scale)


@dataclass(frozen=True)
class TrainConfig:
    """Everything one training run depends on; ``config.json`` of a run is this, as JSON."""

    model: FieldConfig = FieldConfig()
    iterations: int = 2000
    rays_per_batch: int = 512
    lr: float = 5e-3
    lr_final_factor: float = 0.05  # cosine decay ends at lr * this
    warmup: int = 100
    # 16 + 16 samples per ray inside the occupancy grid's interval: 1.4x faster than 24 + 24
    # at the held-out accuracy of 24 + 24 within the seed-to-seed spread (docs/decisions.md)
    samples_uniform: int = 16
    samples_importance: int = 16
    upsample_steps: int = 2
    # samples whose rendering weight is at most this are dropped from the rendering (as if
    # transparent: their colour and semantics are not evaluated; ~60 % of the samples late
    # in training); 0 = keep every sample
    min_sample_weight: float = 1e-4
    # samples whose weight, guessed before the field pass from the up-sampling's SDF at the
    # section ends (neural3d.rendering.neus.edge_alpha), is at most this are not evaluated
    # at all (no SDF gradient, no eikonal term: transparent); 0 = evaluate every sample.
    # On in fast: about half the samples late in training, 0.7-0.85x the training time
    # (docs/decisions.md, 2026-11-27 "samples guessed light")
    min_estimated_weight: float = 1e-4
    # fixed-shape step (neural3d.rendering.fixed_shape): 0 = off, the step renders only the rays
    # that hit and evaluates only the samples it keeps (shapes that follow the data); N > 0 =
    # every ray is rendered and the field is evaluated at N sample slots a batch (padded and
    # masked; candidates beyond N are dropped and counted), so no shape depends on the data
    # and the step can be captured as a CUDA graph. Off in every preset (docs/decisions.md,
    # 2026-11-29 "a fixed-shape step, off")
    sample_buffer: int = 0
    cos_anneal_steps: int = 0  # NeuS cos-anneal length; 0 = no annealing
    rgb_weight: float = 1.0
    eikonal_weight: float = 0.1
    semantic_weight: float = 0.5
    mask_weight: float = 0.1  # silhouette term from the background class (0 = off)
    depth_loss: bool = False  # variant: supervise rendered depth with the depth images
    depth_weight: float = 0.1
    # empty-space skipping (neural3d.rendering.occupancy), on in fast: ~1.9x it/s; 0 = off
    occupancy_resolution: int = 64  # cells along the box's longest side
    occupancy_start: int = 200  # first refresh from the SDF (the box until then)
    occupancy_every: int = 50  # steps between refreshes
    occupancy_margin_cells: float = 1.0  # |sdf| margin beyond the half diagonal, in cells
    # weight averaging: the measured field is an exponential moving average of the trained
    # one (decay per step; 0 = off); evaluations, callbacks and load_trained_field use it.
    # On in fast: the late checks' WWR spread fell from 5-10 points to ~1 (docs/decisions.md,
    # 2026-11-25 "weight averaging on"; docs/measurements/neural3d-paper-preset.md)
    ema_decay: float = 0.995
    image_scale: float = 1.0  # images are resized by this factor on load
    scene_box_margin: float = 0.1  # fraction of the visual-hull box added on each side
    eval_every: int = 500
    eval_max_frames: int = 4
    eval_rays_per_frame: int = 1024  # random pixels of each eval frame, drawn once (0 = all)
    checkpoint_every: int = 500
    seed: int = 0

    def __post_init__(self) -> None:
        positive = ("iterations", "rays_per_batch", "samples_uniform", "eval_every",
                    "checkpoint_every", "eval_max_frames")
        for name in positive:
            if getattr(self, name) <= 0:
                raise ValueError(f"TrainConfig.{name} must be positive, got {getattr(self, name)}")
        if self.occupancy_resolution and (self.occupancy_resolution < 2
                                          or self.occupancy_every <= 0):
            raise ValueError(f"TrainConfig needs occupancy_resolution 0 (off) or >= 2 and "
                             f"occupancy_every > 0, got {self.occupancy_resolution}, "
                             f"{self.occupancy_every}")
        if not 0.0 <= self.ema_decay < 1.0:
            raise ValueError(f"TrainConfig.ema_decay must be in [0, 1), got {self.ema_decay}")
        if not 0.0 <= self.min_sample_weight < 1.0:
            raise ValueError(f"TrainConfig.min_sample_weight must be in [0, 1), got "
                             f"{self.min_sample_weight}")
        if not 0.0 <= self.min_estimated_weight < 1.0:
            raise ValueError(f"TrainConfig.min_estimated_weight must be in [0, 1), got "
                             f"{self.min_estimated_weight}")
        if self.sample_buffer < 0:
            raise ValueError(f"TrainConfig.sample_buffer must be >= 0 (0 = off), got "
                             f"{self.sample_buffer}")
        if self.eval_rays_per_frame < 0:
            raise ValueError(f"TrainConfig.eval_rays_per_frame must be >= 0 (0 = every pixel), "
                             f"got {self.eval_rays_per_frame}")
        if self.lr <= 0 or not 0 < self.image_scale <= 1:
            raise ValueError(
                f"TrainConfig needs lr > 0 and 0 < image_scale <= 1, got lr={self.lr}, "
                f"image_scale={self.image_scale}"
            )
        if self.model.backbone not in ("mlp", "grid"):
            raise ValueError(f"unknown backbone {self.model.backbone!r}; use 'mlp' or 'grid'")
        if self.model.normals not in ("analytic", "finite_difference"):
            raise ValueError(
                f"unknown normals {self.model.normals!r}; use 'analytic' or 'finite_difference'"
            )


def preset_config(name: PresetName) -> TrainConfig:
    """The config of preset ``name``: ``paper``, ``fast`` (the default) or ``tiny``."""
    if name == "paper":
        return TrainConfig(
            model=FieldConfig(backbone="mlp", feature_dim=256, colour_hidden=256,
                              colour_layers=4, init_inv_s=7.4),
            iterations=100_000, rays_per_batch=2048, lr=5e-4, warmup=5000,
            samples_uniform=64, samples_importance=64, upsample_steps=4,
            min_sample_weight=0.0, min_estimated_weight=0.0, cos_anneal_steps=50_000,
            mask_weight=0.0, ema_decay=0.0,
            eval_every=5000, checkpoint_every=5000,
        )
    if name == "fast":
        return TrainConfig()
    if name == "tiny":
        return TrainConfig(
            model=FieldConfig(grid_levels=6, grid_max_res=64, grid_log2_table=15,
                              grid_coarse_to_fine_steps=50, grid_start_levels=3,
                              colour_hidden=32, colour_layers=2, semantic_hidden=32,
                              feature_dim=16, grid_hidden=32),
            iterations=150, rays_per_batch=128, samples_uniform=16, samples_importance=16,
            warmup=10, eval_every=50, checkpoint_every=50, eval_max_frames=2,
            ema_decay=0.0,  # 150 steps: an average over ~200 would still lean on the start
        )
    raise ValueError(f"unknown preset {name!r}; choose one of {', '.join(PRESETS)}")


def config_to_dict(config: TrainConfig) -> dict[str, Any]:
    """Plain JSON-able dict of ``config`` (nested ``model``)."""
    return asdict(config)


def config_from_dict(d: dict[str, Any]) -> TrainConfig:
    """Inverse of :func:`config_to_dict`; unknown keys raise ``ValueError``."""
    d = dict(d)
    model = d.pop("model", {})
    _check_keys(FieldConfig, model)
    _check_keys(TrainConfig, d)
    return replace(TrainConfig(**d), model=FieldConfig(**model))


def _check_keys(cls: type, d: dict[str, Any]) -> None:
    known = {f.name for f in fields(cls)}
    unknown = set(d) - known
    if unknown:
        raise ValueError(f"unknown {cls.__name__} keys {sorted(unknown)}; known: {sorted(known)}")
