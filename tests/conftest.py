"""Shared test fixtures: a labelled box building with exact truth, and the tiny benchmark.

``box_building``: a 20 m (x) x 12 m (y) x 9 m (z) box standing on the ground,
centred on the origin in x/y, 3 floors. Facades 1-4 run counter-clockwise
around the footprint: 1 faces -y, 2 faces +x, 3 faces +y, 4 faces -x. Each
floor has 1.5 m x 1.4 m windows every 4 m; facade 1 has a 1.2 m x 2.2 m door
in the middle of its ground floor instead of ground-floor windows. Windows
and door tile the wall plane exactly (no recess), so every area is exact.
Faces: walls/windows/door with their facade id, a roof (class roof) and a
bottom (class other), both facade id 0; the mesh is closed.

``tiny_benchmark``: the ``tiny`` preset generated once per test session at a
small resolution (see ``TINY_CONFIG``); returns the folder holding the scene
folders (one per building, named by building id).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import box as shapely_box

from dataset.generate import GenerateConfig, generate_preset
from dataset.scenes.scene_writer import generate_scene
from envelope.classes import NO_FACADE, SemanticClass
from envelope.footprint import polygon_to_geojson
from envelope.mesh import LabelledMesh, concatenate_meshes
from envelope.scenes.scene import read_scene
from envelope.truth import Building, BuildingTruth, FacadeTruth
from envelope.wwr import ClassAreas

BOX_SIZE_M = (20.0, 12.0, 9.0)
BOX_FLOORS = 3
_WINDOW_W_M, _WINDOW_H_M, _SILL_M, _WINDOW_PITCH_M = 1.5, 1.4, 0.9, 4.0
_DOOR_W_M, _DOOR_H_M = 1.2, 2.2


def _rect_mesh(corner: np.ndarray, along: np.ndarray, up: np.ndarray, s0: float, s1: float,
               z0: float, z1: float, label: int, facade: int) -> LabelledMesh:
    """Two triangles of the rectangle corner + [s0, s1] * along + [z0, z1] * up,
    counter-clockwise seen from the side along x up."""
    v = np.array([corner + s * along + z * up for s, z in ((s0, z0), (s1, z0), (s1, z1), (s0, z1))])
    return LabelledMesh(v, np.array([[0, 1, 2], [0, 2, 3]]), [label] * 2, [facade] * 2)


Opening = tuple[int, float, float, float, float]  # class, s0, s1, z0, z1 (facade coordinates)


def _facade_openings(facade_id: int, width_m: float) -> list[Opening]:
    """(class, s0, s1, z0, z1) of every window and door of one facade, in facade coordinates."""
    floor_h = BOX_SIZE_M[2] / BOX_FLOORS
    n_windows = int(width_m // _WINDOW_PITCH_M)
    first = (width_m - (n_windows - 1) * _WINDOW_PITCH_M) / 2
    openings = []
    for floor in range(BOX_FLOORS):
        if facade_id == 1 and floor == 0:
            s_mid = width_m / 2
            openings.append((SemanticClass.DOOR, s_mid - _DOOR_W_M / 2, s_mid + _DOOR_W_M / 2,
                             0.0, _DOOR_H_M))
            continue
        z0 = floor * floor_h + _SILL_M
        for k in range(n_windows):
            s_mid = first + k * _WINDOW_PITCH_M
            openings.append((SemanticClass.WINDOW, s_mid - _WINDOW_W_M / 2,
                             s_mid + _WINDOW_W_M / 2, z0, z0 + _WINDOW_H_M))
    return openings


def make_box_building() -> Building:
    """The labelled box described in the module docstring, with its exact truth."""
    sx, sy, height = BOX_SIZE_M
    corners = np.array([[-sx / 2, -sy / 2, 0], [sx / 2, -sy / 2, 0], [sx / 2, sy / 2, 0],
                        [-sx / 2, sy / 2, 0]])
    up = np.array([0.0, 0.0, 1.0])
    parts, facades = [], []
    for i in range(4):
        a, b = corners[i], corners[(i + 1) % 4]
        width = float(np.linalg.norm(b - a))
        along = (b - a) / width
        normal = np.cross(along, up)
        openings = _facade_openings(i + 1, width)
        s_breaks = sorted({0.0, width, *(o[1] for o in openings), *(o[2] for o in openings)})
        z_breaks = sorted({0.0, height, *(o[3] for o in openings), *(o[4] for o in openings)})
        for s0, s1 in zip(s_breaks[:-1], s_breaks[1:]):
            for z0, z1 in zip(z_breaks[:-1], z_breaks[1:]):
                sm, zm = (s0 + s1) / 2, (z0 + z1) / 2
                label = next((o[0] for o in openings if o[1] < sm < o[2] and o[3] < zm < o[4]),
                             SemanticClass.WALL)
                parts.append(_rect_mesh(a, along, up, s0, s1, z0, z1, label, i + 1))
        area = {c: sum((o[2] - o[1]) * (o[4] - o[3]) for o in openings if o[0] == c)
                for c in (SemanticClass.WINDOW, SemanticClass.DOOR)}
        window, door = area[SemanticClass.WINDOW], area[SemanticClass.DOOR]
        wall = width * height - window - door
        areas = ClassAreas(window, wall, door)
        facades.append(FacadeTruth(
            id=i + 1, normal=tuple(float(x) for x in normal), width_m=width, height_m=height,
            window_area_m2=window, wall_area_m2=wall, door_area_m2=door,
            facade_area_m2=areas.gross_m2, wwr=areas.wwr,
        ))
    x_axis, y_axis = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    roof_corner = corners[0] + height * up
    parts.append(_rect_mesh(roof_corner, x_axis, y_axis, 0, sx, 0, sy, SemanticClass.ROOF,
                            NO_FACADE))
    parts.append(_rect_mesh(corners[0], y_axis, x_axis, 0, sy, 0, sx, SemanticClass.OTHER,
                            NO_FACADE))
    mesh = concatenate_meshes(parts)
    window = sum(f.window_area_m2 for f in facades)
    wall = sum(f.wall_area_m2 for f in facades)
    door = sum(f.door_area_m2 for f in facades)
    areas = ClassAreas(window, wall, door)
    footprint = shapely_box(-sx / 2, -sy / 2, sx / 2, sy / 2)
    truth = BuildingTruth(
        id="box", type="imported", floors=BOX_FLOORS, height_m=height, window_area_m2=window,
        facade_area_m2=areas.gross_m2, wall_area_m2=wall, door_area_m2=door,
        wwr=areas.wwr, footprint=polygon_to_geojson(footprint),
        footprint_area_m2=float(footprint.area), facades=tuple(facades), name="test box",
    )
    return Building(mesh=mesh, truth=truth)


@pytest.fixture(scope="session")
def box_building() -> Building:
    """A labelled box building with exact truth (see the module docstring)."""
    return make_box_building()


def assert_complete_scene(root: Path, config: GenerateConfig) -> None:
    """A finished scene: every frame's files exist, splits and intrinsics as configured."""
    scene = read_scene(root)
    assert scene.building is not None
    for frame in scene.frames:
        for rel in (frame.file_path, frame.depth_file_path, frame.semantic_file_path,
                    frame.normal_file_path, frame.instance_file_path):
            assert rel is not None and scene.path(rel).is_file(), rel
        assert (frame.facade_id is not None) == (frame.split in ("ideal", "multi"))
        street = frame.split == "street" and config.street is not None
        assert frame.intrinsics == (config.street.intrinsics(config.resolution) if street
                                    else config.intrinsics())
    n_train = len(scene.frames_in("train"))
    assert n_train + len(scene.frames_in("eval")) == config.views
    assert n_train == int(np.floor(config.views * config.train_fraction))
    assert not list(root.parent.glob(".*.partial"))


TINY_CONFIG = GenerateConfig(resolution=96, views=16)
"""Tiny benchmark: 96 px images, 16 orbit views (8 train, 8 eval), ideal and multi views."""


@pytest.fixture(scope="session")
def tiny_benchmark(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Folder holding the ``tiny`` preset's scene folders, generated once per session."""
    root = tmp_path_factory.mktemp("tiny_benchmark")
    with warnings.catch_warnings():
        # An occluded facade view is dropped with a warning; tests see the result, not the noise.
        warnings.simplefilter("ignore", UserWarning)
        generate_preset("tiny", root, TINY_CONFIG, progress=False)
    return root


@pytest.fixture(scope="session")
def clean_scene(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The box building rendered once: 64 px, 8 orbit views, ideal and multi views (read only:
    copy it before changing it)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return generate_scene(make_box_building(), tmp_path_factory.mktemp("clean"),
                              GenerateConfig(resolution=64, views=8), seed=0, progress=False)
