"""A method that runs on none of a comparison's protocols (``--views`` names none it
declares) is listed and left alone: the comparison of the others finishes, and its
pipeline images are not asked for (they need a protocol)."""

from __future__ import annotations

import shutil
from dataclasses import replace

import pytest

from metrics.comparison import PIPELINE_FOLDER, compare
from metrics.run.methods import method_specs


@pytest.mark.slow  # one comparison of 2D-S on the box's ideal views (about 3 s)
def test_a_method_with_no_protocol_here_does_not_stop_the_comparison(clean_scene, tmp_path):
    shutil.copytree(clean_scene, tmp_path / "data" / "box")
    two_d_s, two_d_ss = method_specs(("2D-S", "2D-SS"), ("ideal",), tmp_path / "results")
    idle = replace(two_d_ss, protocols=())
    assert idle.debug_images is not None
    comparison = compare(tmp_path / "data", [two_d_s, idle], tmp_path / "results",
                         tmp_path / "out")
    assert [(o.method, o.protocol, o.status) for o in comparison.outcomes] == [
        ("2D-S", "ideal", "ran")]
    assert not any((tmp_path / "out" / PIPELINE_FOLDER).glob("*.png"))
