"""The photo look (``RgbConfig(look="photo")``): the texture photographs have, so that
structure from motion finds thousands of features in a render.

Walls get brick, render or ashlar stone with weathering stains, grime streaks and a splash
zone; roofs tiles with moss, or a membrane when flat; window frames weathered; glazing a
blind or curtain per window and reflections of the ground; the ground is the plane z = 0
(paving round the building, a kerb, a road with markings, then grass) lit by the sun and
shaded by the building. Every pattern is a pure function of world coordinates (a wall's own
(along, height) coordinates, shifted per plane so that no two walls look alike, the ground's
x, y) and the look's seed, so it stays put between views; features smaller than a pixel's
footprint fade to their mean (no aliasing, which would differ from view to view). Only the
RGB image changes: labels, depth and facade ids are the same with either look.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from dataset.rendering.look import Look
from dataset.rendering.noise import detail, hash01, value_noise
from envelope.classes import NO_FACADE, SemanticClass

if TYPE_CHECKING:
    from envelope.geometry.raycast import Raycaster

PhotoWall = Literal["brick", "render", "stone"]

# Ground zones, by distance (m) from the building's bounding box in plan.
PAVING_WIDTH_M = 2.5
KERB_WIDTH_M = 0.3
ROAD_WIDTH_M = 7.0
PLINTH_HEIGHT_M = 0.9  # the stone base course of a rendered wall
HAZE_DISTANCE_M = 1500.0  # ground contrast falls to 1/e at this distance
_GROUND_SHADOW_OFFSET_M = 1e-3


@dataclass(frozen=True)
class PhotoMaterials:
    """The photo look's choices for one building, drawn from its texture seed."""

    wall: PhotoWall
    stone_rgb: np.ndarray  # linear (3,)
    paving_rgb: np.ndarray
    asphalt_rgb: np.ndarray
    moss_rgb: np.ndarray
    earth_rgb: np.ndarray
    blind_rgb: np.ndarray


def photo_materials(look: Look) -> PhotoMaterials:
    """The photo look's materials for ``look`` (brick walls stay brick; plaster walls become
    render over a stone plinth or ashlar stone, half each)."""
    rng = np.random.default_rng([look.texture_seed, 0xF070])
    wall: PhotoWall = "brick" if look.wall_material == "brick" else (
        "render" if rng.uniform() < 0.5 else "stone")
    return PhotoMaterials(
        wall=wall,
        stone_rgb=(np.array([0.62, 0.58, 0.52]) * rng.uniform(0.85, 1.1)) ** 2.2,
        paving_rgb=(np.array([0.55, 0.53, 0.50]) * rng.uniform(0.85, 1.1)) ** 2.2,
        asphalt_rgb=(np.array([0.24, 0.24, 0.25]) * rng.uniform(0.85, 1.15)) ** 2.2,
        moss_rgb=np.array([0.30, 0.36, 0.18]) ** 2.2,
        earth_rgb=(np.array([0.45, 0.38, 0.30]) * rng.uniform(0.8, 1.1)) ** 2.2,
        blind_rgb=(np.array([0.85, 0.82, 0.74]) * rng.uniform(0.6, 1.0)) ** 2.2,
    )


def plane_offset_m(points_m: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(N,) shift (m) of the along-wall texture coordinate, constant on each plane and
    different from plane to plane (by the normal's heading and the plane's distance from the
    origin), so that two walls never show the same pattern: structure from motion would
    take one for the other. Inputs (N, 3): points and unit normals."""
    horizontal = normals[:, :2]
    length = np.linalg.norm(horizontal, axis=1)
    heading = np.divide(horizontal, length[:, None], out=np.zeros_like(horizontal),
                        where=length[:, None] > 0)
    distance_m = np.einsum("ij,ij->i", points_m, normals)
    return 1013.7 * heading[:, 0] + 577.3 * heading[:, 1] + 13.1 * distance_m


def surface_albedo(label: np.ndarray, facade: np.ndarray, s: np.ndarray, v: np.ndarray,
                   normal_z: np.ndarray, textured: np.ndarray, albedo: np.ndarray, look: Look,
                   materials: PhotoMaterials, footprint_m: np.ndarray) -> np.ndarray:
    """(N, 3) linear albedo of surface hits in the photo look, from the plain look's
    ``albedo`` (N, 3): procedural walls and roofs get the photo materials, faces with a
    source's own material (``textured``) keep it, and every surface but glazing weathers.

    label, facade : (N,) class and facade ids; s, v : (N,) surface coordinates (m,
    :func:`dataset.rendering.shading.surface_coords`); normal_z : (N,) the seen side's
    normal z; footprint_m : (N,) a pixel's size on the surface.
    """
    out = np.array(albedo, dtype=np.float64)
    seed = look.texture_seed
    wall = (label == SemanticClass.WALL) & ~textured
    out[wall] = wall_albedo(s[wall], v[wall], look, materials, footprint_m[wall])
    roof = (label == SemanticClass.ROOF) & ~textured
    out[roof] = roof_albedo(s[roof], v[roof], normal_z[roof] > 0.95, look, materials,
                            footprint_m[roof])
    frame = (label == SemanticClass.WINDOW) & (facade == NO_FACADE)
    out[frame] *= frame_factor(s[frame], v[frame], seed)[:, None]
    glazing = (label == SemanticClass.WINDOW) & (facade != NO_FACADE)
    out[~glazing] *= weathering(s[~glazing], v[~glazing], seed, footprint_m[~glazing])[:, None]
    return out


def weathering(s: np.ndarray, v: np.ndarray, seed: int, footprint_m: np.ndarray) -> np.ndarray:
    """(N,) brightness factor, mean about 1, of a weathered surface at wall coordinates (m):
    stains from 4 m to 2 cm, vertical grime streaks and a darker splash zone above the
    ground."""
    w = 1.0 + 0.24 * (value_noise(s / 4.0, v / 4.0, seed + 11) - 0.5)
    w += 0.20 * (value_noise(s / 0.9, v / 0.9, seed + 12) - 0.5)
    w += 0.16 * detail(footprint_m, 0.25) * (value_noise(s / 0.25, v / 0.25, seed + 13) - 0.5)
    w += 0.12 * detail(footprint_m, 0.07) * (value_noise(s / 0.07, v / 0.07, seed + 14) - 0.5)
    w += 0.08 * detail(footprint_m, 0.02) * (value_noise(s / 0.02, v / 0.02, seed + 15) - 0.5)
    for scale_m, strength, k in ((2.0, 0.22, 17), (0.5, 0.3, 18), (0.15, 0.3, 19)):
        w *= 1.0 - strength * detail(footprint_m, scale_m / 4) * _blotches(s / scale_m,
                                                                          v / scale_m, seed + k)
    streak = np.clip(value_noise(s / 0.35, v / 6.0, seed + 16) - 0.55, 0.0, None)
    w *= 1.0 - 0.9 * streak
    w *= 1.0 - 0.18 * np.exp(-np.clip(v, 0.0, None) / 0.4)
    return w


def wall_albedo(s: np.ndarray, v: np.ndarray, look: Look, materials: PhotoMaterials,
                footprint_m: np.ndarray) -> np.ndarray:
    """(N, 3) linear albedo of procedural walls at wall coordinates (m), before weathering."""
    seed = look.texture_seed
    if materials.wall == "brick":
        return _blocks(s, v, look.wall_rgb, look.mortar_rgb, seed + 20, footprint_m,
                       size_m=(0.25, 0.075), joint_m=0.01, spread=0.7)
    stone = _blocks(s, v, materials.stone_rgb, 0.7 * materials.stone_rgb, seed + 21,
                    footprint_m, size_m=(0.6, 0.3), joint_m=0.015, spread=0.35)
    if materials.wall == "stone":
        return _blocks(s, v, look.wall_rgb, 0.75 * look.wall_rgb, seed + 22, footprint_m,
                       size_m=(0.55, 0.32), joint_m=0.012, spread=0.3)
    render = 1.0 + 0.10 * detail(footprint_m, 0.01) * (
        value_noise(s / 0.01, v / 0.01, seed + 23) - 0.5)
    out = look.wall_rgb * render[:, None]
    plinth = v < PLINTH_HEIGHT_M
    out[plinth] = stone[plinth]
    return out


def roof_albedo(s: np.ndarray, v: np.ndarray, flat: np.ndarray, look: Look,
                materials: PhotoMaterials, footprint_m: np.ndarray) -> np.ndarray:
    """(N, 3) linear albedo of roofs: tiles with moss on pitched ones (``flat`` False), a
    membrane with seams and gravel on flat ones."""
    seed = look.texture_seed
    tiles = _blocks(s, v, look.roof_rgb, 0.5 * look.roof_rgb, seed + 30, footprint_m,
                    size_m=(0.25, 0.33), joint_m=0.012, spread=0.5)
    overlap = 0.75 + 0.25 * detail(footprint_m, 0.33) * np.mod(v / 0.33, 1.0)
    tiles *= overlap[:, None]
    moss = np.clip(2.5 * (value_noise(s / 1.5, v / 1.5, seed + 31) - 0.6), 0.0, 1.0)
    tiles = tiles * (1 - moss[:, None]) + materials.moss_rgb * moss[:, None]
    membrane = _blocks(s, v, 0.8 * look.roof_rgb, 0.5 * look.roof_rgb, seed + 32, footprint_m,
                       size_m=(1.0, 4.0), joint_m=0.04, spread=0.15)
    gravel = 1.0 + 0.3 * detail(footprint_m, 0.03) * (
        value_noise(s / 0.03, v / 0.03, seed + 33) - 0.5)
    membrane *= gravel[:, None]
    return np.where(flat[:, None], membrane, tiles)


def frame_factor(s: np.ndarray, v: np.ndarray, seed: int) -> np.ndarray:
    """(N,) brightness of window frames: paint that varies from window to window."""
    return 0.75 + 0.5 * hash01(np.floor(s / 1.3).astype(np.int64),
                               np.floor(v / 3.0).astype(np.int64), seed + 40)


def window_interior(s: np.ndarray, v: np.ndarray, interior_rgb: np.ndarray,
                    irradiance: np.ndarray, look: Look, materials: PhotoMaterials,
                    footprint_m: np.ndarray) -> np.ndarray:
    """(N, 3) linear radiance seen through glazing: the dark room, with a blind drawn down a
    share of each window (cells 1.3 m wide, 3 m storeys) or a folded curtain beside it."""
    seed = look.texture_seed
    col = np.floor(s / 1.3).astype(np.int64)
    storey = np.floor(v / 3.0).astype(np.int64)
    drop_m = 2.6 * hash01(col, storey, seed + 41)
    in_storey = v - 3.0 * storey
    blind = in_storey > 3.0 - drop_m
    slats = 0.8 + 0.2 * detail(footprint_m, 0.05) * np.cos(2 * np.pi * v / 0.05)
    curtain = (~blind) & (np.mod(s / 1.3, 1.0) < 0.25 * hash01(col, storey, seed + 42))
    folds = 0.7 + 0.3 * detail(footprint_m, 0.12) * np.cos(2 * np.pi * s / 0.12)
    light = 0.35 * (0.5 + 0.5 * irradiance)
    out = interior_rgb.copy()
    out[blind] = materials.blind_rgb * (slats[blind, None] * light[blind])
    out[curtain] = materials.blind_rgb * 0.6 * (folds[curtain, None] * light[curtain])
    return out


def ground_radiance(raycaster: Raycaster, origins_m: np.ndarray, dirs_unit: np.ndarray,
                    look: Look, materials: PhotoMaterials, pixel_angle_rad: float
                    ) -> np.ndarray:
    """(N, 3) linear radiance of the ground plane z = 0 along downward rays (N, 3) from
    origins above it: paving, kerb, road with markings and grass by distance from the
    building, sunlit where the scene does not shade it, hazy far away."""
    t = -origins_m[:, 2] / np.minimum(dirs_unit[:, 2], -1e-9)
    p = origins_m + t[:, None] * dirs_unit
    footprint_m = t * pixel_angle_rad / np.clip(-dirs_unit[:, 2], 0.05, 1.0)
    albedo = ground_albedo(p[:, 0], p[:, 1], raycaster.bounds_m, look, materials, footprint_m)
    lit = np.zeros(len(p))
    if look.sun_dir[2] > 0:
        starts = p + np.array([0.0, 0.0, _GROUND_SHADOW_OFFSET_M])
        lit = (~raycaster.occluded(starts, np.broadcast_to(look.sun_dir, starts.shape))
               ).astype(float)
    sky = 0.5 * (look.sky_zenith_rgb + look.sky_horizon_rgb)
    sky = 0.6 * sky.mean() + 0.4 * sky
    irradiance = look.sun_rgb * (look.sun_dir[2] * lit)[:, None] + 0.9 * sky
    haze = (1.0 - np.exp(-t / HAZE_DISTANCE_M))[:, None]
    return albedo * irradiance * (1 - haze) + 0.8 * look.sky_horizon_rgb * haze


def ground_albedo(x: np.ndarray, y: np.ndarray, bounds_m: np.ndarray, look: Look,
                  materials: PhotoMaterials, footprint_m: np.ndarray) -> np.ndarray:
    """(N, 3) linear albedo of the ground at plan coordinates (m) round a building whose
    bounding box is ``bounds_m`` (2, 3)."""
    seed = look.texture_seed
    centre, half = bounds_m[:, :2].mean(axis=0), np.ptp(bounds_m[:, :2], axis=0) / 2
    dx = np.abs(x - centre[0]) - half[0]
    dy = np.abs(y - centre[1]) - half[1]
    ring_m = np.maximum(dx, dy)  # distance out from the box (square rings), < 0 inside
    out_m = np.maximum(ring_m, 0.0)
    along = np.where(dx > dy, y, x)  # the coordinate that runs along the ring
    grain = 1.0 + 0.25 * detail(footprint_m, 0.04) * (value_noise(x / 0.04, y / 0.04,
                                                                   seed + 50) - 0.5)
    grain += 0.2 * (value_noise(x / 2.0, y / 2.0, seed + 51) - 0.5)
    paving = _blocks(along, ring_m, materials.paving_rgb, 0.6 * materials.paving_rgb, seed + 52,
                     footprint_m, size_m=(0.6, 0.4), joint_m=0.015, spread=0.3)
    kerb = np.broadcast_to(1.2 * materials.paving_rgb, paving.shape)
    patches = 0.35 * (value_noise(x / 1.2, y / 1.2, seed + 53) - 0.5)
    patches += 0.3 * detail(footprint_m, 0.3) * (value_noise(x / 0.3, y / 0.3, seed + 56) - 0.5)
    cracks = np.abs(value_noise(x / 0.8, y / 0.8, seed + 57) - 0.5) < 0.02
    patches -= 0.4 * cracks * detail(footprint_m, 0.05)
    patches += 0.35 * detail(footprint_m, 0.2) * _blotches(x / 0.8, y / 0.8, seed + 62)
    road = materials.asphalt_rgb * (1.0 + patches)[:, None]
    across = out_m - PAVING_WIDTH_M - KERB_WIDTH_M
    edge_line = (across > 0.3) & (across < 0.45)
    centre_line = (np.abs(across - ROAD_WIDTH_M / 2) < 0.075) & (np.mod(along / 6.0, 1.0) < 0.5)
    marking = (edge_line | centre_line).astype(float) * detail(footprint_m, 0.15)
    road = road * (1 - marking[:, None]) + 0.6 * marking[:, None]
    earth = np.clip(2.0 * (value_noise(x / 3.0, y / 3.0, seed + 58) - 0.45), 0.0, 1.0)
    grass = (look.ground_rgb * (1 - earth[:, None]) + materials.earth_rgb * earth[:, None]) * (
        0.75 + 0.5 * value_noise(x / 5.0, y / 5.0, seed + 54))[:, None]
    tufts = 0.5 * (value_noise(x / 0.8, y / 0.8, seed + 59) - 0.5)
    tufts += 0.5 * detail(footprint_m, 0.25) * (value_noise(x / 0.25, y / 0.25, seed + 55) - 0.5)
    tufts += 0.4 * detail(footprint_m, 0.08) * (value_noise(x / 0.08, y / 0.08, seed + 60) - 0.5)
    grass *= (1.0 + tufts)[:, None] * (1.0 - 0.3 * detail(footprint_m, 0.1) * _blotches(
        x / 0.4, y / 0.4, seed + 61))[:, None]
    zone = np.digitize(out_m, np.cumsum([PAVING_WIDTH_M, KERB_WIDTH_M, ROAD_WIDTH_M]))
    albedo = np.choose(zone[:, None], [paving, kerb, road, grass])
    return albedo * grain[:, None]


def _blotches(x: np.ndarray, y: np.ndarray, seed: int) -> np.ndarray:
    """(N,) irregular patches in [0, 1] with edges a tenth of the lattice wide (stains,
    repairs): value noise above a threshold, about a third of the area."""
    return np.clip((value_noise(x, y, seed) - 0.55) / 0.05, 0.0, 1.0)


def _blocks(s: np.ndarray, v: np.ndarray, rgb: np.ndarray, joint_rgb: np.ndarray, seed: int,
            footprint_m: np.ndarray, *, size_m: tuple[float, float], joint_m: float,
            spread: float) -> np.ndarray:
    """(N, 3) linear albedo of a running bond of blocks ``size_m`` (width, height) with
    joints ``joint_m`` wide: each block's tone drawn in 1 +- spread / 2 with a slight tint;
    blocks and joints fade to their mean below the pixel's footprint."""
    w, h = size_m
    row = np.floor(v / h)
    u = s / w + 0.5 * (row % 2)
    col = np.floor(u)
    ic, ir = col.astype(np.int64), row.astype(np.int64)
    tone = 1.0 + spread * (hash01(ic, ir, seed) - 0.5)
    tint = 1.0 + 0.12 * (np.stack([hash01(ic, ir, seed + k) for k in (1, 2, 3)], axis=1) - 0.5)
    block = rgb * tint * tone[:, None]
    w_block = detail(footprint_m, h)[:, None]
    block = w_block * block + (1 - w_block) * rgb
    joint = ((u - col) * w < joint_m) | ((v - row * h) < joint_m)
    w_joint = detail(footprint_m, 2 * joint_m)[:, None]
    joint_share = 1 - (1 - joint_m / w) * (1 - joint_m / h)
    mean_joint = joint_share * joint_rgb + (1 - joint_share) * block
    sharp = np.where(joint[:, None], joint_rgb, block)
    return w_joint * sharp + (1 - w_joint) * mean_joint
