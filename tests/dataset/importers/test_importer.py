"""dataset.importer: hand-computed areas, facades and footprints of labelled meshes; bad input.

Planar faces give areas exact to float round-off, so areas are checked to a relative
error of 1e-6 (DESIGN: exact truth) and footprints to IoU >= 0.999.
"""

from pathlib import Path

import numpy as np
import pytest
import trimesh
from paths import REPO_ROOT
from shapely.geometry import Polygon

from dataset.examples.make_example_bim import (
    DOOR,
    WALL,
    WINDOW,
    boxes_mesh,
    example_bim_boxes,
    write_labelled_obj,
)
from dataset.importers.mesh.mesh_import import ImportConfig, import_labelled_mesh
from dataset.presets import build_building, preset_recipes
from envelope.classes import SemanticClass
from envelope.footprint import geojson_to_polygon
from envelope.mesh import LabelledMesh, write_labelled_ply

REL = 1e-6
EXAMPLES = REPO_ROOT / "dataset" / "examples"

# The example BIM building (make_example_bim.py), by hand. Facade ids follow the outward
# normal's azimuth counter-clockwise from +x: east, north, west, south.
BIM_FACADES = {  # id: (normal, width, height, window, door, gross)
    1: ((1, 0, 0), 8.0, 6.3, 2 * 1.5 * 1.2, 0.0, 8 * 6.3),
    2: ((0, 1, 0), 12.0, 6.3, 0.0, 1.0 * 2.1, 12 * 6.3),
    3: ((-1, 0, 0), 8.0, 6.3, 0.0, 0.0, 8 * 6.3),
    4: ((0, -1, 0), 12.0, 6.3, 6 * 1.5 * 1.2, 0.0, 12 * 6.3),
}
# Two rooms 5.55 x 7.4 m, 5.7 m high, inside 0.3 m walls: all their walls are hidden.
BIM_HIDDEN_M2 = 2 * 2 * (5.55 + 7.4) * 5.7


def _iou(a, b) -> float:
    return a.intersection(b).area / a.union(b).area


def _check_facades(truth, expected):
    assert len(truth.facades) == len(expected)
    for fid, (normal, width, height, window, door, gross) in expected.items():
        f = truth.facade(fid)
        np.testing.assert_allclose(f.normal, normal, atol=1e-12)
        assert f.width_m == pytest.approx(width, rel=REL)
        assert f.height_m == pytest.approx(height, rel=REL)
        assert f.window_area_m2 == pytest.approx(window, rel=REL, abs=1e-9)
        assert f.door_area_m2 == pytest.approx(door, rel=REL, abs=1e-9)
        assert f.facade_area_m2 == pytest.approx(gross, rel=REL)
        assert f.wall_area_m2 == pytest.approx(gross - window - door, rel=REL)
        assert f.wwr == pytest.approx(window / gross, rel=REL, abs=1e-12)


@pytest.fixture(scope="module")
def bim_mesh() -> LabelledMesh:
    return boxes_mesh(example_bim_boxes())


@pytest.mark.parametrize("form", ["ply", "objects", "groups", "materials"])
def test_example_bim_matches_hand_computed_truth(bim_mesh, tmp_path, form):
    path = tmp_path / ("bim.ply" if form == "ply" else "bim.obj")
    if form == "ply":
        write_labelled_ply(path, bim_mesh)
    else:
        write_labelled_obj(path, bim_mesh, naming=form)
    building = import_labelled_mesh(path, building_id="bim")
    t = building.truth
    assert (t.id, t.type, t.floors) == ("bim", "imported", 2)
    assert t.height_m == pytest.approx(6.3, rel=REL)
    _check_facades(t, BIM_FACADES)
    assert t.window_area_m2 == pytest.approx(8 * 1.5 * 1.2, rel=REL)
    assert t.door_area_m2 == pytest.approx(2.1, rel=REL)
    assert t.facade_area_m2 == pytest.approx(2 * (12 + 8) * 6.3, rel=REL)
    assert t.wwr == pytest.approx(14.4 / 252.0, rel=REL)
    # Inner faces of the outer walls, windows, door and the partition are not facade.
    assert sum(t.extra["hidden_area_m2"].values()) == pytest.approx(BIM_HIDDEN_M2, rel=REL)
    assert sum(t.extra["unassigned_area_m2"].values()) == 0.0
    # Recentred: x/y box centred on the origin, ground at z = 0; footprint is the outline.
    box = Polygon([(-6, -4), (6, -4), (6, 4), (-6, 4)])
    footprint = geojson_to_polygon(t.footprint)
    assert _iou(footprint, box) >= 0.999
    assert t.footprint_area_m2 == pytest.approx(96.0, rel=REL)
    assert building.mesh.vertices_m[:, 2].min() == 0.0
    # Facade ids in the mesh agree with the truth's per-facade areas.
    areas = building.mesh.face_areas_m2()
    for f in t.facades:
        assert areas[building.mesh.face_facade == f.id].sum() == pytest.approx(
            f.facade_area_m2, rel=REL
        )


def test_shipped_example_files_are_reproducible(bim_mesh, tmp_path):
    write_labelled_ply(tmp_path / "example_bim.ply", bim_mesh)
    write_labelled_obj(tmp_path / "example_bim.obj", bim_mesh, naming="objects")
    for name in ("example_bim.ply", "example_bim.obj"):
        shipped = EXAMPLES / name
        assert shipped.stat().st_size < 200_000
        assert shipped.read_bytes() == (tmp_path / name).read_bytes(), (
            f"{name} is stale: run python -m dataset.examples.make_example_bim"
        )


def _l_shaped_boxes():
    """Main block 20 x 8 x 6 m, a lower wing 8 x 8 x 4 m to the north of its west end."""
    boxes = [((0, 0, 0), (20, 8, 6), WALL), ((0, 8, 0), (8, 16, 4), WALL)]
    for x0 in (2, 6, 12, 16):  # south: four 2 x 1.5 m windows
        boxes.append(((x0, 0, 1.5), (x0 + 2, 0.2, 3.0), WINDOW))
    for y0 in (10, 13):  # wing east face: two 1.5 x 1.2 m windows
        boxes.append(((7.8, y0, 1.0), (8, y0 + 1.5, 2.2), WINDOW))
    boxes.append(((3, 15.8, 0), (4, 16, 2), DOOR))  # wing north face: 1 x 2 m door
    return boxes


def test_l_shaped_building_has_six_facades(tmp_path):
    write_labelled_ply(tmp_path / "l.ply", boxes_mesh(_l_shaped_boxes()))
    t = import_labelled_mesh(tmp_path / "l.ply").truth
    expected = {
        1: ((1, 0, 0), 8.0, 4.0, 2 * 1.5 * 1.2, 0.0, 32.0),  # wing east, x = 8
        2: ((1, 0, 0), 8.0, 6.0, 0.0, 0.0, 48.0),  # main east, x = 20
        # Main north at y = 8: full height east of the wing, above the wing's roof west of it.
        3: ((0, 1, 0), 20.0, 6.0, 0.0, 0.0, 12 * 6 + 8 * 2),
        4: ((0, 1, 0), 8.0, 4.0, 0.0, 2.0, 32.0),  # wing north, y = 16
        5: ((-1, 0, 0), 16.0, 6.0, 0.0, 0.0, 8 * 6 + 8 * 4),  # west
        6: ((0, -1, 0), 20.0, 6.0, 4 * 2 * 1.5, 0.0, 120.0),  # south
    }
    _check_facades(t, expected)
    ell = Polygon([(0, 0), (20, 0), (20, 8), (8, 8), (8, 16), (0, 16)])
    ell = Polygon(np.asarray(ell.exterior.coords) - [10, 8])
    assert _iou(geojson_to_polygon(t.footprint), ell) >= 0.999
    assert t.footprint_area_m2 == pytest.approx(224.0, rel=REL)


def test_courtyard_stays_a_hole_and_recessed_windows_stay_on_their_facade(tmp_path):
    # 12 x 12 x 3 m ring around a 4 x 4 m courtyard; one window on the south face is set
    # back 0.2 m into the wall (carved out with background), so its reveals face sideways.
    boxes = [
        ((0, 0, 0), (12, 12, 3), WALL),
        ((4, 4, 0), (8, 8, 3), SemanticClass.BACKGROUND),
        ((5, 0, 1), (7, 0.2, 2), SemanticClass.BACKGROUND),
        ((5, 0.2, 1), (7, 0.3, 2), WINDOW),
    ]
    write_labelled_ply(tmp_path / "o.ply", boxes_mesh(boxes))
    t = import_labelled_mesh(tmp_path / "o.ply").truth
    assert len(t.facades) == 8  # four outside, four around the courtyard
    south = [f for f in t.facades if f.normal[1] < -0.5 and f.width_m > 10]
    assert len(south) == 1
    assert south[0].window_area_m2 == pytest.approx(2.0, rel=REL)
    assert south[0].facade_area_m2 == pytest.approx(36.0, rel=REL)
    footprint = geojson_to_polygon(t.footprint)
    assert len(footprint.interiors) == 1
    assert t.footprint_area_m2 == pytest.approx(144.0 - 16.0, rel=REL)
    # The two 0.2 m deep, 1 m high wall reveals are seen from outside but are no facade
    # (sill and head faces are horizontal and labelled other by the generator).
    assert t.extra["unassigned_area_m2"]["wall"] == pytest.approx(2 * 0.2 * 1.0, rel=REL)


def test_glb_with_y_up_and_named_parts(bim_mesh, tmp_path):
    scene = trimesh.Scene()
    y_up = bim_mesh.vertices_m[:, [0, 2, 1]] * [1, 1, -1]  # (x, y, z) -> (x, z, -y)
    for cls in np.unique(bim_mesh.face_label):
        part = trimesh.Trimesh(y_up, bim_mesh.faces[bim_mesh.face_label == cls], process=False)
        name = SemanticClass(cls).name.capitalize()
        scene.add_geometry(part, node_name=f"{name}.001", geom_name=f"mesh{cls}")
    scene.export(tmp_path / "bim.glb")
    t = import_labelled_mesh(tmp_path / "bim.glb", config=ImportConfig(up_axis="y")).truth
    _check_facades(t, BIM_FACADES)


def test_imported_truth_is_deterministic(tmp_path, bim_mesh):
    write_labelled_ply(tmp_path / "a.ply", bim_mesh)
    a = import_labelled_mesh(tmp_path / "a.ply")
    b = import_labelled_mesh(tmp_path / "a.ply")
    assert a.truth.to_json_dict() == b.truth.to_json_dict()
    np.testing.assert_array_equal(a.mesh.face_facade, b.mesh.face_facade)


# --- bad input -------------------------------------------------------------------------

def _box_obj(tmp_path, body: str) -> Path:
    path = tmp_path / "bad.obj"
    box = trimesh.creation.box([4.0, 4.0, 3.0])
    lines = [f"v {x} {y} {z}" for x, y, z in box.vertices] + [body]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in box.faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_ply_without_labels_is_refused(tmp_path):
    trimesh.creation.box().export(tmp_path / "plain.ply")
    with pytest.raises(ValueError, match="no per-face 'label'"):
        import_labelled_mesh(tmp_path / "plain.ply")


def test_obj_without_names_is_refused(tmp_path):
    with pytest.raises(ValueError, match="has no labels.*Name each object"):
        import_labelled_mesh(_box_obj(tmp_path, ""))


def test_unknown_class_name_is_refused(tmp_path):
    with pytest.raises(ValueError, match="cannot tell the class of parts named Balustrade"):
        import_labelled_mesh(_box_obj(tmp_path, "o Balustrade"))


def test_mesh_without_facade_classes_is_refused(tmp_path):
    with pytest.raises(ValueError, match="no wall, window or door faces.*roof"):
        import_labelled_mesh(_box_obj(tmp_path, "usemtl Roof"))


def test_empty_mesh_is_refused(tmp_path):
    (tmp_path / "empty.obj").write_text("o Wall\nv 0 0 0\n")
    with pytest.raises(ValueError, match="holds no faces"):
        import_labelled_mesh(tmp_path / "empty.obj")


def test_open_body_is_imported_and_counted(tmp_path, bim_mesh):
    # One face of the example building missing: its body is open, the rest is unchanged.
    keep = np.ones(len(bim_mesh.faces), dtype=bool)
    keep[0] = False
    holed = LabelledMesh(bim_mesh.vertices_m, bim_mesh.faces[keep], bim_mesh.face_label[keep],
                         bim_mesh.face_facade[keep])
    write_labelled_ply(tmp_path / "holed.ply", holed)
    t = import_labelled_mesh(tmp_path / "holed.ply").truth
    assert t.extra["bodies"]["open"] == 1
    assert t.window_area_m2 == pytest.approx(_example_truth(tmp_path, bim_mesh).window_area_m2,
                                             rel=REL)


def test_flipped_faces_and_inside_out_bodies_are_turned_round(tmp_path, bim_mesh):
    faces = bim_mesh.faces.copy()
    faces[0] = faces[0, ::-1]
    flipped_one = LabelledMesh(bim_mesh.vertices_m, faces, bim_mesh.face_label,
                               bim_mesh.face_facade)
    write_labelled_ply(tmp_path / "one.ply", flipped_one)
    t = import_labelled_mesh(tmp_path / "one.ply").truth
    assert t.extra["bodies"]["rewound"] == 1
    _check_facades(t, BIM_FACADES)
    inside_out = LabelledMesh(bim_mesh.vertices_m, bim_mesh.faces[:, ::-1], bim_mesh.face_label,
                              bim_mesh.face_facade)
    write_labelled_ply(tmp_path / "inv.ply", inside_out)
    t = import_labelled_mesh(tmp_path / "inv.ply").truth
    assert t.extra["bodies"]["turned_inside_out"] >= 1
    _check_facades(t, BIM_FACADES)


def _example_truth(tmp_path, bim_mesh):
    write_labelled_ply(tmp_path / "bim.ply", bim_mesh)
    return import_labelled_mesh(tmp_path / "bim.ply").truth


def test_missing_file_and_bad_config_are_refused(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        import_labelled_mesh(tmp_path / "nope.ply")
    (tmp_path / "m.stl").write_text("solid\n")
    with pytest.raises(ValueError, match="unsupported mesh format"):
        import_labelled_mesh(tmp_path / "m.stl")
    with pytest.raises(ValueError, match="min_escape_fraction"):
        ImportConfig(min_escape_fraction=0.0)
    with pytest.raises(ValueError, match="up_axis"):
        ImportConfig(up_axis="x")


def test_agrees_with_the_generators_exact_truth(tmp_path):
    # The benchmark's own L-shaped building, labels only: the importer re-derives its truth.
    recipe = next(r for r in preset_recipes("tiny") if r.family == "l_shaped")
    generated = build_building(recipe)
    m = generated.mesh
    write_labelled_ply(tmp_path / "g.ply", LabelledMesh(m.vertices_m, m.faces, m.face_label,
                                                        np.zeros(len(m.faces))))
    t = import_labelled_mesh(tmp_path / "g.ply", config=ImportConfig(recentre=False)).truth
    g = generated.truth
    assert len(t.facades) == len(g.facades) == 6
    for key in ("window_area_m2", "wall_area_m2", "door_area_m2", "facade_area_m2"):
        assert getattr(t, key) == pytest.approx(getattr(g, key), rel=REL)
    for f in g.facades:  # match facades by outward normal and width
        mine = max(t.facades, key=lambda h: np.dot(h.normal, f.normal) - abs(h.width_m - f.width_m))
        assert mine.window_area_m2 == pytest.approx(f.window_area_m2, rel=REL, abs=1e-9)
        assert mine.facade_area_m2 == pytest.approx(f.facade_area_m2, rel=REL)
    assert _iou(geojson_to_polygon(t.footprint), geojson_to_polygon(g.footprint)) >= 0.999


def _two_boxes(tmp_path, a, b):
    """The truth of two boxes (bounds ``a``, ``b``), all wall, imported as one PLY."""
    both = trimesh.util.concatenate([trimesh.creation.box(bounds=a),
                                     trimesh.creation.box(bounds=b)])
    n = len(both.faces)
    write_labelled_ply(tmp_path / "two.ply", LabelledMesh(
        both.vertices, both.faces, np.full(n, WALL), np.zeros(n, dtype=np.int32)))
    return import_labelled_mesh(tmp_path / "two.ply").truth


def test_overlapping_boxes_give_the_union_footprint(tmp_path):
    # Two closed boxes that overlap, one mesh without repairs: inside is their union.
    t = _two_boxes(tmp_path, [[0, 0, 0], [10, 8, 6]], [[6, 4, 0], [14, 10, 4]])
    union = Polygon([(0, 0), (10, 0), (10, 4), (14, 4), (14, 10), (6, 10), (6, 8), (0, 8)])
    assert t.footprint_area_m2 == pytest.approx(union.area, rel=1e-9)  # 80 + 48 - 16
    shift = np.asarray(t.extra["offset_m"][:2])
    fp = geojson_to_polygon(t.footprint)
    fp = Polygon(np.asarray(fp.exterior.coords) - shift)
    assert _iou(fp, union) >= 0.999


def test_overlapping_boxes_are_clipped_where_they_pass_into_each_other(tmp_path):
    # A = [0, 10] x [0, 8] x [0, 6] and B = [4, 12] x [4, 10] x [0, 6], one mesh, no
    # repairs: A's east and north faces pass into B, B's south and west faces into A.
    # Union footprint 80 + 48 - 24 = 104 m²; its outline is a staircase whose perimeter is
    # the bounding box's, 2 (12 + 10) = 44 m, so the facade is 44 x 6 = 264 m² (kept or
    # dropped whole, the faces partly inside the other box gave 312 m² before).
    t = _two_boxes(tmp_path, [[0, 0, 0], [10, 8, 6]], [[4, 4, 0], [12, 10, 6]])
    assert t.footprint_area_m2 == pytest.approx(104.0, rel=0.01)
    assert t.facade_area_m2 == pytest.approx(264.0, rel=0.01)
    assert sorted(round(f.width_m, 6) for f in t.facades) == [2, 2, 4, 4, 6, 8, 8, 10]


def test_ground_level_cuts_faces_and_nothing_below_counts(tmp_path, bim_mesh):
    # The example building with its ground 1.2 m up: the lowest 1.2 m is underground.
    write_labelled_ply(tmp_path / "bim.ply", bim_mesh)
    t = import_labelled_mesh(tmp_path / "bim.ply", config=ImportConfig(ground_z_m=1.2)).truth
    assert t.facade_area_m2 == pytest.approx(2 * (12 + 8) * (6.3 - 1.2), rel=REL)
    assert t.door_area_m2 == pytest.approx(1.0 * (2.4 - 1.2), rel=REL)  # door: z 0.3 to 2.4
    assert t.height_m == pytest.approx(6.3 - 1.2, rel=REL)
    assert t.extra["below_grade_area_m2"]["door"] > 0.0
    assert t.footprint_area_m2 == pytest.approx(96.0, rel=REL)


def test_generate_mesh_takes_every_import_option(tmp_path):
    from dataclasses import fields

    from dataset.generate import _parse_args
    from dataset.source_args import import_config_from_args

    args = _parse_args(["--mesh", "m.ply", "--out", str(tmp_path), "--ground-z", "0.5",
                        "--up-axis", "y", "--footprint-height-m", "0.2", "--keep-position",
                        "--rays-per-sample", "8", "--min-facade-width-m", "0.7"])
    config = import_config_from_args(args)
    assert (config.ground_z_m, config.up_axis, config.footprint_height_m, config.recentre,
            config.rays_per_sample, config.min_facade_width_m) == (0.5, "y", 0.2, False, 8, 0.7)
    defaults = import_config_from_args(_parse_args(["--mesh", "m.ply", "--out", str(tmp_path)]))
    assert defaults == ImportConfig()
    assert all(hasattr(defaults, f.name) for f in fields(ImportConfig))
