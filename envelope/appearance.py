"""How the faces of a mesh look where the source says so: textures and material colours.

A source that knows its surfaces' materials (CityGML's ``app:ParameterizedTexture`` and
``app:X3DMaterial``) gives a :class:`SurfaceAppearance` beside the labelled mesh; the
renderer's RGB then shows them (:mod:`dataset.rendering.textures`). Labels, depth and
normals never depend on it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SurfaceAppearance:
    """Per-face material of a mesh.

    Attributes
    ----------
    face_material : (F,) int32
        Index into ``images`` per face; -1: none (the renderer's procedural look).
    uv_from_world : (F, 2, 4) float64
        Texture coordinates of a world point ``p`` (metres) on the face:
        ``uv = M @ [p, 1]``; u to the right, v up the image (0 at its bottom row), tiled
        (the texture repeats). Unused for faces without material or with a plain colour.
    images : tuple of (H, W, 3) uint8
        sRGB images; a plain colour is a (1, 1, 3) image.

    Raises
    ------
    ValueError
        Shapes that do not fit together, or a material index out of range.
    """

    face_material: np.ndarray
    uv_from_world: np.ndarray
    images: tuple[np.ndarray, ...]

    def __post_init__(self) -> None:
        material = np.ascontiguousarray(self.face_material, dtype=np.int32)
        uv = np.ascontiguousarray(self.uv_from_world, dtype=np.float64)
        if material.ndim != 1 or uv.shape != (len(material), 2, 4):
            raise ValueError(f"face_material (F,) and uv_from_world (F, 2, 4) must agree, got "
                             f"{material.shape} and {uv.shape}")
        if len(material) and (material.min() < -1 or material.max() >= len(self.images)):
            raise ValueError("face_material indexes an image that does not exist")
        for image in self.images:
            if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 3:
                raise ValueError(f"images must be (H, W, 3) uint8, got {image.dtype} "
                                 f"{image.shape}")
        object.__setattr__(self, "face_material", material)
        object.__setattr__(self, "uv_from_world", uv)
        object.__setattr__(self, "images", tuple(self.images))


def concatenate_appearances(parts: list[tuple[SurfaceAppearance | None, int]]
                            ) -> SurfaceAppearance | None:
    """One appearance for meshes concatenated in order: ``parts`` holds each mesh's
    appearance (``None``: none) and face count. ``None`` when no part has one."""
    if all(a is None for a, _ in parts):
        return None
    material, uv, images = [], [], []
    for appearance, faces in parts:
        if appearance is None:
            material.append(np.full(faces, -1, dtype=np.int32))
            uv.append(np.zeros((faces, 2, 4)))
            continue
        m = appearance.face_material
        material.append(np.where(m >= 0, m + len(images), -1).astype(np.int32))
        uv.append(appearance.uv_from_world)
        images.extend(appearance.images)
    return SurfaceAppearance(np.concatenate(material), np.concatenate(uv), tuple(images))
