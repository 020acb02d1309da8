"""dataset.importers.photos end to end: photos of a synthetic textured block (three boxes
with random multi-scale texture, ray cast here with numpy) from known cameras, posed by
structure from motion, compared with the true cameras after a similarity alignment.

The renders' plain look is too plain for structure from motion (issue 47); this scene has
the texture photos have, so the test checks the photos path itself (the photo look's own
end-to-end test is tests/dataset/importers/test_photos_from_renders.py). 20 photos of at most
480 x 360 px, 4 of them from another camera (other size and focal length)."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from dataset.generate import main as generate_main
from dataset.importers.photos.pose_error import pose_errors
from envelope.camera import Intrinsics, look_at, rays_world
from envelope.scenes.scene import read_method_input

TEXTURE_PX_PER_M = 20.0
BOXES_M = ((0.0, 0.0, 5.0, 4.0, 6.0), (9.0, 2.0, 2.0, 2.0, 3.0), (-7.0, -6.0, 1.5, 1.5, 9.0))
"""(centre x, centre y, half width x, half width y, height): a block of three buildings."""
MAIN = Intrinsics.from_fov(480, 360, 60.0)
OTHER = Intrinsics.from_fov(400, 300, 50.0)
"""Every fifth photo is taken with this other camera."""
# Measured (2026-11-29, pycolmap 4.2.1): scale 1.5e-4 off, up 0.04 deg, rotation 0.21 deg,
# position 0.056 m (orbit of 22 m radius), focal length 0.26 %; the tolerances leave room
# for another machine's floating point.
SCALE_TOLERANCE = 2e-3
UP_TOLERANCE_DEG = 0.2
ROTATION_TOLERANCE_DEG = 0.7
POSITION_TOLERANCE_M = 0.2
FOCAL_TOLERANCE = 0.01


def _noise_texture(rng: np.random.Generator, size_px: int = 1024) -> np.ndarray:
    """(size_px, size_px) float32 in [0, 1]: random noise at 4 scales (the smallest 4 px)."""
    tex = np.zeros((size_px, size_px), np.float32)
    for cells in (4, 16, 64, 256):
        tex += cv2.resize(rng.random((cells, cells), dtype=np.float32), (size_px, size_px),
                          interpolation=cv2.INTER_CUBIC) / cells ** 0.3
    return (tex - tex.min()) / (tex.max() - tex.min())


def _rectangles() -> list[tuple]:
    """Each box face as (fixed axis, its value, (axis a, lo, hi), (axis b, lo, hi))."""
    faces = []
    for cx, cy, hx, hy, h in BOXES_M:
        faces += [(0, cx + s * hx, (1, cy - hy, cy + hy), (2, 0.0, h)) for s in (-1, 1)]
        faces += [(1, cy + s * hy, (0, cx - hx, cx + hx), (2, 0.0, h)) for s in (-1, 1)]
        faces.append((2, h, (0, cx - hx, cx + hx), (1, cy - hy, cy + hy)))
    return faces


def _render(faces, textures, intrinsics: Intrinsics, pose: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8: the nearest textured face along each pixel's ray; grey elsewhere."""
    origin, direction = rays_world(intrinsics, pose)
    nearest = np.full(direction.shape[:2], np.inf)
    grey = np.full(direction.shape[:2], 0.5, np.float32)
    for (axis, value, (a, a_lo, a_hi), (b, b_lo, b_hi)), tex in zip(faces, textures):
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (value - origin[..., axis]) / direction[..., axis]
        pa = origin[..., a] + t * direction[..., a]
        pb = origin[..., b] + t * direction[..., b]
        hit = ((t > 0) & (pa >= a_lo) & (pa <= a_hi) & (pb >= b_lo) & (pb <= b_hi)
               & (t < nearest))
        map_x = np.nan_to_num((pa - a_lo) * TEXTURE_PX_PER_M).astype(np.float32)
        map_y = np.nan_to_num((pb - b_lo) * TEXTURE_PX_PER_M).astype(np.float32)
        seen = cv2.remap(tex, map_x % tex.shape[1], map_y % tex.shape[0], cv2.INTER_LINEAR,
                         borderMode=cv2.BORDER_WRAP)
        grey = np.where(hit, seen, grey)
        nearest = np.where(hit, t, nearest)
    return np.repeat((np.clip(grey, 0, 1) * 255).astype(np.uint8)[..., None], 3, axis=2)


def write_block_photos(folder, n: int = 20) -> dict[str, tuple[np.ndarray, Intrinsics]]:
    """Photos ``v00.png`` ... of the block from an orbit of radius 22 m at 2 and 6 m height;
    return each photo's true pose and intrinsics."""
    rng = np.random.default_rng(0)
    faces = _rectangles()
    textures = [_noise_texture(rng) for _ in faces]
    folder.mkdir(parents=True)
    truth = {}
    for i, angle in enumerate(np.linspace(0, 2 * np.pi, n, endpoint=False)):
        eye = [22.0 * np.cos(angle), 22.0 * np.sin(angle), 2.0 + 4.0 * (i % 2)]
        pose = look_at(eye, [0.0, 0.0, 3.0])
        intrinsics = OTHER if i % 5 == 4 else MAIN
        name = f"v{i:02d}.png"
        cv2.imwrite(str(folder / name), _render(faces, textures, intrinsics, pose))
        truth[name] = (pose, intrinsics)
    return truth


@pytest.mark.slow
def test_photos_of_a_textured_block_are_posed_in_metres_with_z_up(tmp_path, capsys):
    truth = write_block_photos(tmp_path / "block")
    distance = np.linalg.norm(truth["v00.png"][0][:3, 3] - truth["v10.png"][0][:3, 3])
    code = generate_main(["--photos", str(tmp_path / "block"), "--out", str(tmp_path / "out"),
                          "--known-distance", "v00.png", "v10.png", str(distance), "--quiet"])
    assert code == 0, capsys.readouterr().err
    scene = read_method_input(tmp_path / "out" / "block")  # validated: images and poses
    record = json.loads((tmp_path / "out" / "block" / "transforms.json").read_text())["photos"]
    assert record["unposed"] == [] and "x axes" in record["up"]
    names = [f.file_path.removeprefix("images/") for f in scene.frames]
    assert names == sorted(truth)
    errors = pose_errors(np.stack([f.world_from_camera for f in scene.frames]),
                         np.stack([truth[n][0] for n in names]))
    # Metres: the known distance fixes the scale.
    assert errors.scale_error < SCALE_TOLERANCE
    # z up: the alignment turns about z only.
    assert errors.up_deg < UP_TOLERANCE_DEG
    assert errors.rotation_deg.max() < ROTATION_TOLERANCE_DEG
    assert errors.position_m.max() < POSITION_TOLERANCE_M
    # Both cameras' focal lengths, each from its own intrinsics.
    for frame, name in zip(scene.frames, names):
        assert frame.intrinsics.fx == pytest.approx(truth[name][1].fx, rel=FOCAL_TOLERANCE)
