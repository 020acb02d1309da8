"""Rendering a preset as Ray tasks (local Ray, 2 CPUs) writes the same scene folders as here."""

import os
import warnings

import pytest
from conftest import TINY_CONFIG

from dataset.generate import generate_preset
from envelope.executors.ray_tasks import LOCAL_ONLY_ENV, RayConfig

# Before Ray is first imported (it reads its settings then): no usage reports, loopback only.
os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
os.environ.setdefault(LOCAL_ONLY_ENV, "0")
ray = pytest.importorskip("ray", reason="the ray executor needs Ray (scripts/setup.sh)")


def _files(root):
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in root.rglob("*") if p.is_file()}


@pytest.mark.slow
def test_ray_renders_the_tiny_preset_byte_identical_to_the_local_run(tiny_benchmark, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        scenes = generate_preset("tiny", tmp_path, TINY_CONFIG, progress=False,
                                 ray=RayConfig(num_cpus=2))
    assert not ray.is_initialized()  # the session it started is closed again
    assert sorted(s.name for s in scenes) == sorted(p.name for p in tiny_benchmark.iterdir())
    assert _files(tmp_path) == _files(tiny_benchmark)
