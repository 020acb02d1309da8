"""The fixed-shape training step (``TrainConfig.sample_buffer``): the same loss and gradients
as today's step when no candidate is dropped, shapes and op sequence independent of the
batch and no host read before the optimiser, overflow dropped lightest first and counted,
and a short training with it on."""

import csv
from dataclasses import replace

import numpy as np
import pytest
import torch
from torch.utils._python_dispatch import TorchDispatchMode

from envelope.scenes.scene import read_method_input
from neural3d.config import preset_config
from neural3d.field.fields import SemanticSDF
from neural3d.rendering.fixed_shape import render_rays_fixed_shape, sample_slots
from neural3d.rendering.model import render_rays
from neural3d.rendering.occupancy import OccupancyGrid
from neural3d.train import train
from neural3d.training.data import Pixels
from neural3d.training.step import train_step

CLASSES = 4
STEP = 60  # past the tiny preset's coarse-to-fine ramp: every grid level on
LO, HI = torch.full((3,), -1.0), torch.full((3,), 1.0)
CONFIG = replace(preset_config("tiny"), rays_per_batch=96)
SAMPLES = CONFIG.rays_per_batch * (CONFIG.samples_uniform + CONFIG.samples_importance - 1)


def make_field() -> SemanticSDF:
    torch.manual_seed(0)
    return SemanticSDF(CONFIG.model, CLASSES, np.full(3, -1.0), np.full(3, 1.0))  # sphere 0.5


def make_pixels(n: int, spread: float, seed: int) -> Pixels:
    """``n`` pixels on rays from 3 units out towards the centre, offset by up to ``spread``
    (past about 1 a ray misses the box [-1, 1]^3), with random colours, labels and depths
    (a quarter without depth)."""
    gen = torch.Generator().manual_seed(seed)
    dirs = torch.randn(n, 3, generator=gen)
    dirs = dirs / dirs.norm(dim=1, keepdim=True)
    origins = -3.0 * dirs + spread * (torch.rand(n, 3, generator=gen) - 0.5)
    depth = 2.0 + torch.rand(n, generator=gen)
    depth[torch.rand(n, generator=gen) < 0.25] = float("nan")
    return Pixels(origins, dirs, torch.rand(n, 3, generator=gen),
                  torch.randint(CLASSES, (n,), generator=gen), depth, ((n, 1),))


def step_loss_and_gradients(config, pixels, occupancy=None):
    """The loss of one ``train_step`` and every parameter's gradient (SGD at lr 0: the
    optimiser leaves the gradients and the weights as they are)."""
    field = make_field()
    result = train_step(field, torch.optim.SGD(field.parameters(), lr=0.0), None, pixels,
                        LO, HI, config, step=STEP, background_class=0,
                        generator=torch.Generator().manual_seed(7), occupancy=occupancy)
    return result, {n: p.grad for n, p in field.named_parameters() if p.grad is not None}


def full_grid() -> OccupancyGrid:
    return OccupancyGrid(LO, HI, 16)  # every cell occupied: clipping keeps the box


@pytest.mark.parametrize("occupancy", [None, full_grid], ids=["no grid", "full grid"])
def test_with_a_slot_for_every_candidate_the_step_is_todays(occupancy):
    """Same rays and seed, a batch with rays that miss the box: loss equal within 1e-6
    (relative), every gradient within 1e-5 of its largest entry, depth term included."""
    config = replace(CONFIG, depth_loss=True)
    pixels = make_pixels(config.rays_per_batch * 4, spread=2.5, seed=1)
    grid = None if occupancy is None else occupancy()
    today, grads = step_loss_and_gradients(config, pixels, grid)
    grid = None if occupancy is None else occupancy()
    fixed, fixed_grads = step_loss_and_gradients(replace(config, sample_buffer=SAMPLES),
                                                 pixels, grid)
    hits = (today.render.accumulation > 0).sum()
    assert 0 < hits < config.rays_per_batch  # some rays miss: their masking is exercised
    assert torch.equal(today.pixel_index, fixed.pixel_index)
    assert fixed.dropped_samples == 0
    assert fixed.loss == pytest.approx(today.loss, rel=1e-6)
    for part, value in today.parts.items():
        assert fixed.parts[part] == pytest.approx(value, rel=1e-5, abs=1e-7), part
    assert set(fixed_grads) == set(grads)
    for name, g in grads.items():
        assert (fixed_grads[name] - g).abs().max() <= 1e-5 * g.abs().max() + 1e-9, name
    # Only the candidates count: as many slots valid as today's step evaluated samples.
    assert int(fixed.render.sdf_gradient_mask.sum()) == len(today.render.sdf_gradients)


class ShapeLog(TorchDispatchMode):
    """Every op run under it, with the shapes of its tensor inputs and outputs."""

    def __init__(self):
        super().__init__()
        self.ops: list[tuple[str, tuple]] = []

    def __torch_dispatch__(self, func, types, args=(), kwargs=None):
        out = func(*args, **(kwargs or {}))
        flat = [*args, *(kwargs or {}).values(), *(out if isinstance(out, (tuple, list))
                                                   else [out])]
        self.ops.append((str(func), tuple(tuple(x.shape) for x in flat
                                          if isinstance(x, torch.Tensor))))
        return out


def logged_step(config, pixels, grid) -> list[tuple[str, tuple]]:
    field = make_field()
    optimizer = torch.optim.Adam(field.parameters(), lr=1e-3, fused=True)
    with ShapeLog() as log:
        train_step(field, optimizer, None, pixels, LO, HI, config, step=STEP,
                   background_class=0, generator=torch.Generator().manual_seed(3),
                   occupancy=grid)
    return log.ops


def shell_grid() -> OccupancyGrid:
    """A grid refreshed from the initial sphere: only a shell of cells occupied."""
    grid = OccupancyGrid(LO, HI, 16)
    grid.update_from_sdf(make_field().sdf, margin=grid.cell)
    assert 0 < grid.fraction_occupied() < 1
    return grid


def test_every_shape_and_op_of_the_step_is_independent_of_the_data():
    """Two batches that differ in every data-dependent way (all rays hitting the box and the
    grid kept whole, against most rays missing and a shell of cells): the fixed-shape step
    runs the same ops on the same shapes, and reads nothing on the host (no ``.item()``,
    ``bool()``, ``float()``: ``_local_scalar_dense``) before the optimiser has stepped.
    Today's step, logged alike, differs between the two and reads the host before."""
    near = make_pixels(CONFIG.rays_per_batch * 4, spread=0.2, seed=2)  # every ray hits
    far = make_pixels(CONFIG.rays_per_batch * 4, spread=5.0, seed=3)  # most miss
    config = replace(CONFIG, sample_buffer=SAMPLES // 3)
    a, b = logged_step(config, near, full_grid()), logged_step(config, far, shell_grid())
    assert a == b
    names = [op for op, _ in a]
    assert "aten.nonzero.default" not in names
    sync = names.index("aten._local_scalar_dense.default")
    assert sync > max(i for i, op in enumerate(names) if "adam" in op)  # after the optimiser
    today_a, today_b = logged_step(CONFIG, near, full_grid()), logged_step(CONFIG, far,
                                                                           shell_grid())
    assert today_a != today_b  # the check sees a data-dependent shape
    today_names = [op for op, _ in today_a]
    assert today_names.index("aten._local_scalar_dense.default") < min(
        i for i, op in enumerate(today_names) if "adam" in op)


def test_slots_take_the_heaviest_candidates_and_count_the_rest():
    """Closed form: 5 candidates for 3 slots keep the 3 heaviest guesses (a tie goes to the
    earlier sample) and count 2 dropped; with slots to spare, every candidate is valid and
    the padding is the first non-candidates, masked out."""
    candidate = torch.tensor([True, False, True, True, False, True, True])
    guess = torch.tensor([0.2, 0.9, 0.5, 0.1, 0.8, 0.5, 0.05])
    s = sample_slots(candidate, guess, 3)
    assert s.rows.tolist() == [0, 2, 5] and s.valid.all() and int(s.dropped) == 2
    s = sample_slots(candidate, guess, 7)
    assert s.rows.tolist() == list(range(7)) and int(s.dropped) == 0
    assert s.valid.tolist() == candidate.tolist()
    s = sample_slots(candidate, guess, 6)
    assert s.rows.tolist() == [0, 1, 2, 3, 5, 6] and s.valid.tolist() == [True, False] + [True] * 4


def test_an_overflowing_buffer_drops_the_lightest_candidates_deterministically():
    """A buffer of a quarter of the candidates: every slot valid, the dropped count is the
    rest, the kept samples are the heaviest guesses, and a rerun chooses the same slots."""
    field = make_field()
    pixels = make_pixels(CONFIG.rays_per_batch, spread=0.5, seed=4)

    def render(buffer):
        return render_rays_fixed_shape(field, pixels.origins, pixels.dirs, LO, HI,
                                       replace(CONFIG, sample_buffer=buffer), step=STEP,
                                       background_class=0,
                                       generator=torch.Generator().manual_seed(5))

    full, dropped = render(SAMPLES)
    n_candidates = int(full.sdf_gradient_mask.sum())
    assert int(dropped) == 0 and n_candidates > 8
    small = n_candidates // 4
    out, dropped = render(small)
    again, dropped_again = render(small)
    assert out.sdf_gradients.shape == (small, 3) and out.sdf_gradient_mask.all()
    assert int(dropped) == n_candidates - small == int(dropped_again)
    assert torch.equal(out.sdf_gradients, again.sdf_gradients)
    assert torch.isfinite(out.rgb).all() and torch.isfinite(out.depth).all()
    today = render_rays(field, pixels.origins, pixels.dirs, LO, HI, CONFIG, step=STEP,
                        training=True, background_class=0,
                        generator=torch.Generator().manual_seed(5))
    assert out.accumulation.sum() < today.accumulation.sum()  # dropped samples are transparent


@pytest.mark.slow
def test_a_tiny_training_with_the_fixed_shape_step(box_building, tmp_path):
    """20 steps of the tiny preset with a buffer of 512 slots (of 128 x 31 samples) and the
    grid refreshed: the run finishes, its losses are finite and log.csv counts the dropped
    candidates (the first steps of a sphere have more than 512)."""
    from neural3d_scene import write_ring_scene

    scene = write_ring_scene(box_building, tmp_path / "box", size_px=24, n_train=8, n_eval=2)
    config = replace(preset_config("tiny"), iterations=20, sample_buffer=512,
                     occupancy_start=5, occupancy_every=5, eval_every=20, checkpoint_every=20)
    run = train(read_method_input(scene), config, tmp_path / "runs", device=torch.device("cpu"))
    with (run / "log.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["step"]) for r in rows] == [10, 20]
    assert all(np.isfinite(float(r["loss"])) for r in rows)
    assert int(rows[0]["dropped_samples"]) > 0
