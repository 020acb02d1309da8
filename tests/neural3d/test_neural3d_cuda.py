"""neural3d on a CUDA GPU: the same field renders, trains, loads and measures as on the CPU.

Skipped where torch sees no GPU (CI never has one); run on a lent GPU machine with
``python -m pytest tests/neural3d/test_neural3d_cuda.py`` (docs/neural3d.md, "On a GPU").
"""

import copy

import pytest
import torch
from conftest import BOX_SIZE_M
from neural3d_scene import write_ring_scene
from test_neural3d_train import SHORT, SURFACE_TOL_M, box_surface_points

from envelope.footprint import geojson_to_polygon
from envelope.scenes.scene import read_method_input, read_scene
from neural3d.config import preset_config
from neural3d.extract import ExtractConfig, extract_run
from neural3d.field.trained import build_field, load_trained_field
from neural3d.method import Neural3dBudget, run_neural3d
from neural3d.rendering.model import render_rays
from neural3d.rendering.occupancy import OccupancyGrid
from neural3d.train import main, train
from neural3d.training.data import (
    background_class,
    frames_to_pixels,
    load_frames,
    scene_normalisation,
)
from neural3d.training.losses import total_loss

pytestmark = pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA GPU")

CPU, CUDA = torch.device("cpu"), torch.device("cuda")
# float32 on two devices: reductions and atomics add in other orders. Measured on an H100:
# rendered rgb / accumulation differ by < 1e-5, depth by < 1e-4 (normalised units).
RENDER_ATOL = 1e-3
# Gradients of the same loss: each parameter tensor's gradient agrees in direction (cosine)
# and norm; the hash table's gradient is a sum over many rays, added by atomics on CUDA.
GRAD_COSINE, GRAD_NORM_RTOL = 0.999, 1e-2


@pytest.fixture(scope="module")
def scene(box_building, tmp_path_factory):
    return write_ring_scene(box_building, tmp_path_factory.mktemp("cuda") / "box", size_px=32,
                            n_train=16, n_eval=2)


@pytest.fixture(scope="module")
def fast_setup(scene):
    """The fast preset's field (all grid levels on) and a batch of 256 train rays, on CPU."""
    config = preset_config("fast")
    read = read_scene(scene)
    bg = background_class(read)
    frames = load_frames(read, "train")
    norm = scene_normalisation(frames, bg, margin=config.scene_box_margin)
    pixels = frames_to_pixels(frames, norm, CPU)
    torch.manual_seed(0)
    field = build_field(config.model, len(read.semantic_classes), norm)
    field.set_step(config.model.grid_coarse_to_fine_steps)
    idx = torch.randperm(len(pixels), generator=torch.Generator().manual_seed(0))[:256]
    lo = torch.tensor(norm.box_min_unit, dtype=torch.float32)
    hi = torch.tensor(norm.box_max_unit, dtype=torch.float32)
    return config, bg, field, pixels, idx, lo, hi


def _render_and_grad(config, bg, field, pixels, idx, lo, hi, device):
    field = copy.deepcopy(field).to(device)
    out = render_rays(field, pixels.origins[idx].to(device), pixels.dirs[idx].to(device),
                      lo.to(device), hi.to(device), config, step=config.iterations,
                      training=False, background_class=bg)
    loss, _ = total_loss(out, pixels.rgb[idx].to(device), pixels.labels[idx].to(device),
                         config, background_class=bg)
    loss.backward()
    grads = {n: p.grad.detach().cpu() for n, p in field.named_parameters() if p.grad is not None}
    return out, grads


def test_render_and_gradients_match_the_cpu(fast_setup):
    out_cpu, grads_cpu = _render_and_grad(*fast_setup, CPU)
    out_gpu, grads_gpu = _render_and_grad(*fast_setup, CUDA)
    for name in ("rgb", "semantics", "depth", "accumulation"):
        a, b = getattr(out_cpu, name), getattr(out_gpu, name).cpu()
        assert torch.allclose(a, b, atol=RENDER_ATOL), (name, float((a - b).abs().max()))
    assert grads_cpu.keys() == grads_gpu.keys() and grads_cpu
    for name, g in grads_cpu.items():
        h = grads_gpu[name]
        if float(g.norm()) < 1e-12:
            assert float(h.norm()) < 1e-9, name
            continue
        cosine = float((g * h).sum() / (g.norm() * h.norm()))
        assert cosine > GRAD_COSINE, (name, cosine)
        assert float(h.norm()) == pytest.approx(float(g.norm()), rel=GRAD_NORM_RTOL), name


def test_occupancy_grid_matches_the_cpu(fast_setup):
    config, _, field, pixels, idx, lo, hi = fast_setup
    grids = {}
    for device in (CPU, CUDA):
        f = copy.deepcopy(field).to(device)
        grid = OccupancyGrid(lo.to(device), hi.to(device), config.occupancy_resolution)
        grid.update_from_sdf(f.sdf, margin=config.occupancy_margin_cells * grid.cell)
        grids[device.type] = grid
    cpu, gpu = grids["cpu"].occupied, grids["cuda"].occupied.cpu()
    assert 0.0 < grids["cpu"].fraction_occupied() < 1.0
    assert float((cpu != gpu).float().mean()) < 1e-3  # cells exactly at the threshold may flip
    near, far = torch.zeros(len(idx)), torch.full((len(idx),), 10.0)
    hit = torch.ones(len(idx), dtype=torch.bool)
    o, d = pixels.origins[idx], pixels.dirs[idx]
    grids["cuda"].occupied = cpu.to(CUDA)  # the same cells: clipping itself must agree
    a = grids["cpu"].clip_rays(o, d, near, far, hit)
    b = grids["cuda"].clip_rays(o.to(CUDA), d.to(CUDA), near.to(CUDA), far.to(CUDA),
                                hit.to(CUDA))
    assert torch.equal(a[2], b[2].cpu())
    assert torch.allclose(a[0], b[0].cpu(), atol=1e-5)
    assert torch.allclose(a[1], b[1].cpu(), atol=1e-5)


@pytest.fixture(scope="module")
def cuda_run(scene, tmp_path_factory):
    return train(read_method_input(scene), SHORT, tmp_path_factory.mktemp("runs"), device=CUDA)


def test_training_on_cuda_fits_the_box_and_loads_on_the_cpu(cuda_run):
    on_gpu = load_trained_field(cuda_run, device=CUDA)
    on_cpu = load_trained_field(cuda_run, device=CPU)
    points = box_surface_points(1000)
    sdf_gpu, sdf_cpu = on_gpu.sdf_m(points.to(CUDA)).cpu(), on_cpu.sdf_m(points)
    assert torch.allclose(sdf_gpu, sdf_cpu, atol=1e-4), float((sdf_gpu - sdf_cpu).abs().max())
    assert sdf_cpu.abs().median() < SURFACE_TOL_M, sdf_cpu.abs().median()
    sx, sy, sz = BOX_SIZE_M
    assert on_cpu.sdf_m(torch.tensor([[0.0, 0.0, sz / 2]])) < 0
    assert (on_cpu.sdf_m(torch.tensor([[sx / 2 + 3, 0, sz / 2], [0, -sy / 2 - 3, sz / 2]]))
            > 0).all()


def test_extraction_on_cuda_matches_the_cpu(cuda_run, tmp_path):
    config = ExtractConfig(resolution=48)
    gpu = extract_run(cuda_run, config=config, device=CUDA, out_dir=tmp_path / "gpu")
    cpu = extract_run(cuda_run, config=config, device=CPU, out_dir=tmp_path / "cpu")
    # The same weights on both devices: the SDF agrees to ~1e-6 m, so marching cubes and the
    # measurement give the same mesh up to rounding at a few vertices.
    assert gpu.facade_area_m2 == pytest.approx(cpu.facade_area_m2, rel=1e-3)
    assert gpu.window_area_m2 == pytest.approx(cpu.window_area_m2, rel=1e-3, abs=1e-3)
    assert (gpu.footprint is None) == (cpu.footprint is None)
    if cpu.footprint is not None:
        assert geojson_to_polygon(gpu.footprint).area == pytest.approx(
            geojson_to_polygon(cpu.footprint).area, rel=1e-3)


def test_train_cli_on_cuda(scene, tmp_path):
    assert main(["--scene", str(scene), "--preset", "tiny", "--iterations", "20",
                 "--out", str(tmp_path), "--device", "cuda"]) == 0
    assert (tmp_path / scene.name / "checkpoint.pt").is_file()


def test_neural3d_method_on_cuda_reuses_its_training(scene, tmp_path):
    """A comparison's neural3d on CUDA: trained once, then only re-extracted."""
    budget = Neural3dBudget(preset="tiny", steps=30, resolution=32, device="cuda")
    read = read_method_input(scene)
    first = run_neural3d(read, "train", budget, artefacts_dir=tmp_path)
    again = run_neural3d(read, "train", budget, artefacts_dir=tmp_path)
    assert first.steps == again.steps == 30
    assert first.config["budget"]["device"] == "cuda"
    assert not first.warnings or not any("training reused" in w for w in first.warnings)
    assert any("training reused" in w for w in again.warnings)
    assert again.wwr == first.wwr  # the same stored field, measured on the same device

