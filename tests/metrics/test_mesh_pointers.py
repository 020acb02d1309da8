"""``<method>_runs.json``: a method's meshes found per scene and protocol, where
:func:`envelope.method.artefacts_folder` puts them."""

import json

from envelope.method import artefacts_folder
from metrics.run.mesh_pointers import MeshRun, read_mesh_pointers, write_mesh_pointers
from metrics.run.methods import spec_from_method
from neural3d.method import METHOD_NEURAL3D


def test_a_street_run_and_an_orbit_run_of_one_scene_are_both_found(tmp_path):
    spec = spec_from_method(METHOD_NEURAL3D, ("train", "street"), tmp_path / "results")
    assert spec.mesh_file is not None and spec.protocols == ("train", "street")
    scene_dirs = [tmp_path / "data" / "house", tmp_path / "data" / "shed"]
    made = {}
    for scene, protocol in (("house", "train"), ("house", "street"), ("shed", "street")):
        mesh = artefacts_folder(spec.artefacts_dir, scene, protocol) / spec.mesh_file
        mesh.parent.mkdir(parents=True, exist_ok=True)
        mesh.write_bytes(b"ply\n")
        made[scene, protocol] = mesh.resolve()
    assert made["house", "street"] != made["house", "train"]
    write_mesh_pointers(scene_dirs, spec, tmp_path / "out")
    found = read_mesh_pointers(tmp_path / "out")
    assert found == [MeshRun("neural3d", "house", "train", made["house", "train"]),
                     MeshRun("neural3d", "house", "street", made["house", "street"]),
                     MeshRun("neural3d", "shed", "street", made["shed", "street"])]


def test_only_the_protocols_the_comparison_ran_are_listed(tmp_path):
    """A street mesh left from an earlier comparison is not drawn in an orbit-only one."""
    spec = spec_from_method(METHOD_NEURAL3D, ("train",), tmp_path / "results")
    street = artefacts_folder(spec.artefacts_dir, "house", "street") / spec.mesh_file
    street.parent.mkdir(parents=True)
    street.write_bytes(b"ply\n")
    write_mesh_pointers([tmp_path / "data" / "house"], spec, tmp_path / "out")
    assert read_mesh_pointers(tmp_path / "out") == []


def test_a_pointer_file_without_protocols_reads_as_the_orbit(tmp_path):
    (tmp_path / "neural3d_runs.json").write_text(json.dumps(
        {"runs": [{"scene": "house", "mesh": "/x/mesh.ply"}]}))
    [run] = read_mesh_pointers(tmp_path)
    assert run.protocol == "train"
