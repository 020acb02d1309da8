"""Reading and writing the per-frame image files of a scene (docs/DESIGN.md formats).

| file | PNG format | in memory |
|---|---|---|
| RGB | 8-bit, 3 channels | (H, W, 3) uint8, RGB order |
| depth | 16-bit, 1 channel, value x scale = z-depth (m), 0 = none | (H, W) float32 m |
| semantics | 8-bit, 1 channel, class id | (H, W) uint8 |
| instances | 16-bit, 1 channel, facade id, 0 = none | (H, W) int32 |
| normals | 16-bit, 3 channels, (n + 1) / 2 x 65535, world frame, 0 = none | (H, W, 3) float32 |

Every reader raises ``ValueError`` naming the file when it is missing or unreadable.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from envelope.atomic import write_bytes_atomic

DEPTH_MAX_UNITS = 65535


def read_rgb(path: str | Path) -> np.ndarray:
    """(H, W, 3) uint8 RGB image."""
    img = _imread(path, cv2.IMREAD_COLOR)
    return np.ascontiguousarray(img[..., ::-1])


def write_rgb(path: str | Path, rgb: np.ndarray) -> None:
    """Write an (H, W, 3) uint8 RGB image as PNG."""
    rgb = np.asarray(rgb)
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.dtype != np.uint8:
        raise ValueError(f"RGB image must be (H, W, 3) uint8, got {rgb.shape} {rgb.dtype}")
    _imwrite(path, np.ascontiguousarray(rgb[..., ::-1]))


def read_depth_m(path: str | Path, depth_unit_scale_factor: float) -> np.ndarray:
    """(H, W) float32 z-depth in metres; 0 where no surface was hit."""
    raw = _imread(path, cv2.IMREAD_UNCHANGED)
    if raw.dtype != np.uint16 or raw.ndim != 2:
        raise ValueError(f"{path}: depth must be a single-channel 16-bit PNG, got {raw.dtype}")
    return raw.astype(np.float32) * np.float32(depth_unit_scale_factor)


def write_depth_m(path: str | Path, depth_z_m: np.ndarray, depth_unit_scale_factor: float) -> None:
    """Write (H, W) z-depth in metres (0 or non-finite = none) as a 16-bit PNG.

    Raises ``ValueError`` if a depth exceeds what 16 bits hold at this scale.
    """
    d = np.asarray(depth_z_m, dtype=np.float64)
    valid = np.isfinite(d) & (d > 0)
    units = np.zeros(d.shape, dtype=np.float64)
    units[valid] = np.round(d[valid] / depth_unit_scale_factor)
    if units.max(initial=0) > DEPTH_MAX_UNITS:
        raise ValueError(
            f"depth {d[valid].max():.2f} m exceeds the 16-bit range at "
            f"{depth_unit_scale_factor} m per unit; raise depth_unit_scale_factor"
        )
    units[valid] = np.maximum(units[valid], 1)  # a hit never reads as "no surface"
    _imwrite(path, units.astype(np.uint16))


def read_labels(path: str | Path) -> np.ndarray:
    """(H, W) uint8 semantic class ids."""
    raw = _imread(path, cv2.IMREAD_UNCHANGED)
    if raw.ndim != 2:
        raise ValueError(f"{path}: semantic image must be single-channel, got shape {raw.shape}")
    return raw.astype(np.uint8)


def write_labels(path: str | Path, labels: np.ndarray) -> None:
    """Write (H, W) class ids (< 256) as an 8-bit PNG."""
    labels = np.asarray(labels)
    if labels.ndim != 2 or labels.min(initial=0) < 0 or labels.max(initial=0) > 255:
        raise ValueError("semantic image must be (H, W) with ids in 0..255")
    _imwrite(path, labels.astype(np.uint8))


def read_facade_ids(path: str | Path) -> np.ndarray:
    """(H, W) int32 facade ids, 0 = no facade. Ground truth: methods must not read these."""
    raw = _imread(path, cv2.IMREAD_UNCHANGED)
    if raw.ndim != 2:
        raise ValueError(f"{path}: instance image must be single-channel, got shape {raw.shape}")
    return raw.astype(np.int32)


def write_facade_ids(path: str | Path, facade_ids: np.ndarray) -> None:
    """Write (H, W) facade ids (0 = none, < 65536) as a 16-bit PNG."""
    ids = np.asarray(facade_ids)
    if ids.ndim != 2 or ids.min(initial=0) < 0 or ids.max(initial=0) > 65535:
        raise ValueError("facade-id image must be (H, W) with ids in 0..65535")
    _imwrite(path, ids.astype(np.uint16))


def read_normals(path: str | Path) -> np.ndarray:
    """(H, W, 3) float32 world-frame unit normals; zero vectors where there is no surface."""
    raw = _imread(path, cv2.IMREAD_UNCHANGED)
    if raw.ndim != 3 or raw.dtype != np.uint16:
        raise ValueError(f"{path}: normals must be a 3-channel 16-bit PNG")
    rgb = raw[..., ::-1].astype(np.float32)
    n = rgb / 65535.0 * 2.0 - 1.0
    n[(raw == 0).all(axis=-1)] = 0.0
    return n


def write_normals(path: str | Path, normals: np.ndarray) -> None:
    """Write (H, W, 3) world-frame unit normals (zero vector = none) as a 16-bit PNG."""
    n = np.asarray(normals, dtype=np.float64)
    if n.ndim != 3 or n.shape[2] != 3:
        raise ValueError(f"normals must be (H, W, 3), got {n.shape}")
    enc = np.round((np.clip(n, -1, 1) + 1.0) / 2.0 * 65535.0).astype(np.uint16)
    enc[(n == 0).all(axis=-1)] = 0
    _imwrite(path, np.ascontiguousarray(enc[..., ::-1]))


def _imread(path: str | Path, flags: int) -> np.ndarray:
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"image {path} does not exist")
    img = cv2.imread(str(path), flags)
    if img is None:
        raise ValueError(f"image {path} cannot be read (corrupt or not an image)")
    return img


def _imwrite(path: str | Path, img: np.ndarray) -> None:
    ok, buf = cv2.imencode(".png", img)
    if not ok:
        raise ValueError(f"cannot encode {path} as PNG")
    write_bytes_atomic(path, buf.tobytes())
