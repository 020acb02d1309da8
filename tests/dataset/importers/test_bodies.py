"""dataset.importers.mesh.bodies: bodies found and turned outwards one by one; faces paired round
edges that more than two faces use (dataset.importers.mesh.edge_pairs)."""

import numpy as np
import shapely
import trimesh

from dataset.importers.mesh.bodies import orient_bodies
from dataset.importers.mesh.edge_pairs import face_pairs
from dataset.importers.mesh.mesh_files import merge_vertices
from envelope.geometry.raycast import winding_numbers


def _box(lo, hi) -> trimesh.Trimesh:
    return trimesh.creation.box(bounds=np.array([lo, hi], dtype=float))


def _soup(*meshes):
    both = trimesh.util.concatenate(list(meshes))
    return np.asarray(both.vertices), np.asarray(both.faces)


def _volumes(v, faces, body):
    t = v[faces]
    return np.bincount(body, weights=np.einsum("ij,ij->i", t[:, 0],
                                               np.cross(t[:, 1], t[:, 2])) / 6.0)


def test_each_body_is_turned_outwards_whatever_the_others_do():
    # A closed box, the same box inside out elsewhere, one with a flipped face, one with a
    # face missing (open, inside out), a single triangle (a sheet).
    inverted = _box((20, 0, 0), (21, 1, 1))
    inverted.invert()
    flipped = _box((40, 0, 0), (42, 1, 1))
    flipped.faces[3] = flipped.faces[3][::-1]
    holed = _box((60, 0, 0), (61, 2, 1))
    holed = trimesh.Trimesh(holed.vertices, holed.faces[1:, ::-1], process=False)
    sheet = trimesh.Trimesh([[80, 0, 0], [81, 0, 0], [81, 0, 1]], [[0, 1, 2]], process=False)
    v, f = _soup(_box((0, 0, 0), (10, 8, 6)), inverted, flipped, holed, sheet)
    bodies = orient_bodies(v, f)
    assert bodies.counts == {"bodies": 5, "closed": 3, "open": 2, "sheets": 1,
                             "turned_inside_out": 2, "cavities": 0, "rewound": 1}
    volume = _volumes(v, bodies.faces, bodies.body)
    np.testing.assert_allclose(volume[:3], [480.0, 1.0, 2.0], rtol=1e-12)
    assert volume[3] > 0 and volume[4] == 0.0
    assert bodies.sheet.sum() == 1 and bodies.open_body.sum() == 12


def test_touching_bodies_stay_apart_and_elements_never_share_a_body():
    # Two boxes sharing an edge: four faces use it, so the bodies are two.
    v, f = _soup(_box((0, 0, 0), (1, 1, 1)), _box((1, 1, 0), (2, 2, 1)))
    assert orient_bodies(v, f).counts == {"bodies": 2, "closed": 2, "open": 0, "sheets": 0,
                                          "turned_inside_out": 0, "cavities": 0, "rewound": 0}
    # Two boxes sharing a whole face (same corners): every edge of it is used by four faces,
    # paired round it box by box, so each box stays closed.
    v, f = _soup(_box((0, 0, 0), (1, 1, 1)), _box((1, 0, 0), (2, 1, 1)))
    bodies = orient_bodies(v, f)
    assert bodies.counts == {"bodies": 2, "closed": 2, "open": 0, "sheets": 0,
                             "turned_inside_out": 0, "cavities": 0, "rewound": 0}
    np.testing.assert_allclose(_volumes(v, bodies.faces, bodies.body), [1.0, 1.0], rtol=1e-12)
    # One element of two disjoint boxes is two bodies; two open halves of one box given as
    # two elements are never joined into it.
    box = _box((0, 0, 0), (1, 1, 1))
    group = (np.arange(12) >= 6).astype(int)
    assert orient_bodies(box.vertices, box.faces, group).counts["open"] == 2


def test_a_cavity_that_the_others_enclose_keeps_its_orientation():
    # A room: the inner surface of a shell (faces pointing into the room), inside the
    # shell's outer surface. Turning it would fill the room.
    outer = _box((0, 0, 0), (10, 8, 6))
    room = _box((1, 1, 1), (9, 7, 5))
    room.invert()
    v, f = _soup(outer, room)
    bodies = orient_bodies(v, f)
    assert bodies.counts["cavities"] == 1 and bodies.counts["turned_inside_out"] == 0
    assert winding_numbers(v[bodies.faces], np.array([[5.0, 4.0, 3.0]]))[0] < 0.5


def _mitred_walls():
    """Two walls 3 m high, 0.3 m thick, meeting at a 45-degree mitre at (10, 0): wall A
    along x (outer face y = 0), wall B along y (outer face x = 10); their mitre faces
    coincide, so each of the mitre's four edges is used by four faces."""
    a = trimesh.creation.extrude_polygon(
        shapely.Polygon([(0, 0), (10, 0), (9.7, 0.3), (0, 0.3)]), 3.0)
    b = trimesh.creation.extrude_polygon(
        shapely.Polygon([(10, 0), (10, 8), (9.7, 8), (9.7, 0.3)]), 3.0)
    return a, b


def test_walls_meeting_at_a_mitre_are_two_closed_bodies():
    a, b = _mitred_walls()
    v, f = _soup(a, b)
    bodies = orient_bodies(v, f)
    assert bodies.counts == {"bodies": 2, "closed": 2, "open": 0, "sheets": 0,
                             "turned_inside_out": 0, "cavities": 0, "rewound": 0}
    np.testing.assert_allclose(_volumes(v, bodies.faces, bodies.body),
                               [(10 + 9.7) / 2 * 0.3 * 3, (8 + 7.7) / 2 * 0.3 * 3], rtol=1e-12)
    # Wall A given inside out: its faces and B's no longer pair round the mitre's edges, so
    # none are joined there (no body takes faces of both walls); A, open at the mitre, is
    # still turned outwards.
    outward = a.face_normals.copy()
    a.invert()
    v, f = _soup(a, b)
    bodies = orient_bodies(v, f)
    owner = np.arange(len(f)) >= len(a.faces)
    assert all(len(np.unique(owner[bodies.body == i])) == 1
               for i in range(bodies.counts["bodies"]))
    t = v[bodies.faces[: len(a.faces)]]
    normals = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    mitre = np.isclose(outward @ np.array([1.0, 1.0, 0.0]) / np.sqrt(2), 1.0)
    assert (np.einsum("ij,ij->i", normals, outward)[~mitre] > 0).all()


def test_four_boxes_round_one_edge_are_four_closed_bodies():
    # The edge x = y = 1 is used by eight faces, four boxes' two each.
    boxes = [_box((x, y, 0), (x + 1, y + 1, 2)) for x in (0, 1) for y in (0, 1)]
    v, f = _soup(*boxes)
    bodies = orient_bodies(v, f)
    assert bodies.counts == {"bodies": 4, "closed": 4, "open": 0, "sheets": 0,
                             "turned_inside_out": 0, "cavities": 0, "rewound": 0}
    np.testing.assert_allclose(_volumes(v, bodies.faces, bodies.body), [2.0] * 4, rtol=1e-12)


def test_face_pairs_join_each_wedge_of_a_mitre():
    a, b = _mitred_walls()
    v, f = _soup(a, b)
    merged_v, merged_f = merge_vertices(v, f)
    pairs = face_pairs(merged_v, merged_f)
    owner = (np.arange(len(f)) >= len(a.faces)).astype(int)
    assert (owner[pairs[:, 0]] == owner[pairs[:, 1]]).all()  # never across the joint
    # Every edge of each wall is used by exactly two of its own faces: 3 per face, halved.
    assert len(pairs) == 3 * len(f) // 2


def test_a_solid_given_twice_is_two_closed_bodies():
    # Overlapping elements that repeat each other's faces (window members in IfcOpenHouse):
    # every edge is used by two identical pairs, either of which closes the box.
    v, f = _soup(_box((0, 0, 0), (1, 2, 3)), _box((0, 0, 0), (1, 2, 3)))
    bodies = orient_bodies(v, f)
    assert bodies.counts == {"bodies": 2, "closed": 2, "open": 0, "sheets": 0,
                             "turned_inside_out": 0, "cavities": 0, "rewound": 0}
    np.testing.assert_allclose(_volumes(v, bodies.faces, bodies.body), [6.0, 6.0], rtol=1e-12)
