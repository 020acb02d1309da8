"""The one scene finder every command uses (envelope.scenes.scene.find_scene_folders)."""

import pytest

from envelope.scenes.scene import find_scene_folders


def _scene(folder, *files):
    folder.mkdir(parents=True)
    for name in files:
        (folder / name).write_text("{}")
    return folder


def test_a_folder_of_scene_folders_gives_its_scenes_sorted(tmp_path):
    data = tmp_path / "data"
    b = _scene(data / "b", "transforms.json", "building.json")
    a = _scene(data / "a", "transforms.json")
    truth_only = _scene(data / "c", "building.json")
    _scene(data / ".a.x1y2.partial", "transforms.json")  # a killed run's unfinished copy
    _scene(data / "notes")
    _scene(data / "group" / "deeper", "transforms.json")  # one level down only
    assert find_scene_folders(data) == [a, b, truth_only]
    assert find_scene_folders(data, with_images=True) == [a, b]


def test_a_scene_folder_given_directly_is_the_one_scene(tmp_path):
    scene = _scene(tmp_path / "data" / "a", "transforms.json")
    _scene(scene / "images")
    assert find_scene_folders(scene) == [scene]
    assert find_scene_folders(scene, with_images=True) == [scene]
    truth_only = _scene(tmp_path / "truth", "building.json")
    assert find_scene_folders(truth_only) == [truth_only]


def test_a_folder_without_scenes_is_refused_with_what_a_scene_needs(tmp_path):
    _scene(tmp_path / "empty" / "notes")
    with pytest.raises(ValueError, match=r"holds no scene folder \(one with transforms.json or "
                                         r"building.json\).*dataset.generate"):
        find_scene_folders(tmp_path / "empty")
    truths = _scene(tmp_path / "truths" / "a", "building.json").parent
    with pytest.raises(ValueError, match=r"holds no scene folder \(one with transforms.json\)"):
        find_scene_folders(truths, with_images=True)
    with pytest.raises(ValueError, match="does not exist"):
        find_scene_folders(tmp_path / "nowhere")
