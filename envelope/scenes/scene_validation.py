"""Check a scene once, when it is read, so that bad input never becomes a wrong number.

:func:`validate_scene` (called by :func:`envelope.scenes.scene.read_scene`) checks what
a header read can tell: every frame's paths stay inside the scene folder (no
``..``, no absolute path, no symlink out), poses and intrinsics are finite and
proper, the depth scale is a positive number, and every image exists, is an
image and has the declared size. What needs a full decode is checked where the
pixels are loaded anyway, once: :func:`read_frame_labels` (only the scene's
declared class ids) and :func:`read_frame_depth_m` (positive depth wherever the
labels say building). All of them raise :class:`InvalidSceneError`, which
methods let through instead of skipping a view: a bad file means a bad scene.
"""

from __future__ import annotations

from pathlib import Path, PurePosixPath, PureWindowsPath

import numpy as np

from envelope.method_input import MethodInput
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import read_depth_m, read_labels
from envelope.scenes.labels import mapping_for_classes, read_remapped_labels

ROTATION_TOLERANCE = 1e-3
"""Largest |R^T R - I| entry of a pose's rotation: float32 round trips reach ~1e-6, a
scaled or sheared matrix is off by far more."""
MAX_IMAGE_PIXELS = 100_000_000
"""Declared images above 100 megapixels are refused (a decoded label image alone is 100 MB)."""
MAX_PROBLEMS_SHOWN = 3
FRAME_FILES = ("file_path", "depth_file_path", "semantic_file_path", "normal_file_path",
               "instance_file_path")
_SINGLE_CHANNEL_16 = ("I;16", "I;16B", "I;16L", "I")


class InvalidSceneError(ValueError):
    """The scene's files contradict ``transforms.json`` or hold impossible values."""


def validate_scene(scene: Scene | MethodInput) -> None:
    """Check every frame of ``scene`` (see the module docstring); header reads only.

    Raises
    ------
    InvalidSceneError
        Naming the first problems and how many there are.
    """
    problems: list[str] = []
    unit = scene.depth_unit_scale_factor
    if not (np.isfinite(unit) and unit > 0):
        problems.append(f"depth_unit_scale_factor must be a positive number of metres per "
                        f"unit, got {unit}")
    if not scene.semantic_classes or len(scene.semantic_classes) > 256:
        problems.append(f"semantic_classes must list 1 to 256 classes, got "
                        f"{len(scene.semantic_classes)}")
    root = scene.root.resolve()
    for frame in scene.frames:
        problems.extend(_frame_problems(scene.root, root, frame))
    if problems:
        shown = "; ".join(problems[:MAX_PROBLEMS_SHOWN])
        more = (f" (and {len(problems) - MAX_PROBLEMS_SHOWN} more problems)"
                if len(problems) > MAX_PROBLEMS_SHOWN else "")
        raise InvalidSceneError(f"scene {scene.root} is invalid: {shown}{more}")


def pose_problem(world_from_camera: np.ndarray) -> str | None:
    """Why a (4, 4) camera-to-world pose is not a proper rigid transform, or ``None``."""
    pose = np.asarray(world_from_camera, dtype=np.float64)
    if pose.shape != (4, 4):
        return f"the pose is not 4x4 (shape {pose.shape})"
    if not np.isfinite(pose).all():
        return "the pose holds NaN or inf"
    if not np.allclose(pose[3], (0.0, 0.0, 0.0, 1.0), atol=ROTATION_TOLERANCE):
        return f"the pose's last row is {pose[3].tolist()}, not [0, 0, 0, 1]"
    rot = pose[:3, :3]
    error = float(np.abs(rot.T @ rot - np.eye(3)).max())
    if error > ROTATION_TOLERANCE:
        return (f"the pose's rotation is not orthonormal (|R^T R - I| = {error:.2g} > "
                f"{ROTATION_TOLERANCE})")
    if np.linalg.det(rot) < 0:
        return "the pose's rotation is a reflection (determinant -1)"
    return None


def resolve_inside(root: Path, relative: str) -> Path:
    """``root / relative`` if it stays inside ``root`` (symlinks followed), else ValueError."""
    if not isinstance(relative, str) or not relative:
        raise ValueError(f"path {relative!r} is not a relative file path")
    if (PurePosixPath(relative).is_absolute() or PureWindowsPath(relative).is_absolute()
            or PureWindowsPath(relative).drive):
        raise ValueError(f"path {relative!r} is absolute; paths must be relative to the scene "
                         "folder")
    if ".." in PurePosixPath(relative.replace("\\", "/")).parts:
        raise ValueError(f"path {relative!r} leaves the scene folder ('..')")
    root = root.resolve()
    target = (root / relative).resolve()
    if not target.is_relative_to(root):
        raise ValueError(f"path {relative!r} resolves to {target}, outside the scene folder "
                         "(a symlink out)")
    return target


def read_frame_labels(scene: Scene | MethodInput, frame: Frame) -> np.ndarray:
    """(H, W) uint8 project class ids of ``frame``'s semantic image, checked against the scene.

    The one way methods read labels: a scene that declares the project's classes
    holds our ids (checked); one that declares a known source's classes
    (:mod:`envelope.scenes.labels`) is remapped to ours; any other class list is refused.

    Raises
    ------
    InvalidSceneError
        If the image is missing, undecodable, of another size than the intrinsics, or
        holds an id that is not one of the scene's ``semantic_classes`` (the message
        names the file, the id and its pixel count).
    ValueError
        If the frame has no semantic image.
    """
    if frame.semantic_file_path is None:
        raise ValueError(f"frame {frame.file_path} has no semantic_file_path (semantic mask) "
                         "in transforms.json")
    path = scene.path(frame.semantic_file_path)
    try:
        mapping = mapping_for_classes(scene.semantic_classes)
        # A scene read from a source (meta_data.json) holds that source's ids or colours.
        labels = read_labels(path) if mapping is None else read_remapped_labels(path, mapping)
    except ValueError as exc:
        raise InvalidSceneError(str(exc)) from exc
    _check_shape(labels, frame, frame.semantic_file_path)
    if mapping is not None:
        return labels  # remapped: unknown source ids or colours were refused on the way
    n = len(scene.semantic_classes)
    counts = np.bincount(labels.ravel(), minlength=256)
    unknown = np.flatnonzero(counts[n:]) + n
    if len(unknown):
        ids = ", ".join(f"id {i} on {counts[i]} pixels" for i in unknown[:5])
        raise InvalidSceneError(
            f"{path} holds class ids the scene does not declare ({ids}); semantic_classes "
            f"lists {n} classes (0..{n - 1}: {', '.join(scene.semantic_classes)}). Remap the "
            "image's ids or fix semantic_classes in transforms.json")
    return labels


MAX_DEPTH_HOLE_FRACTION = 0.5
"""Depth may have holes (0: a sensor's dropouts, glass); more than this share of the
building's pixels without depth means depth and labels do not belong together."""


def read_frame_depth_m(scene: Scene | MethodInput, frame: Frame, labels: np.ndarray | None = None
                       ) -> np.ndarray:
    """(H, W) float32 z-depth (m) of ``frame``, checked: finite, >= 0, and > 0 on at least
    half (:data:`MAX_DEPTH_HOLE_FRACTION`) of the pixels where ``labels`` (if given) show
    anything but the scene's background class; 0 is a hole (no depth).

    Raises
    ------
    InvalidSceneError
        If the image has another size than the intrinsics or its depth contradicts the labels.
    ValueError
        If the frame has no depth image, or it is missing or unreadable (callers decide
        whether depth matters).
    """
    if frame.depth_file_path is None:
        raise ValueError("the frame has no depth_file_path in transforms.json")
    path = scene.path(frame.depth_file_path)
    depth = read_depth_m(path, scene.depth_unit_scale_factor)
    _check_shape(depth, frame, frame.depth_file_path)
    bad = ~np.isfinite(depth) | (depth < 0)
    if bad.any():
        raise InvalidSceneError(
            f"{path}: {int(bad.sum())} pixels have negative or non-finite depth; write 0 where "
            "there is no depth")
    if labels is not None:
        names = [n.lower() for n in scene.semantic_classes]
        background = names.index("background") if "background" in names else 0
        building = labels != background
        holes = building & (depth <= 0)
        if holes.sum() > MAX_DEPTH_HOLE_FRACTION * max(int(building.sum()), 1):
            raise InvalidSceneError(
                f"{path}: {int(holes.sum())} of {int(building.sum())} building pixels have no "
                "valid depth (zero) where the semantic mask shows the building; depth and "
                "labels must come from the same view")
    return depth


def _check_shape(img: np.ndarray, frame: Frame, relative: str) -> None:
    k = frame.intrinsics
    if img.shape[:2] != (k.height, k.width):
        raise InvalidSceneError(f"{relative} is {img.shape[1]}x{img.shape[0]} but "
                                f"transforms.json says {k.width}x{k.height}")


def _frame_problems(root: Path, resolved_root: Path, frame: Frame) -> list[str]:
    name = f"frame {frame.file_path}"
    out = []
    why = pose_problem(frame.world_from_camera)
    if why:
        out.append(f"{name}: {why}")
    k = frame.intrinsics
    if not all(np.isfinite(v) for v in (k.fx, k.fy, k.cx, k.cy)):
        out.append(f"{name}: intrinsics hold NaN or inf (fx={k.fx}, fy={k.fy}, cx={k.cx}, "
                   f"cy={k.cy})")
    if k.width * k.height > MAX_IMAGE_PIXELS:
        out.append(f"{name}: declared image size {k.width}x{k.height} exceeds "
                   f"{MAX_IMAGE_PIXELS // 1_000_000} megapixels")
        return out
    for key in FRAME_FILES:
        relative = getattr(frame, key)
        if relative is None:
            continue
        try:
            path = resolve_inside(resolved_root, relative)
        except ValueError as exc:
            out.append(f"{name}: {key} {exc}")
            continue
        problem = _image_header_problem(path, k.width, k.height, key)
        if problem:
            out.append(f"{root / relative}: {problem}")
    return out


def _image_header_problem(path: Path, width: int, height: int, key: str) -> str | None:
    from PIL import Image, UnidentifiedImageError

    if not path.is_file():
        return "does not exist"
    try:
        with Image.open(path) as img:
            size, mode = img.size, img.mode
    except (UnidentifiedImageError, Image.DecompressionBombError, OSError, ValueError) as exc:
        return f"is not a readable image ({type(exc).__name__})"
    if size != (width, height):
        return f"is {size[0]}x{size[1]} but transforms.json says {width}x{height}"
    if key == "depth_file_path" and mode not in _SINGLE_CHANNEL_16:
        return f"depth must be a single-channel 16-bit PNG, got PIL mode {mode}"
    return None
