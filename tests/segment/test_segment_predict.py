"""``python -m segment.predict``: mask copies of a folder of scenes, and its refusals."""

import shutil

import torch

from envelope.scenes.scene import read_scene
from segment.network import UNet, UNetConfig
from segment.predict import main
from segment.scene_masks import RECORD_KEY
from segment.weights import save_weights


def test_predict_copies_scenes_with_masks_and_refuses_bad_folders(clean_scene, tmp_path,
                                                                  capsys):
    torch.manual_seed(0)
    weights = tmp_path / "w.pt"
    save_weights(weights, UNet(UNetConfig(base_channels=4, levels=2)).eval(), {})
    data = tmp_path / "data"
    shutil.copytree(clean_scene, data / clean_scene.name)
    out = tmp_path / "masks"
    assert main(["--data", str(data), "--out", str(out), "--model", str(weights),
                 "--threads", "1"]) == 0
    copy = out / clean_scene.name
    assert capsys.readouterr().out.split() == [str(copy)]
    scene = read_scene(copy)
    assert RECORD_KEY in scene.extra and len(scene.frames) == len(
        read_scene(clean_scene).frames)
    assert main(["--data", str(data), "--out", str(data), "--model", str(weights)]) == 2
    assert "holds the scenes themselves" in capsys.readouterr().err
    assert main(["--data", str(tmp_path / "none"), "--out", str(out)]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert main(["--data", str(data), "--out", str(out), "--model", "nope"]) == 2
    assert "unknown segmenter 'nope'" in capsys.readouterr().err
