"""dataset.importers.mesh.facade_grouping: offsets, gaps, narrow pieces, tilted faces, curved
walls."""

import numpy as np
import trimesh

from dataset.importers.mesh.facade_grouping import facade_ids_of_faces, group_facades

KW = dict(max_tilt_deg=10.0, angle_tolerance_deg=10.0, offset_tolerance_m=0.3,
          gap_tolerance_m=0.05, min_width_m=0.5)


def _quad(corner, along, up):
    """Two triangles of the rectangle corner + s*along + t*up, normal along x up."""
    c, a, u = (np.asarray(v, dtype=float) for v in (corner, along, up))
    return [[c, c + a, c + a + u], [c, c + a + u, c + u]]


def _group(quads):
    tri = np.array([t for q in quads for t in q])
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    areas = np.linalg.norm(n, axis=1) / 2
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return group_facades(tri, n, areas, np.ones(len(tri), bool), **KW), tri


def test_parallel_walls_at_different_offsets_are_two_facades():
    # Two walls facing +x (along +y, up +z gives normal +x) at x = 0 and x = 5.
    groups, _ = _group([_quad([0, 0, 0], [0, 4, 0], [0, 0, 3]),
                        _quad([5, 4, 0], [0, 4, 0], [0, 0, 3])])
    assert len(groups) == 2
    assert [round(g.offset_m, 9) for g in groups] == [0.0, 5.0]
    np.testing.assert_allclose(groups[0].normal, [1, 0, 0], atol=1e-12)


def test_coplanar_pieces_split_only_at_a_gap():
    touching, _ = _group([_quad([0, 0, 0], [0, 4, 0], [0, 0, 3]),
                          _quad([0, 4, 0], [0, 2, 0], [0, 0, 1])])
    assert len(touching) == 1 and touching[0].along_m == (0.0, 6.0)
    apart, _ = _group([_quad([0, 0, 0], [0, 4, 0], [0, 0, 3]),
                       _quad([0, 5, 0], [0, 2, 0], [0, 0, 3])])
    assert len(apart) == 2


def test_recessed_piece_joins_and_narrow_or_tilted_pieces_do_not():
    groups, tri = _group([
        _quad([0, 0, 0], [0, 4, 0], [0, 0, 3]),
        _quad([-0.2, 1, 1], [0, 1, 0], [0, 0, 1]),  # window set back 0.2 m: same facade
        _quad([3, 0, 0], [0, 0.3, 0], [0, 0, 3]),  # 0.3 m wide at x = 3: too narrow
        _quad([6, 0, 0], [0, 4, 0], [-1, 0, 3]),  # leans 18 deg: roof-like
    ])
    assert len(groups) == 1
    ids = facade_ids_of_faces(groups, len(tri))
    np.testing.assert_array_equal(ids, [1, 1, 1, 1, 0, 0, 0, 0])


def test_cylinder_is_cut_into_sectors_no_wider_than_twice_the_tolerance():
    cyl = trimesh.creation.cylinder(radius=10.0, height=6.0, sections=72)
    n = cyl.face_normals
    groups = group_facades(cyl.triangles, n, cyl.area_faces, np.ones(len(n), bool), **KW)
    side = np.abs(n[:, 2]) < 0.5
    assert sum(len(g.face_index) for g in groups) == side.sum()
    for g in groups:
        h = n[g.face_index, :2]
        spread = np.degrees(np.arccos(np.clip(h @ np.asarray(g.normal[:2]), -1, 1)))
        assert spread.max() <= KW["angle_tolerance_deg"] + 1e-9
    assert 360 / 20 <= len(groups) <= 360 / 5
