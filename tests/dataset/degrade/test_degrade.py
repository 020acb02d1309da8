"""Input degradations: identity at severity 0, seeded, closed-form sizes, truth untouched."""

from __future__ import annotations

import filecmp
import json
from pathlib import Path

import numpy as np
import pytest
from conftest import make_box_building

from dataset.degrade.depth_noise import noisy_depth_m
from dataset.degrade.masks import (
    bleed_labels,
    dilate_windows,
    erode_windows,
    false_windows,
    mask_noise,
    miss_windows,
)
from dataset.degrade.poses import perturb_pose, pose_noise
from dataset.degrade.scene_copy import RECORD_KEY, degrade_scene
from dataset.degrade.spec import DEGRADATIONS, DegradeSpec, parse_specs, specs_key
from dataset.scenes.scene_writer import GenerateConfig, generate_scene
from envelope.camera import Intrinsics, unproject_depth_to_world
from envelope.classes import SemanticClass
from envelope.scenes.images import read_labels
from envelope.scenes.scene import read_method_input, read_scene

WALL, WINDOW = int(SemanticClass.WALL), int(SemanticClass.WINDOW)
SMALL = GenerateConfig(resolution=48, views=6)


@pytest.fixture(scope="module")
def box_scene(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return generate_scene(make_box_building(), tmp_path_factory.mktemp("box"), SMALL, seed=4,
                          progress=False)


def _rect_labels(w: int = 20, h: int = 12) -> np.ndarray:
    labels = np.full((60, 80), WALL, np.uint8)
    labels[20 : 20 + h, 30 : 30 + w] = WINDOW
    return labels


def _input_files(root: Path) -> list[Path]:
    return sorted(p.relative_to(root) for p in root.rglob("*.png"))


def test_parse_specs_orders_defaults_and_rejects_bad_input() -> None:
    specs = parse_specs("pose:0.5, occluders", seed=3)
    assert [s.name for s in specs] == ["occluders", "pose"]
    assert specs[0].severity == 1.0 and specs[1].seed == 3
    assert specs_key(specs) == "occluders-1_pose-0.5_seed3"
    for bad in ("blur:1", "pose:x", "pose:-1", "mask_miss:2", "mask_erode:1.5", "pose,pose", ""):
        with pytest.raises(ValueError):
            parse_specs(bad)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_erosion_and_dilation_change_a_rectangle_by_the_closed_form_area(k: int) -> None:
    w, h = 20, 12
    labels = _rect_labels(w, h)
    assert (erode_windows(labels, k) == WINDOW).sum() == (w - 2 * k) * (h - 2 * k)
    assert (dilate_windows(labels, k) == WINDOW).sum() == (w + 2 * k) * (h + 2 * k)
    # Lost window pixels become wall; nothing else changes.
    eroded = erode_windows(labels, k)
    changed = eroded != labels
    assert (labels[changed] == WINDOW).all() and (eroded[changed] == WALL).all()


def test_mask_noises_are_identity_at_zero_and_seeded() -> None:
    labels = _rect_labels()
    labels[5:10, 5:15] = WINDOW
    rng = np.random.default_rng
    for fn in (miss_windows, false_windows, mask_noise):
        assert np.array_equal(fn(labels, 0.0, rng(0)), labels)
        assert np.array_equal(fn(labels, 0.5, rng(1)), fn(labels, 0.5, rng(1)))
    assert np.array_equal(bleed_labels(labels, 0, rng(0)), labels)
    assert np.array_equal(miss_windows(labels, 1.0, rng(0)) == WINDOW, np.zeros_like(labels, bool))
    assert (false_windows(labels, 1.0, rng(0)) == WINDOW).sum() == 2 * (labels == WINDOW).sum()
    bled = bleed_labels(labels, 2, rng(0))
    assert (bled != labels).any() and set(np.unique(bled)) <= {WALL, WINDOW}


def test_depth_noise_size_holes_and_quantisation() -> None:
    depth = np.full((200, 200), 10.0, np.float32)
    depth[:, :20] = 0.0
    labels = np.full(depth.shape, WALL, np.uint8)
    labels[100:, 100:] = WINDOW
    rng = np.random.default_rng
    assert np.array_equal(noisy_depth_m(depth, labels, 0.0, rng(0)), depth)
    noisy = noisy_depth_m(depth, labels, 2.0, rng(0))
    wall = noisy[:100, 20:]
    assert wall.std() == pytest.approx(0.01 * 2 * 10.0, rel=0.05)  # 0.01 s z
    assert np.allclose(wall / 0.02, np.round(wall / 0.02), atol=1e-3)  # 0.01 s m steps
    assert (noisy[:, :20] == 0).all()
    assert (noisy[100:, 100:] == 0).mean() == pytest.approx(0.5, abs=0.03)  # 0.25 s on glass


def test_pose_noise_moves_back_projected_points_by_the_stated_amount() -> None:
    k = Intrinsics.from_fov(32, 32, 60.0)
    pose = np.eye(4)
    pose[:3, 3] = (1.0, 2.0, 3.0)
    uv = np.stack(np.meshgrid(np.arange(32) + 0.5, np.arange(32) + 0.5), -1).reshape(-1, 2)
    depth = np.full(len(uv), 10.0)
    before = unproject_depth_to_world(uv, depth, k, pose)
    # Translation only: every point moves by exactly the translation.
    moved = unproject_depth_to_world(uv, depth, k, perturb_pose(pose, 0.0, 0.05,
                                                                np.random.default_rng(0)))
    assert np.allclose(np.linalg.norm(moved - before, axis=1), 0.05)
    # Rotation only: a point at distance r moves by 2 r sin(theta / 2) sin(phi); over random
    # axes E[sin phi] = pi / 4, so the centre pixel's point moves by pi / 2 r sin(theta / 2).
    theta = np.radians(0.5)
    centre = np.array([[16.0, 16.0]])
    shifts = []
    for seed in range(2000):
        p = perturb_pose(pose, 0.5, 0.0, np.random.default_rng(seed))
        assert np.allclose(p[:3, 3], pose[:3, 3])
        shifts.append(np.linalg.norm(unproject_depth_to_world(centre, [10.0], k, p)
                                     - unproject_depth_to_world(centre, [10.0], k, pose)))
    assert max(shifts) <= 2 * 10.0 * np.sin(theta / 2) + 1e-9
    assert np.mean(shifts) == pytest.approx(np.pi / 2 * 10.0 * np.sin(theta / 2), rel=0.03)
    assert np.array_equal(pose_noise(pose, 0.0, np.random.default_rng(0)), pose)


@pytest.mark.slow
@pytest.mark.parametrize("name", DEGRADATIONS)
def test_severity_zero_leaves_every_input_bit_identical(box_scene: Path, tmp_path: Path,
                                                        name: str) -> None:
    out = degrade_scene(box_scene, tmp_path, (DegradeSpec(name, 0.0),))  # type: ignore[arg-type]
    files = _input_files(box_scene)
    assert files == _input_files(out)
    _, mismatch, errors = filecmp.cmpfiles(box_scene, out, [str(f) for f in files],
                                           shallow=False)
    assert not mismatch and not errors
    for a, b in zip(read_scene(box_scene).frames, read_scene(out).frames):
        assert np.array_equal(a.world_from_camera, b.world_from_camera)


@pytest.mark.slow
@pytest.mark.parametrize("text", ["occluders:2", "mask_noise:2", "depth_noise:2", "pose:0.5"])
def test_degradations_are_seeded_and_never_touch_the_truth(box_scene: Path, tmp_path: Path,
                                                           text: str) -> None:
    truth_before = {p: p.read_bytes() for p in (box_scene / "building.json",
                                                box_scene / "mesh.ply")}
    inputs_before = {f: (box_scene / f).read_bytes() for f in _input_files(box_scene)}
    a = degrade_scene(box_scene, tmp_path / "a", parse_specs(text, seed=1))
    b = degrade_scene(box_scene, tmp_path / "b", parse_specs(text, seed=1))
    c = degrade_scene(box_scene, tmp_path / "c", parse_specs(text, seed=2))
    files = [str(f) for f in _input_files(box_scene)]
    assert not filecmp.cmpfiles(a, b, files, shallow=False)[1]  # reproducible
    ta, tb = (json.loads((x / "transforms.json").read_text()) for x in (a, b))
    assert ta["frames"] == tb["frames"] and ta[RECORD_KEY]["specs"][0]["seed"] == 1
    changed = filecmp.cmpfiles(box_scene, a, files, shallow=False)[1]
    poses_changed = read_scene(a).frames[0].world_from_camera.tolist() != \
        read_scene(box_scene).frames[0].world_from_camera.tolist()
    assert changed or poses_changed  # the degradation did something
    assert filecmp.cmpfiles(a, c, files, shallow=False)[1] or text.startswith("pose")
    for path, data in truth_before.items():  # the truth is untouched, in both folders
        assert path.read_bytes() == data
        assert (a / path.name).read_bytes() == data
    assert all((box_scene / f).read_bytes() == d for f, d in inputs_before.items())
    assert not [f for f in changed if f.startswith("instances/")]


@pytest.mark.slow
def test_occluders_cover_facade_pixels_and_label_them_background(box_scene: Path,
                                                                 tmp_path: Path) -> None:
    out = degrade_scene(box_scene, tmp_path, parse_specs("occluders:3"))
    scene = read_scene(box_scene)
    covered = 0
    for fr in scene.frames_in("ideal"):
        before = read_labels(scene.path(fr.semantic_file_path))
        after = read_labels(out / fr.semantic_file_path)
        lost = (before != after)
        assert (after[lost] == SemanticClass.BACKGROUND).all()
        covered += int(lost.sum())
    assert covered > 0


def test_depth_holes_are_read_and_the_baselines_run_on_them(box_scene: Path,
                                                            tmp_path: Path) -> None:
    """Holes on glass (depth 0) are a sensor's, not a broken scene: every frame's depth
    reads, 2D-SS runs; depth missing on most of the building is still refused."""
    from baselines.wwr2dss import run_2dss
    from envelope.scenes.images import write_depth_m
    from envelope.scenes.scene_validation import (
        InvalidSceneError,
        read_frame_depth_m,
        read_frame_labels,
    )

    out = degrade_scene(box_scene, tmp_path / "holes", parse_specs("depth_noise:1"))
    scene = read_scene(out)
    holes = 0
    for frame in scene.frames_in("ideal"):
        labels = read_frame_labels(scene, frame)
        depth = read_frame_depth_m(scene, frame, labels)
        holes += int(((labels == WINDOW) & (depth == 0)).sum())
    assert holes > 0
    assert run_2dss(read_method_input(out), "ideal").wwr is not None
    frame = scene.frames_in("ideal")[0]
    write_depth_m(out / frame.depth_file_path, np.zeros((48, 48)), 0.001)
    with pytest.raises(InvalidSceneError, match="building pixels have no valid depth"):
        read_frame_depth_m(scene, frame, read_frame_labels(scene, frame))
