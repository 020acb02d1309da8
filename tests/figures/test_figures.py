"""figures.make on ready-made inputs: every figure it can, clear skips for missing inputs."""

import contextlib
import io
import json

import numpy as np
import pytest
import trimesh
from metrics_helpers import make_benchmark

from envelope.camera import Intrinsics, look_at
from envelope.mesh import LabelledMesh, write_labelled_ply
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import write_depth_m, write_labels, write_normals, write_rgb
from envelope.scenes.scene import write_transforms
from envelope.semantic_ply import write_semantic_ply
from figures.make import main
from figures.meshes import face_labels_from_vertices, render_mesh_views
from metrics.compare import main as compare_main

pytestmark = pytest.mark.slow  # every test here makes figures from a tiny comparison

ALL_FIGURES = ("table1_dataset", "dataset_renders", "2dss_pipeline", "neural3d_meshes",
               "footprint_overlays", "errors_by_family", "wwr_scatter", "iou_per_building")
SIZE = 24  # px: small frames keep the test fast


def _add_frame(scene_dir):
    """One 24 px orbit frame with every modality: left half wall, right half window."""
    labels = np.ones((SIZE, SIZE), np.uint8)
    labels[:, SIZE // 2:] = 2
    labels[:4] = 0
    write_rgb(scene_dir / "images/0.png", np.full((SIZE, SIZE, 3), 90, np.uint8))
    write_labels(scene_dir / "semantics/0.png", labels)
    normals = np.zeros((SIZE, SIZE, 3), np.float32)
    normals[4:, :, 1] = -1.0
    write_normals(scene_dir / "normals/0.png", normals)
    write_depth_m(scene_dir / "depth/0.png", np.where(labels > 0, 12.5, 0.0), 0.001)
    frame = Frame("images/0.png", look_at([0, -20, 5], [0, 0, 3]),
                  Intrinsics.from_fov(SIZE, SIZE, 60), "eval", None, "depth/0.png",
                  "semantics/0.png", "normals/0.png")
    write_transforms(scene_dir, Scene(scene_dir, (frame,)))


def _box_mesh(size=(10.0, 10.0, 6.0)):
    box = trimesh.creation.box(size)
    box.apply_translation([5.0, 5.0, 3.0])
    return np.asarray(box.vertices), np.asarray(box.faces)


@pytest.fixture(scope="module")
def ready_made(tmp_path_factory):
    """A compared hand-made benchmark plus images, 2D-SS debug images and one neural3d mesh."""
    root = tmp_path_factory.mktemp("figures")
    data, results = make_benchmark(root)
    out = root / "compare"
    with contextlib.redirect_stdout(io.StringIO()):
        assert compare_main(["--data", str(data), "--results", str(results), "--out", str(out),
                             "--views", "ideal,train", "--no-run"]) == 0
    _add_frame(data / "sky_a")
    for kind, shape in (("mask", (20, 30, 3)), ("corners", (20, 30, 3)),
                        ("rectified", (16, 24, 3))):
        write_rgb(out / "2dss_pipeline" / f"sky_a__ideal__f1__v0__{kind}.png",
                  np.full(shape, 128, np.uint8))
    vertices, faces = _box_mesh()
    labels = np.where(vertices[:, 2] > 5.0, 3, 1).astype(np.uint8)  # roof on top, wall below
    run_dir = results / "neural3d_runs" / "sky_a"
    write_semantic_ply(run_dir / "mesh.ply", vertices, faces, labels,
                       np.full((len(vertices), 3), 100, np.uint8))
    write_labelled_ply(data / "sky_a" / "mesh.ply",
                       LabelledMesh(vertices, faces, np.ones(len(faces)), np.ones(len(faces))))
    (out / "neural3d_runs.json").write_text(json.dumps(
        {"runs": [{"scene": "sky_a", "mesh": str(run_dir / "mesh.ply")}]}))
    return data, out


@pytest.fixture(scope="module")
def figures_made(ready_made, tmp_path_factory):
    """Run the CLI once on the ready-made inputs; returns (figures folder, stdout, stderr)."""
    _, compare_out = ready_made
    out = tmp_path_factory.mktemp("figs")
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        assert main(["--results", str(compare_out), "--out", str(out)]) == 0
    return out, stdout.getvalue(), stderr.getvalue()


@pytest.mark.slow
def test_every_figure_is_made_from_ready_made_inputs(figures_made):
    out, stdout, stderr = figures_made
    assert "skipped" not in stderr
    for name in ALL_FIGURES:
        assert f"made {name}:" in stdout
    for name in ALL_FIGURES[1:]:
        for ext in ("png", "pdf"):
            assert (out / f"{name}.{ext}").stat().st_size > 1000, name
    prov = json.loads((out / "figures_provenance.json").read_text())
    assert prov["code_version"] and set(prov["figures"]) == set(ALL_FIGURES)


def test_table1_uses_the_data_recorded_by_compare(figures_made):
    out, _, _ = figures_made
    t1 = (out / "table1_dataset.md").read_text()
    assert "| skyscraper | 2 | 1 | 2 | 100 | 6.0 | 0.25 |" in t1  # sky_a has one image
    assert "| all | 3 | 1 | 2 | 100 | 6.0 | 0.25 |" in t1
    assert (out / "table1_dataset.tex").read_text().startswith("% produced by")


@pytest.mark.slow
def test_missing_inputs_are_skipped_with_a_message(tmp_path, capsys):
    data, results = make_benchmark(tmp_path)
    out = tmp_path / "compare"
    with contextlib.redirect_stdout(io.StringIO()):
        compare_main(["--data", str(data), "--results", str(results), "--out", str(out),
                      "--methods", "2D-S", "--views", "ideal", "--no-run"])
    assert main(["--results", str(out), "--data", str(data), "--out", str(tmp_path / "f")]) == 0
    err = capsys.readouterr().err
    assert "skipped dataset_renders: no scene with images" in err
    assert "skipped 2dss_pipeline: no 2D-SS debug images" in err
    assert "skipped neural3d_meshes: no reconstructed mesh yet" in err
    assert "skipped footprint_overlays: no estimated footprint" in err
    assert "skipped iou_per_building: no footprint IoU to plot" in err
    assert (tmp_path / "f" / "errors_by_family.png").is_file()
    assert (tmp_path / "f" / "wwr_scatter.pdf").is_file()


def test_no_comparison_folder_is_an_error(tmp_path, capsys):
    assert main(["--results", str(tmp_path / "nope")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: comparison folder") and err.count("\n") == 1
    assert main(["--results", str(tmp_path), "--data", str(tmp_path / "x")]) == 2
    assert "data folder" in capsys.readouterr().err


def test_face_labels_take_the_majority_vertex_label():
    faces = np.array([[0, 1, 2], [1, 2, 3], [0, 2, 3]])
    labels = np.array([1, 2, 2, 3])
    assert face_labels_from_vertices(faces, labels).tolist() == [2, 2, 1]


def test_mesh_views_show_the_mesh_centred():
    vertices, faces = _box_mesh()
    images = render_mesh_views(LabelledMesh(vertices, faces, np.full(len(faces), 2),
                                            np.zeros(len(faces))))
    assert len(images) == 3
    for img in images:
        assert img.shape == (256, 256, 3) and img.dtype == np.uint8
        covered = (img != 255).any(axis=-1)
        assert covered[128, 128] and not covered[0, 0]  # building in the middle, sky in the corner
        assert 0.05 < covered.mean() < 0.8


def test_table1_ranges_per_family(tmp_path):
    from dataclasses import replace

    from metrics_helpers import make_truth

    from figures.dataset_table import table1_dataset

    truths = [
        (tmp_path / "a", replace(make_truth("a"), floors=9, height_m=27.0, wwr=0.15,
                                 footprint_area_m2=27.4)),
        (tmp_path / "b", replace(make_truth("b"), floors=22, height_m=46.0, wwr=0.41,
                                 footprint_area_m2=80.0)),
        (tmp_path / "c", replace(make_truth("c", "realistic"), floors=3)),
    ]
    rows = {r[0]: r for r in table1_dataset(truths).rows}
    assert rows["skyscraper"] == ("skyscraper", 2, 0, "9–22", "27–80", "27.0–46.0", "0.15–0.41")
    assert rows["realistic"] == ("realistic", 1, 0, "3", "100", "6.0", "0.25")
    assert rows["all"][1:4] == (3, 0, "3–22")


def test_display_encodings():
    from figures.style import CLASS_RGB_ARRAY, colour_depth, colour_labels, colour_normals

    labels = np.array([[0, 2], [5, 200]], np.uint8)
    rgb = colour_labels(labels)
    assert rgb[0, 1].tolist() == CLASS_RGB_ARRAY[2].tolist() and rgb[1, 1].tolist() == [255, 0, 255]
    normals = np.array([[[0, 0, 0], [1, 0, 0]]], np.float32)
    assert colour_normals(normals).tolist() == [[[0, 0, 0], [255, 128, 128]]]
    depth = colour_depth(np.array([[0.0, 5.0, 10.0]]))
    assert depth[0, 0].tolist() == [255, 255, 255]
    assert depth[0, 1].sum() > depth[0, 2].sum()  # near is brighter than far
