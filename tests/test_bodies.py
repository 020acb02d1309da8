"""dataset.importers.bodies: bodies found and turned outwards one by one."""

import numpy as np
import trimesh

from dataset.importers.bodies import orient_bodies
from dataset.rendering.raycast import winding_numbers


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
    # Two boxes sharing a whole face (same corners, same diagonal): the two coincident
    # triangles pairs close on each other into a flat body between them; each box, open
    # there, keeps its outward orientation.
    v, f = _soup(_box((0, 0, 0), (1, 1, 1)), _box((1, 0, 0), (2, 1, 1)))
    bodies = orient_bodies(v, f)
    assert bodies.counts["turned_inside_out"] == 0 and bodies.counts["sheets"] >= 1
    assert (_volumes(v, bodies.faces, bodies.body)[~np.isin(
        np.arange(bodies.counts["bodies"]), bodies.body[bodies.sheet])] > 0).all()
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
