"""Surface textures and material colours in the RGB render (a source's
:class:`envelope.appearance.SurfaceAppearance`).

:func:`prepare_textures` turns each image into a mip pyramid of linear albedo once per
scene; :func:`texture_albedo` samples it at hit points: texture coordinates from the face's
affine map, the level whose texels match the pixel's footprint on the surface (no moiré),
bilinear within it, tiled. Only the RGB image uses it; labels, depth and normals never do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from envelope.appearance import SurfaceAppearance

SRGB_GAMMA = 2.2  # sRGB texel -> linear albedo, as the procedural palettes (shading.py)


@dataclass(frozen=True)
class TextureSet:
    """An appearance ready to sample: per image, mip levels of (h, w, 3) float32 linear
    albedo, finest first, each half the size of the one before (down to one texel)."""

    appearance: SurfaceAppearance
    pyramids: tuple[tuple[np.ndarray, ...], ...]


def prepare_textures(appearance: SurfaceAppearance | None) -> TextureSet | None:
    """The mip pyramids of ``appearance``'s images (``None`` passes through)."""
    if appearance is None:
        return None
    return TextureSet(appearance, tuple(_pyramid(im) for im in appearance.images))


def texture_albedo(textures: TextureSet, face: np.ndarray, points_m: np.ndarray,
                   footprint_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Linear albedo of the faces' materials at hit points.

    face : (N,) int face ids; points_m : (N, 3) hit points, world metres; footprint_m : (N,)
    a pixel's size on the surface there. Returns (N,) bool (the face has a material) and
    (N, 3) float64 albedo (zero where it has none).
    """
    a = textures.appearance
    material = a.face_material[face]
    has = material >= 0
    out = np.zeros((len(face), 3))
    if not has.any():
        return has, out
    homogeneous = np.column_stack([points_m, np.ones(len(points_m))])
    for k in np.unique(material[has]):
        sel = np.flatnonzero(material == k)
        m = a.uv_from_world[face[sel]]  # (n, 2, 4)
        uv = np.einsum("nij,nj->ni", m, homogeneous[sel])
        levels = textures.pyramids[k]
        h, w = levels[0].shape[:2]
        texels_per_m = np.maximum(np.linalg.norm(m[:, 0, :3], axis=1) * w,
                                  np.linalg.norm(m[:, 1, :3], axis=1) * h)
        lod = np.log2(np.maximum(footprint_m[sel] * texels_per_m, 1.0))
        level = np.clip(np.rint(lod).astype(int), 0, len(levels) - 1)
        for lv in np.unique(level):
            at = level == lv
            out[sel[at]] = _bilinear_tiled(levels[lv], uv[at])
    return has, out


def _pyramid(image: np.ndarray) -> tuple[np.ndarray, ...]:
    levels = [(image.astype(np.float32) / 255.0) ** SRGB_GAMMA]
    while max(levels[-1].shape[:2]) > 1:
        x = levels[-1]
        h, w = max(1, x.shape[0] // 2), max(1, x.shape[1] // 2)
        sy, sx = x.shape[0] // h, x.shape[1] // w
        levels.append(x[: h * sy, : w * sx].reshape(h, sy, w, sx, 3).mean(axis=(1, 3)))
    return tuple(levels)


def _bilinear_tiled(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(n, 3) bilinear samples of a tiled (h, w, 3) image at (n, 2) texture coordinates
    (u right, v up from the bottom row; pixel centres at half-integers)."""
    h, w = image.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = (1.0 - uv[:, 1]) * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    x0, y0 = x0.astype(np.int64) % w, y0.astype(np.int64) % h
    x1, y1 = (x0 + 1) % w, (y0 + 1) % h
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bottom = image[y1, x0] * (1 - fx) + image[y1, x1] * fx
    return top * (1 - fy) + bottom * fy
