"""A rendered scene on the cameras structure from motion recovered from its images: the
check of what the pose errors of the photos source cost the methods (issue 47).

The images, exact masks and depth stay those rendered from the true cameras; only the
cameras a method is told change. :func:`scenes_true_and_recovered` writes two scenes of the
same views, the photos source posed: one with the true cameras, one with the recovered ones.
A method's figures on the two differ by what the pose errors cost it and nothing else.

The recovered cameras keep what the photos source made of them, scale and up included; one
turn about the vertical and a shift (:func:`rigid_about_up`, fitted on the camera centres)
put them where the truth's footprint and facades are, since the photos source cannot know
where north or the origin is (``--known-distance`` gives neither). For checking only: the
photos source never sees the true cameras.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from dataset.scenes.links import link_tree
from envelope.atomic import atomic_directory
from envelope.camera import Intrinsics
from envelope.scene_record import Frame, Scene
from envelope.scenes.scene import read_scene, write_transforms

RECORD_KEY = "recovered_poses"


def rigid_about_up(source_m: np.ndarray, target_m: np.ndarray) -> np.ndarray:
    """(4, 4) the turn about z and shift taking (N, 3) ``source_m`` points closest to
    ``target_m`` in least squares (no scale, no tilt; N >= 2, not all on one vertical).

    Raises
    ------
    ValueError
        Shapes differ, N < 2, or the points' horizontal spread is zero (no heading).
    """
    source_m, target_m = np.asarray(source_m, float), np.asarray(target_m, float)
    if source_m.shape != target_m.shape or source_m.ndim != 2 or source_m.shape[1] != 3 \
            or len(source_m) < 2:
        raise ValueError(f"need two (N, 3) point sets of one shape with N >= 2, got "
                         f"{source_m.shape} and {target_m.shape}")
    mu_s, mu_t = source_m.mean(axis=0), target_m.mean(axis=0)
    s, t = source_m[:, :2] - mu_s[:2], target_m[:, :2] - mu_t[:2]
    cross = float(np.sum(s[:, 0] * t[:, 1] - s[:, 1] * t[:, 0]))
    dot = float(np.sum(s * t))
    if np.hypot(cross, dot) == 0.0:
        raise ValueError("the points have no horizontal spread: the heading is undefined")
    angle = np.arctan2(cross, dot)
    c, si = np.cos(angle), np.sin(angle)
    transform = np.eye(4)
    transform[:3, :3] = [[c, -si, 0.0], [si, c, 0.0], [0.0, 0.0, 1.0]]
    transform[:3, 3] = mu_t - transform[:3, :3] @ mu_s
    return transform


def recovered_intrinsics(true: Intrinsics, recovered: Intrinsics) -> Intrinsics:
    """The recovered pinhole camera on the true image: its focal lengths, and its principal
    point at the same offset from the image centre (the photos source's images are
    undistorted and cropped about the principal point; the true images are not)."""
    return Intrinsics(recovered.fx, recovered.fy,
                      true.width / 2 + recovered.cx - recovered.width / 2,
                      true.height / 2 + recovered.cy - recovered.height / 2,
                      true.width, true.height)


def scenes_true_and_recovered(true_dir: str | Path, posed_dir: str | Path,
                              out_true: str | Path, out_recovered: str | Path
                              ) -> tuple[Path, Path]:
    """Write the rendered scene at ``true_dir`` twice, keeping only the views the photos
    scene at ``posed_dir`` posed (matched by file stem): at ``out_true`` with their true
    cameras, at ``out_recovered`` with the recovered ones (:func:`rigid_about_up`,
    :func:`recovered_intrinsics`). Images, masks, depth and truth are hard links to the
    rendered scene's. Returns the two folders.

    Raises
    ------
    ValueError
        A posed photo has no rendered view of its stem, or fewer than 2 views were posed.
    """
    true, posed = read_scene(true_dir), read_scene(posed_dir)
    by_stem = {Path(f.file_path).stem: f for f in true.frames}
    missing = [f.file_path for f in posed.frames if Path(f.file_path).stem not in by_stem]
    if missing:
        raise ValueError(f"{posed_dir}: photos with no rendered view in {true_dir}: "
                         f"{', '.join(missing[:3])}")
    if len(posed.frames) < 2:
        raise ValueError(f"{posed_dir}: {len(posed.frames)} posed photos; the alignment needs 2")
    pairs = [(by_stem[Path(f.file_path).stem], f) for f in posed.frames]
    align = rigid_about_up(np.stack([p.world_from_camera[:3, 3] for _, p in pairs]),
                           np.stack([t.world_from_camera[:3, 3] for t, _ in pairs]))
    kept = tuple(t for t, _ in pairs)
    moved = tuple(replace(t, world_from_camera=align @ p.world_from_camera,
                          intrinsics=recovered_intrinsics(t.intrinsics, p.intrinsics))
                  for t, p in pairs)
    record = {"source": str(Path(true_dir).resolve()), "posed": str(Path(posed_dir).resolve()),
              "views": len(kept)}
    out_true = _write(true, Path(true_dir), kept, Path(out_true), {**record, "cameras": "true"})
    out_recovered = _write(true, Path(true_dir), moved, Path(out_recovered),
                           {**record, "cameras": "recovered",
                            "alignment": "turn about z and shift on the camera centres"})
    return out_true, out_recovered


def _write(scene: Scene, source_dir: Path, frames: tuple[Frame, ...], out: Path,
           record: dict) -> Path:
    with atomic_directory(out) as tmp:
        link_tree(source_dir, tmp)
        write_transforms(tmp, replace(scene, root=tmp, frames=frames,
                                      extra={**scene.extra, RECORD_KEY: record}))
    return out
