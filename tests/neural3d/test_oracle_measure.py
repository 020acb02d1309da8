"""neural3d.extraction.oracle: the truth mesh as a perfect field (exact signed distance, inside
as the union of closed bodies, one-hot classes of the nearest face), and bench/oracle_measure.py
(run as its command) measuring on it."""

import json
import subprocess
import sys

import numpy as np
import pytest
import torch
import trimesh
from paths import REPO_ROOT

from envelope.classes import NUM_CLASSES, SemanticClass
from envelope.mesh import LabelledMesh
from neural3d.extraction.oracle import OracleField, scene_box_m

WALL, ROOF = int(SemanticClass.WALL), int(SemanticClass.ROOF)
VOXEL_M = 0.1


def _boxes(*boxes):
    """A LabelledMesh of closed boxes ((size, centre) each): sides wall, top and bottom roof."""
    parts = []
    for size, centre in boxes:
        box = trimesh.creation.box(size)
        box.apply_translation(centre)
        parts.append(box)
    mesh = trimesh.util.concatenate(parts)
    label = np.where(np.abs(mesh.face_normals[:, 2]) > 0.5, ROOF, WALL)
    return LabelledMesh(mesh.vertices, mesh.faces, label, np.zeros(len(label)))


def _field(mesh):
    lo, hi = scene_box_m(mesh, 0.1)
    return OracleField(mesh, "boxes", voxel_m=VOXEL_M, box_min_m=lo, box_max_m=hi)


def _box_sdf(p, size, centre):
    q = np.abs(p - centre) - np.asarray(size) / 2
    return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)


def test_the_distance_is_exact_near_the_surface_and_clipped_beyond():
    size, centre = (4.0, 3.0, 2.0), (0.0, 0.0, 1.0)
    field = _field(_boxes((size, centre)))
    p = np.random.default_rng(0).uniform([-3, -3, -1], [3, 3, 3], (4000, 3))
    exact = _box_sdf(p, size, centre)
    got = field.sdf(p)
    band = np.abs(exact) < field.band_m - 1e-9
    assert band.sum() > 100 and (~band).sum() > 100
    np.testing.assert_array_equal(np.sign(got[band]), np.sign(exact[band]))
    # exact but where the nearest samples miss the nearest face (near an edge): then the
    # distance to another face, longer by less than the samples' spacing
    excess = np.abs(got[band]) - np.abs(exact[band])
    assert excess.min() > -1e-9 and excess.max() < VOXEL_M / 3
    assert (excess < 1e-9).mean() > 0.99
    np.testing.assert_allclose(got[~band], np.sign(exact[~band]) * field.band_m)
    assert field.sdf(p) is got  # asked again: the same answer, not computed again


def test_inside_is_the_union_of_overlapping_bodies():
    # a chimney through a roof: ray parity over the whole mesh counts the overlap twice
    # (outside); the oracle, like the project's winding-number rule, keeps it inside
    mesh = _boxes(((4.0, 4.0, 2.0), (0, 0, 1.0)), ((1.0, 1.0, 2.0), (1.0, 1.0, 2.0)))
    overlap = np.array([[1.0, 1.0, 1.5], [1.2, 0.8, 1.9]])
    outside = np.array([[1.0, 1.0, 3.5], [3.0, 0.0, 1.0]])
    field = _field(mesh)
    np.testing.assert_array_equal(field.contains(np.vstack([overlap, outside])),
                                  [True, True, False, False])
    assert (field.sdf(overlap) < 0).all()
    whole = trimesh.Trimesh(mesh.vertices_m, mesh.faces)
    assert not whole.contains(overlap).any()  # what the oracle no longer does


def test_the_field_interface_gives_one_hot_classes_of_the_nearest_face():
    field = _field(_boxes(((4.0, 4.0, 2.0), (0, 0, 1.0))))
    p = torch.tensor([[2.01, 0.0, 1.0], [0.0, 0.0, 2.02], [-1.0, 1.99, 0.5]])
    logits = field.semantic_logits(p)
    probabilities = torch.softmax(logits.double(), dim=1).numpy()
    assert probabilities.shape == (3, NUM_CLASSES)
    np.testing.assert_array_equal(probabilities.argmax(axis=1), [WALL, ROOF, WALL])
    np.testing.assert_array_equal(probabilities.max(axis=1), 1.0)  # exactly one-hot
    np.testing.assert_allclose(field.sdf_m(p).numpy(), [0.01, 0.02, -0.01], atol=1e-6)


def test_a_body_that_is_not_closed_is_refused():
    box = trimesh.creation.box([2.0, 2.0, 2.0])
    open_box = LabelledMesh(box.vertices, box.faces[1:], np.full(11, WALL), np.zeros(11))
    with pytest.raises(ValueError, match="not closed"):
        _field(open_box)


def _bench(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "bench.oracle_measure", *args], cwd=REPO_ROOT,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_the_bench_prints_and_writes_bias_and_error_per_stage_set(tmp_path):
    out = tmp_path / "oracle.json"
    done = _bench("--preset", "tiny", "--buildings", "tiny_skyscraper", "--resolution", "40",
                  "--without", "concave_corner_fill", "--json", str(out))
    assert done.returncode == 0, done.stderr
    assert "| stages | family (buildings) | WWR bias % | WWR APE % |" in done.stdout
    assert "| -concave_corner_fill | tiny_skyscraper |" in done.stdout
    (building,) = json.loads(out.read_text())["buildings"]
    assert set(building["sets"]) == {"all", "-concave_corner_fill"}
    truth = building["truth"]
    for entry in building["sets"].values():
        result, bias, errors = entry["result"], entry["bias"], entry["errors"]
        assert bias["wwr"] == pytest.approx(100 * (result["wwr"] / truth["wwr"] - 1))
        assert abs(bias["facade"]) == pytest.approx(errors["facade_ape"])
        assert abs(bias["facade"]) < 10 and errors["footprint_iou"] > 0.9  # 0.9 m voxels
    refused = _bench("--preset", "tiny", "--buildings", "nowhere")
    assert refused.returncode == 2 and "no building(s) ['nowhere']" in refused.stderr
