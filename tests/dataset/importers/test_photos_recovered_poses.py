"""A rendered scene on recovered cameras (dataset.importers.photos.recovered_poses): the
alignment about the vertical in closed form, and the two scenes of the same views."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from dataset.importers.photos.recovered_poses import (
    recovered_intrinsics,
    rigid_about_up,
    scenes_true_and_recovered,
)
from envelope.camera import Intrinsics
from envelope.scenes.scene import read_scene, write_transforms


def _turn_about_z(angle_rad: float, shift_m) -> np.ndarray:
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    transform = np.eye(4)
    transform[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    transform[:3, 3] = shift_m
    return transform


def _write_posed(true, frames, posed_dir: Path) -> None:
    """A photos scene of ``frames`` at ``posed_dir``, each image the rendered RGB as JPEG."""
    (posed_dir / "images").mkdir(parents=True)
    by_stem = {Path(f.file_path).stem: f for f in true.frames}
    for frame in frames:
        rendered = by_stem.get(Path(frame.file_path).stem, true.frames[0])
        with Image.open(true.path(rendered.file_path)) as image:
            image.convert("RGB").save(posed_dir / frame.file_path, format="JPEG")
    write_transforms(posed_dir, replace(true, root=posed_dir, frames=frames, building=None,
                                        extra={}))


def test_a_turn_about_up_and_a_shift_come_back_exactly():
    rng = np.random.default_rng(3)
    points = rng.normal(size=(7, 3)) * [20.0, 15.0, 4.0]
    moved = _turn_about_z(2.1, [5.0, -3.0, 1.5])
    target = points @ moved[:3, :3].T + moved[:3, 3]
    np.testing.assert_allclose(rigid_about_up(points, target), moved, atol=1e-9)


def test_the_fit_keeps_scale_and_tilt_and_centres_the_points():
    # A source 1 % too large: the fit turns and shifts it, never rescales it; the centroids
    # meet, and the turn is the true one because the spread is symmetric.
    points = np.array([[10.0, 0, 0], [0, 10, 0], [-10, 0, 0], [0, -10, 0]])
    moved = _turn_about_z(0.5, [1.0, 2.0, 3.0])
    target = points @ moved[:3, :3].T + moved[:3, 3]
    fit = rigid_about_up(points * 1.01, target)
    np.testing.assert_allclose(fit[:3, :3], moved[:3, :3], atol=1e-12)
    np.testing.assert_allclose(fit[:3, 3], [1.0, 2.0, 3.0], atol=1e-12)


def test_points_on_one_vertical_or_too_few_are_refused():
    with pytest.raises(ValueError, match="no horizontal spread"):
        rigid_about_up(np.array([[0.0, 0, 0], [0, 0, 5]]), np.array([[1.0, 1, 0], [1, 1, 5]]))
    with pytest.raises(ValueError, match="N >= 2"):
        rigid_about_up(np.zeros((1, 3)), np.zeros((1, 3)))


def test_the_recovered_camera_keeps_its_principal_point_offset_on_the_true_image():
    true = Intrinsics(500.0, 500.0, 512.0, 384.0, 1024, 768)
    cropped = Intrinsics(503.0, 503.0, 498.0, 371.0, 1000, 740)
    k = recovered_intrinsics(true, cropped)
    assert (k.fx, k.fy, k.width, k.height) == (503.0, 503.0, 1024, 768)
    assert (k.cx, k.cy) == (510.0, 371.0 - 370.0 + 384.0)


def test_two_scenes_of_the_posed_views_differ_only_in_their_cameras(clean_scene, tmp_path):
    true = read_scene(clean_scene)
    orbit = [f for f in true.frames if f.split in ("train", "eval")]
    # A photos scene of all orbit views but the first, in a frame of its own (turned and
    # shifted), with a focal length 1 % long, named as the photos source names them.
    gauge = _turn_about_z(-1.2, [40.0, 7.0, -2.0])
    posed_frames = tuple(
        replace(f, file_path=f"images/{Path(f.file_path).stem}.jpg",
                world_from_camera=gauge @ f.world_from_camera,
                intrinsics=replace(f.intrinsics, fx=f.intrinsics.fx * 1.01,
                                   fy=f.intrinsics.fy * 1.01),
                depth_file_path=None, semantic_file_path=None, normal_file_path=None,
                instance_file_path=None)
        for f in orbit[1:])
    posed_dir = tmp_path / "posed"
    _write_posed(true, posed_frames, posed_dir)
    out_true, out_recovered = scenes_true_and_recovered(
        clean_scene, posed_dir, tmp_path / "b", tmp_path / "b-sfm")
    a, b = read_scene(out_true), read_scene(out_recovered)
    assert [f.file_path for f in a.frames] == [f.file_path for f in orbit[1:]]
    assert [f.file_path for f in b.frames] == [f.file_path for f in orbit[1:]]
    for fa, fb in zip(a.frames, b.frames):
        np.testing.assert_allclose(fb.world_from_camera, fa.world_from_camera, atol=1e-9)
        assert fb.intrinsics.fx == pytest.approx(1.01 * fa.intrinsics.fx)
        assert (fb.intrinsics.cx, fb.intrinsics.cy) == (fa.intrinsics.cx, fa.intrinsics.cy)
        assert (fb.semantic_file_path, fb.depth_file_path) == (fa.semantic_file_path,
                                                               fa.depth_file_path)
        # The images are the rendered ones, linked, not copied.
        assert (out_recovered / fb.semantic_file_path).samefile(
            Path(clean_scene) / fa.semantic_file_path) or \
            (out_recovered / fb.semantic_file_path).read_bytes() == \
            (Path(clean_scene) / fa.semantic_file_path).read_bytes()
    assert a.building == true.building == b.building
    assert b.extra["recovered_poses"]["cameras"] == "recovered"


def test_a_photo_with_no_rendered_view_is_refused(clean_scene, tmp_path):
    true = read_scene(clean_scene)
    frames = tuple(replace(f, file_path=f"images/other_{i}.jpg", depth_file_path=None,
                           semantic_file_path=None, normal_file_path=None,
                           instance_file_path=None)
                   for i, f in enumerate(true.frames[:3]))
    posed_dir = tmp_path / "posed"
    _write_posed(true, frames, posed_dir)
    with pytest.raises(ValueError, match="no rendered view"):
        scenes_true_and_recovered(clean_scene, posed_dir, tmp_path / "a", tmp_path / "b")
    assert not (tmp_path / "a").exists()
