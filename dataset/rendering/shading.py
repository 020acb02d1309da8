"""The RGB look of a rendered building: sun, sky, ground, materials and procedural textures.

Everything is a pure function of hit points and a per-building :class:`Look`,
drawn once from a seed, so all views of one building agree (a multi-view
method sees one consistent building). Radiance is linear RGB; the renderer
tone-maps it to sRGB.

Light: a sun (with hard shadows from shadow rays), sky ambient from above and
ground bounce from below. Background: an environment map (a function of the
ray direction only) with a sky, a sun disc, a hazy horizon and ground tones
below it; the ground is not geometry, so the building casts no shadow on it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, get_args

import numpy as np

from dataset.rendering import photo_backdrop, photo_look
from dataset.rendering.look import Look
from dataset.rendering.noise import detail, hash01, value_noise
from dataset.rendering.textures import TextureSet, texture_albedo
from envelope.classes import NO_FACADE, SemanticClass

if TYPE_CHECKING:
    from envelope.geometry.raycast import Raycaster

WallMaterial = Literal["random", "plaster", "brick"]
LookName = Literal["plain", "photo"]

# Shadow rays start this far off the surface (plus a share of the building size)
# so that float32 Embree does not hit the surface the ray leaves.
_SHADOW_OFFSET_M = 2e-3
_SHADOW_OFFSET_REL = 1e-5


@dataclass(frozen=True)
class RgbConfig:
    """Options of :func:`dataset.rendering.render.render_rgb` (the per-building look comes from the
    seed).

    ``wall_material``: ``"random"`` (drawn from the seed), ``"plaster"`` or ``"brick"``.
    ``sun_elevation_deg``: range the sun's elevation is drawn from.
    ``exposure``: tone-mapping gain. ``glass_reflectance``: Fresnel reflectance of
    glazing at normal incidence (real glass is ~0.04; windows read as glass at ~0.1).
    ``look``: ``"plain"`` (the default) or ``"photo"``, the texture photographs have, for
    structure from motion (:mod:`dataset.rendering.photo_look`); labels and depth are the
    same with either.
    """

    shadows: bool = True
    wall_material: WallMaterial = "random"
    sun_elevation_deg: tuple[float, float] = (20.0, 65.0)
    exposure: float = 1.6
    glass_reflectance: float = 0.1
    look: LookName = "plain"

    def __post_init__(self) -> None:
        if self.look not in get_args(LookName):
            names = " or ".join(repr(n) for n in get_args(LookName))
            raise ValueError(f"look must be {names}, got {self.look!r}")
        if self.wall_material not in ("random", "plaster", "brick"):
            raise ValueError(
                f"wall_material must be 'random', 'plaster' or 'brick', got {self.wall_material!r}"
            )
        lo, hi = self.sun_elevation_deg
        if not 0 < lo <= hi <= 90:
            raise ValueError(f"sun_elevation_deg must satisfy 0 < lo <= hi <= 90, got {lo, hi}")
        if self.exposure <= 0 or not 0 <= self.glass_reflectance <= 1:
            raise ValueError("exposure must be > 0 and glass_reflectance in [0, 1]")


_PLASTER = ((0.80, 0.78, 0.72), (0.85, 0.75, 0.55), (0.62, 0.62, 0.60), (0.78, 0.62, 0.50),
            (0.70, 0.76, 0.78), (0.88, 0.86, 0.82))
_BRICK = ((0.52, 0.22, 0.14), (0.45, 0.28, 0.20), (0.66, 0.52, 0.36), (0.38, 0.17, 0.12))
_ROOF = ((0.20, 0.20, 0.22), (0.42, 0.20, 0.14), (0.30, 0.34, 0.32), (0.45, 0.44, 0.42))
_FRAME = ((0.90, 0.90, 0.88), (0.16, 0.16, 0.17), (0.35, 0.24, 0.16))
_GROUND = ((0.22, 0.30, 0.14), (0.30, 0.30, 0.30), (0.42, 0.38, 0.33))


def sample_look(seed: int, config: RgbConfig = RgbConfig()) -> Look:
    """Draw a building's look (sun position, sky, ground, materials) from ``seed``."""
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, 0x5EED])

    def pick(palette: tuple[tuple[float, float, float], ...], jitter: float) -> np.ndarray:
        # Brightness varies freely, hue only a little (no pink grass).
        base = np.asarray(palette[rng.integers(len(palette))])
        tint = rng.uniform(1 - jitter / 4, 1 + jitter / 4, 3)
        return np.clip(base * rng.uniform(1 - jitter, 1 + jitter) * tint, 0.02, 0.95) ** 2.2

    azimuth = rng.uniform(0, 2 * np.pi)
    elevation = np.deg2rad(rng.uniform(*config.sun_elevation_deg))
    sun_dir = np.array(
        [np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth),
         np.sin(elevation)]
    )
    warmth = rng.uniform(0.0, 0.15)
    material = config.wall_material
    if material == "random":
        material = "brick" if rng.uniform() < 0.4 else "plaster"
    return Look(
        sun_dir=sun_dir,
        sun_rgb=2.0 * np.array([1.0, 0.96 - 0.3 * warmth, 0.90 - 0.6 * warmth]),
        sky_zenith_rgb=np.array([0.10, 0.22, 0.62]) * rng.uniform(0.8, 1.2),
        sky_horizon_rgb=np.array([0.62, 0.70, 0.80]) * rng.uniform(0.85, 1.1),
        ground_rgb=pick(_GROUND, 0.15),
        wall_material=material,
        wall_rgb=pick(_BRICK if material == "brick" else _PLASTER, 0.08),
        mortar_rgb=np.array([0.55, 0.53, 0.50]) ** 2.2,
        roof_rgb=pick(_ROOF, 0.1),
        frame_rgb=pick(_FRAME, 0.05),
        door_rgb=pick(((0.35, 0.22, 0.12), (0.20, 0.25, 0.32), (0.55, 0.12, 0.10)), 0.1),
        other_rgb=pick(((0.55, 0.55, 0.55), (0.25, 0.25, 0.27)), 0.1),
        interior_rgb=np.array([0.030, 0.032, 0.036]) * rng.uniform(0.7, 1.4),
        texture_seed=int(rng.integers(2**31)),
    )


def environment_radiance(dirs_unit: np.ndarray, look: Look, *, sun_disc: bool = True) -> np.ndarray:
    """Linear radiance (N, 3) of the environment map seen along unit directions (N, 3)."""
    d = np.asarray(dirs_unit, dtype=np.float64)
    out = np.empty((len(d), 3))
    up = d[:, 2]
    sky = up >= 0
    ds = d[sky]
    elev = np.sqrt(np.sqrt(ds[:, 2:3]))  # ~ elevation**0.45 without a general power
    radiance = look.sky_horizon_rgb + (look.sky_zenith_rgb - look.sky_horizon_rgb) * elev
    cos_sun = np.clip(ds @ look.sun_dir, 0.0, 1.0)
    glow = cos_sun**2
    glow = glow * glow
    glow = glow * glow  # cos**8
    halo = np.where(cos_sun > 0.97, cos_sun, 0.0)
    for _ in range(8):  # cos**256 by squaring: np.power is slow on large arrays
        halo = halo * halo
    radiance += (0.12 * glow + 0.3 * halo)[:, None] * look.sun_rgb
    if sun_disc:
        radiance += (40.0 * (cos_sun > np.cos(np.deg2rad(0.6))))[:, None] * look.sun_rgb
    out[sky] = radiance
    # Ground tones: a texture on an imagined plane 10 m below, fading into haze.
    dg = d[~sky]
    down = np.maximum(-dg[:, 2], 1e-3)
    gx, gy = 10.0 * dg[:, 0] / down, 10.0 * dg[:, 1] / down
    tone = 0.8 + 0.4 * value_noise(gx / 4.0, gy / 4.0, look.texture_seed + 7)
    tone *= 0.9 + 0.2 * value_noise(gx / 0.5, gy / 0.5, look.texture_seed + 8)
    sky_mean = 0.5 * (look.sky_zenith_rgb + look.sky_horizon_rgb)
    ground_light = look.sun_rgb * look.sun_dir[2] + sky_mean
    haze = np.exp(-12.0 * down)[:, None]
    out[~sky] = (look.ground_rgb * ground_light) * (tone[:, None] * (1 - haze)) + (
        0.8 * look.sky_horizon_rgb * haze
    )
    return out


def shade(
    raycaster: Raycaster,
    *,
    origins_m: np.ndarray,
    dirs: np.ndarray,
    face: np.ndarray,
    t: np.ndarray,
    config: RgbConfig,
    seed: int,
    pixel_angle_rad: float,
    textures: TextureSet | None = None,
) -> np.ndarray:
    """Linear radiance (N, 3) along rays whose first hits are ``face`` (-1: miss) at ``t``.

    ``pixel_angle_rad`` (about 1 / focal length in pixels) sets the pixel's footprint on
    the surface, below which texture detail fades to its mean (no moiré). ``textures``: the
    source's own materials (:mod:`dataset.rendering.textures`); a face that has one shows
    it instead of the procedural material (a textured window shows its texture, not glass).

    Parameters
    ----------
    origins_m, dirs : (N, 3) float
        The rays (``dirs`` any length; hit point = origin + t * dir).
    face : (N,) int, t : (N,) float
        First hits as returned by :meth:`envelope.geometry.raycast.Raycaster.first_hit`.
    """
    look = sample_look(seed, config)
    d_unit = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    out = np.empty((len(dirs), 3))
    miss = face < 0
    out[miss] = environment_radiance(d_unit[miss], look)
    photo = photo_look.photo_materials(look) if config.look == "photo" else None
    if photo is not None:
        ground = miss & (d_unit[:, 2] < 0) & (origins_m[:, 2] > 0)
        out[ground] = photo_look.ground_radiance(raycaster, origins_m[ground], d_unit[ground],
                                                 look, photo, pixel_angle_rad)
        far = np.flatnonzero(miss)
        trees, radiance = photo_backdrop.backdrop_radiance(
            origins_m[far], d_unit[far], raycaster.bounds_m, look, pixel_angle_rad)
        out[far[trees]] = radiance
    hit = np.flatnonzero(~miss)
    if len(hit) == 0:
        return out
    f = face[hit]
    mesh = raycaster.mesh
    p = origins_m[hit] + t[hit, None] * dirs[hit]
    d = d_unit[hit]
    n = raycaster.face_normals[f]
    # Shade the side the camera sees, whatever the winding of an imported mesh.
    n_front = np.where((np.einsum("ij,ij->i", n, d) > 0)[:, None], -n, n)
    label, facade = mesh.face_label[f], mesh.face_facade[f]

    cos_sun = np.clip(n_front @ look.sun_dir, 0.0, None)
    lit = np.ones(len(hit))
    if config.shadows:
        size = float(np.linalg.norm(np.ptp(raycaster.bounds_m, axis=0)))
        offset = _SHADOW_OFFSET_M + _SHADOW_OFFSET_REL * size
        facing = cos_sun > 0
        starts = p[facing] + offset * n_front[facing]
        to_sun = np.broadcast_to(look.sun_dir, starts.shape)
        lit[facing] = ~raycaster.occluded(starts, to_sun)
    lit = lit * (cos_sun > 0)

    # Skylight, desaturated: a white wall in shade reads grey-blue, not blue.
    mean_sky = 0.5 * (look.sky_zenith_rgb + look.sky_horizon_rgb)
    mean_sky = 0.6 * mean_sky.mean() + 0.4 * mean_sky
    up_share = (0.5 + 0.5 * n_front[:, 2])[:, None]
    ambient = 0.9 * mean_sky * up_share + 0.6 * look.ground_rgb * (1 - up_share)
    irradiance = look.sun_rgb * (cos_sun * lit)[:, None] + ambient

    cos_i = np.clip(-np.einsum("ij,ij->i", d, n_front), 0.15, 1.0)
    footprint_m = t[hit] * np.linalg.norm(dirs[hit], axis=1) * pixel_angle_rad / cos_i
    s, v = surface_coords(p, n_front)
    if photo is not None:  # no two walls alike: matching must not confuse them
        s = s + photo_look.plane_offset_m(p, n_front)
    albedo = _albedo(label, facade, s, v, look, footprint_m)
    textured = np.zeros(len(hit), dtype=bool)
    if textures is not None:
        textured, source_albedo = texture_albedo(textures, f, p, footprint_m)
        albedo[textured] = source_albedo[textured]
    if photo is not None:
        albedo = photo_look.surface_albedo(label, facade, s, v, n_front[:, 2], textured, albedo,
                                           look, photo, footprint_m)
    radiance = albedo * irradiance

    glass = (label == SemanticClass.WINDOW) & (facade != NO_FACADE) & ~textured
    if glass.any():
        radiance[glass] = _glass(
            d[glass], n_front[glass], s[glass], v[glass], lit[glass], irradiance[glass], look,
            config.glass_reflectance,
            photo=None if photo is None else _PhotoGlass(raycaster, p[glass], photo,
                                                         pixel_angle_rad, footprint_m[glass]),
        )
    out[hit] = radiance
    return out


def surface_coords(points_m: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Texture coordinates (m) of points on surfaces: (along the wall, height) on walls, (x, y) on
    near-horizontal surfaces. Inputs (N, 3); outputs two (N,) arrays."""
    horizontal = np.cross(np.array([0.0, 0.0, 1.0]), normals)
    length = np.linalg.norm(horizontal, axis=1, keepdims=True)
    flat = length[:, 0] < 0.3
    tangent = np.divide(horizontal, length, out=np.zeros_like(horizontal), where=length > 0)
    s = np.where(flat, points_m[:, 0], np.einsum("ij,ij->i", points_m, tangent))
    v = np.where(flat, points_m[:, 1], points_m[:, 2])
    return s, v


def _albedo(
    label: np.ndarray, facade: np.ndarray, s: np.ndarray, v: np.ndarray, look: Look,
    footprint_m: np.ndarray,
) -> np.ndarray:
    seed = look.texture_seed
    grain = 1.0 + 0.12 * (value_noise(s / 1.5, v / 1.5, seed) - 0.5)
    grain += 0.08 * detail(footprint_m, 0.25) * (value_noise(s / 0.25, v / 0.25, seed + 1) - 0.5)
    albedo = np.broadcast_to(look.other_rgb, (len(s), 3)) * grain[:, None]

    wall = label == SemanticClass.WALL
    if look.wall_material == "brick":
        albedo[wall] = _brick(s[wall], v[wall], look, footprint_m[wall]) * grain[wall, None]
    else:
        streaks = 1.0 - 0.10 * value_noise(s[wall] * 1.5, v[wall] / 6.0, seed + 2)
        albedo[wall] = look.wall_rgb * (grain[wall] * streaks)[:, None]

    roof = label == SemanticClass.ROOF
    rows = 0.92 + 0.08 * detail(footprint_m[roof], 0.35) * np.cos(2 * np.pi * v[roof] / 0.35)
    albedo[roof] = look.roof_rgb * (rows * grain[roof])[:, None]

    door = label == SemanticClass.DOOR
    wood = 1.0 + 0.3 * detail(footprint_m[door], 0.04) * (
        value_noise(s[door] * 25.0, v[door] * 0.6, seed + 3) - 0.5
    )
    albedo[door] = look.door_rgb * wood[:, None]

    frame = (label == SemanticClass.WINDOW) & (facade == NO_FACADE)
    albedo[frame] = look.frame_rgb
    return albedo


def _brick(s: np.ndarray, v: np.ndarray, look: Look, footprint_m: np.ndarray) -> np.ndarray:
    brick_w, brick_h = 0.25, 0.075  # metres, incl. mortar joint
    joint_u, joint_v = 0.05, 0.14  # mortar share of a brick's width and height
    row = np.floor(v / brick_h)
    u = s / brick_w + 0.5 * (row % 2)
    col = np.floor(u)
    mortar = ((u - col) < joint_u) | ((v / brick_h - row) < joint_v)
    tone = 0.8 + 0.4 * hash01(col.astype(np.int64), row.astype(np.int64), look.texture_seed + 4)
    sharp = np.where(mortar[:, None], look.mortar_rgb, look.wall_rgb * tone[:, None])
    mortar_share = 1 - (1 - joint_u) * (1 - joint_v)
    mean = mortar_share * look.mortar_rgb + (1 - mortar_share) * look.wall_rgb
    w = detail(footprint_m, brick_h)[:, None]
    return w * sharp + (1 - w) * mean


@dataclass(frozen=True)
class _PhotoGlass:
    """What glazing needs for the photo look: the scene (the ground in reflections), the hit
    points (N, 3), the look's materials and the pixels' footprints (N,)."""

    raycaster: Raycaster
    points_m: np.ndarray
    materials: photo_look.PhotoMaterials
    pixel_angle_rad: float
    footprint_m: np.ndarray


def _glass(
    d: np.ndarray, n: np.ndarray, s: np.ndarray, v: np.ndarray, lit: np.ndarray,
    irradiance: np.ndarray, look: Look, f0: float, photo: _PhotoGlass | None = None,
) -> np.ndarray:
    cos_i = np.clip(-np.einsum("ij,ij->i", d, n), 0.0, 1.0)
    fresnel = (f0 + (1 - f0) * (1 - cos_i) ** 5)[:, None]
    reflected = d + 2.0 * cos_i[:, None] * n
    mirror = environment_radiance(reflected, look, sun_disc=False)
    glint = (40.0 * lit * (reflected @ look.sun_dir > np.cos(np.deg2rad(0.6))))[:, None]
    rooms = 0.6 + 0.8 * value_noise(s / 1.3, np.floor(v / 3.0) * 7.1, look.texture_seed + 5)
    interior = look.interior_rgb * rooms[:, None] * (0.5 + 0.5 * irradiance)
    if photo is not None:
        down = (reflected[:, 2] < 0) & (photo.points_m[:, 2] > 0)
        mirror[down] = photo_look.ground_radiance(
            photo.raycaster, photo.points_m[down], reflected[down], look, photo.materials,
            photo.pixel_angle_rad)
        trees, radiance = photo_backdrop.backdrop_radiance(
            photo.points_m, reflected, photo.raycaster.bounds_m, look, photo.pixel_angle_rad)
        mirror[trees] = radiance
        interior = photo_look.window_interior(s, v, interior, irradiance, look, photo.materials,
                                              photo.footprint_m)
    return fresnel * (mirror + glint * look.sun_rgb) + (1 - fresnel) * interior
