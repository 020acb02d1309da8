"""How CityGML polygons look: ``app:ParameterizedTexture`` and ``app:X3DMaterial`` (2.0 and
3.0), and their per-face form for the renderer.

Read (:func:`polygon_looks`): every ``Appearance`` of the file, whatever its theme. A
texture gives an image (``imageURI``, relative to the file) and, per ring of each target
polygon, its texture coordinates (2.0: ``target uri=`` with ``TexCoordList`` /
``textureCoordinates ring=``; 3.0: ``TextureAssociation`` with ``target`` and
``TexCoordList`` of ``textureCoordinates`` and ``ring``). A material gives its
``diffuseColor`` and ``transparency`` (``target`` text). A polygon with both keeps the
texture. Texture coordinates generated from a world-to-texture matrix (``TexCoordGen``) and
``GeoreferencedTexture`` are not read: those polygons keep the procedural look.

Per face (:func:`face_appearance`): each textured polygon's texture coordinates become an
affine map from world points to (u, v), fitted by least squares to its rings' corners (the
models' textures are planar projections: the fit misses by a hundredth of a tile at most),
so any point of any of its triangles gets its coordinates; a material becomes
a 1 x 1 image of its diffuse colour. A transparent material (glass) is left to the
procedural glass look; so is a face whose image file is missing (counted in the warnings).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from envelope.appearance import SurfaceAppearance

MAX_UV_FIT_RESIDUAL = 0.05
"""A texture's coordinates that an affine map from the polygon's corners misses by more than
this (texture units: a twentieth of a tile) are not a planar projection; the fit is used
all the same and the polygon is counted in the warnings. Ingolstadt's textured polygons
miss by at most 0.01 (corners a few millimetres off their plane), but for 4018154's 0.1."""


@dataclass(frozen=True)
class PolygonLook:
    """One polygon's look: ``image_uri`` (a texture, relative to the CityGML file) with
    ``ring_uv`` (ring ``gml:id`` -> (n, 2) texture coordinates, closing repeat dropped), or
    an X3D material's ``diffuse_rgb`` (three numbers in [0, 1]) and ``transparency``."""

    image_uri: str | None = None
    ring_uv: dict[str, np.ndarray] = field(default_factory=dict)
    diffuse_rgb: tuple[float, float, float] | None = None
    transparency: float = 0.0


def polygon_looks(root) -> dict[str, PolygonLook]:
    """Polygon ``gml:id`` -> look, from every ``Appearance`` under the lxml ``root``."""
    textures: dict[str, PolygonLook] = {}
    materials: dict[str, PolygonLook] = {}
    for tex in root.iter("{*}ParameterizedTexture"):
        uri = (tex.findtext("{*}imageURI") or "").strip()
        if not uri:
            continue
        for polygon_id, ring_uv in _texture_targets(tex):
            textures[polygon_id] = PolygonLook(image_uri=uri, ring_uv=ring_uv)
    for mat in root.iter("{*}X3DMaterial"):
        rgb = _numbers(mat.findtext("{*}diffuseColor"))
        if rgb is None or len(rgb) != 3:
            continue
        look = PolygonLook(diffuse_rgb=tuple(float(x) for x in np.clip(rgb, 0, 1)),
                           transparency=float((_numbers(mat.findtext("{*}transparency"))
                                               or [0.0])[0]))
        for target in mat.findall("{*}target"):
            materials[(target.text or "").strip().lstrip("#")] = look
    return {**materials, **textures}


def face_appearance(looks: Sequence[PolygonLook | None], rings: Sequence[tuple],
                    reversed_rings: Sequence[bool], face_counts: Sequence[int],
                    offset_m: np.ndarray, folder: Path, warnings: Counter,
                    ) -> SurfaceAppearance | None:
    """Per-face appearance of a mesh made of polygons, one after another.

    looks : each polygon's look (None: none); rings : each polygon's (ring ids, rings in the
    file's CRS) as read; reversed_rings : whether the reader reversed its rings;
    face_counts : how many mesh faces each polygon has, in mesh order (faces after them:
    none); offset_m : (3,) the shift from file to world coordinates; folder : where image
    URIs start. ``None`` when no polygon has a look.
    """
    images: list[np.ndarray] = []
    index: dict[object, int] = {}
    material, uv_maps = [], []
    for look, (ring_ids, ring_pts), rev, count in zip(looks, rings, reversed_rings,
                                                       face_counts):
        key, uv_map = _material(look, ring_ids, ring_pts, rev, offset_m, folder, warnings)
        if key is not None and key not in index:
            index[key] = len(images)
            images.append(_image(key))
        material.append(np.full(count, -1 if key is None else index[key], dtype=np.int32))
        uv_maps.append(np.broadcast_to(uv_map, (count, 2, 4)))
    if not images:
        return None
    return SurfaceAppearance(np.concatenate(material), np.concatenate(uv_maps),
                             tuple(images))


def _material(look, ring_ids, ring_pts, rev, offset_m, folder: Path, warnings: Counter):
    """(key, (2, 4) uv-from-world map) of one polygon; key None for the procedural look.
    A key is ``(path, None)`` for a texture, ``(None, rgb)`` for a plain colour."""
    none = np.zeros((2, 4))
    if look is None:
        return None, none
    if look.image_uri is not None:
        path = (folder / look.image_uri).resolve()
        if not path.is_file():
            warnings["texture image missing: procedural look"] += 1
            return None, none
        uv_map = _uv_map(look.ring_uv, ring_ids, ring_pts, rev, offset_m, warnings)
        return (None, none) if uv_map is None else ((str(path), None), uv_map)
    if look.transparency > 0:
        return None, none  # glass: the renderer's glass look
    rgb = tuple(int(round(255 * c)) for c in look.diffuse_rgb)
    return (None, rgb), none


def _uv_map(ring_uv: dict[str, np.ndarray], ring_ids, ring_pts, rev: bool, offset_m,
            warnings: Counter) -> np.ndarray | None:
    """(2, 4) affine map from world points (file points + offset) to texture coordinates."""
    pts, uvs = [], []
    for rid, p in zip(ring_ids, ring_pts):
        uv = ring_uv.get(rid)
        if uv is None:
            continue
        uv = uv[::-1] if rev else uv
        if len(uv) != len(p):
            warnings["texture coordinates that do not match their ring: ring left out"] += 1
            continue
        pts.append(np.asarray(p) + offset_m)
        uvs.append(uv)
    if not pts:
        warnings["textured polygon without coordinates for its rings: procedural look"] += 1
        return None
    pts, uvs = np.concatenate(pts), np.concatenate(uvs)
    centre = pts.mean(axis=0)
    a = np.column_stack([pts - centre, np.ones(len(pts))])
    coef, *_ = np.linalg.lstsq(a, uvs, rcond=None)  # (4, 2): min-norm along the normal
    if np.abs(a @ coef - uvs).max() > MAX_UV_FIT_RESIDUAL:
        warnings["texture not a planar projection (affine fit used)"] += 1
    linear = coef[:3].T  # (2, 3)
    return np.column_stack([linear, coef[3] - linear @ centre])


def _image(key) -> np.ndarray:
    """(H, W, 3) uint8 sRGB image of a material key."""
    path, rgb = key
    if path is None:
        return np.asarray(rgb, dtype=np.uint8).reshape(1, 1, 3)
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"), dtype=np.uint8)


def _texture_targets(tex):
    """(polygon id, ring id -> (n, 2) uv) of every target of one ParameterizedTexture."""
    for target in tex.iter("{*}target"):
        uri = target.get("uri")
        if uri is not None:  # 2.0: <target uri="#poly"><TexCoordList><textureCoordinates ring=
            rings = {}
            for tc in target.iter("{*}textureCoordinates"):
                uv = _uv(tc.text)
                if uv is not None and tc.get("ring"):
                    rings[tc.get("ring").lstrip("#")] = uv
            yield uri.lstrip("#"), rings
            continue
        assoc = target.getparent()  # 3.0: <TextureAssociation><target>#poly</target>...
        if assoc is None or not assoc.tag.endswith("TextureAssociation"):
            continue
        rings = {}
        for tcl in assoc.iter("{*}TexCoordList"):
            coords = [_uv(t.text) for t in tcl.findall("{*}textureCoordinates")]
            ids = [(r.text or "").strip().lstrip("#") for r in tcl.findall("{*}ring")]
            rings.update({i: uv for i, uv in zip(ids, coords) if uv is not None})
        yield (target.text or "").strip().lstrip("#"), rings


def _uv(text: str | None) -> np.ndarray | None:
    values = _numbers(text)
    if values is None or len(values) < 6 or len(values) % 2:
        return None
    uv = np.asarray(values, dtype=np.float64).reshape(-1, 2)
    return uv[:-1] if len(uv) > 1 and np.array_equal(uv[0], uv[-1]) else uv


def _numbers(text: str | None) -> list[float] | None:
    try:
        return [float(x) for x in (text or "").split()] or None
    except ValueError:
        return None
