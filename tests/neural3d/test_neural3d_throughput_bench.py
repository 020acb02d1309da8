"""bench/neural3d_throughput.py: its two arms per device, the figures it reads from a
comparison's per_building.csv (failed rows left out) and its table's closed-form ratios."""

import importlib.util
import sys

from paths import REPO_ROOT

spec = importlib.util.spec_from_file_location(
    "neural3d_throughput", REPO_ROOT / "bench" / "neural3d_throughput.py")
bench = importlib.util.module_from_spec(spec)
sys.modules[spec.name] = bench  # its dataclasses look their module up there
spec.loader.exec_module(bench)


def test_the_arms_split_cores_on_cpu_and_the_gpu_on_cuda():
    local, at_once = bench.arms(2, "cpu")
    assert local.options == ("--executor", "local", "--neural3d-threads", "2")
    assert at_once.options == ("--executor", "processes", "--neural3d-threads", "1",
                               "--cpus", "2")
    local, at_once = bench.arms(8, "cuda")
    assert local.options == ("--executor", "local")
    assert at_once.options == ("--executor", "processes", "--neural3d-runs-per-gpu", "8")


def test_figures_and_table(tmp_path):
    csv_path = tmp_path / "per_building.csv"
    csv_path.write_text(
        "# produced by `python -m metrics.compare`\n"
        "scene,status,wwr_ape,footprint_iou\n"
        "a,ok,1.0,0.97\n"
        "b,ok,3.0,0.99\n"
        "c,failed,,\n")
    first = bench.read_figures(csv_path, wall_s=360.0)
    assert first == bench.ArmFigures(360.0, 2, 2.0, 0.98)
    second = bench.ArmFigures(240.0, 2, 2.5, 0.97)
    text = bench.table([(bench.Arm("one after the other", ()), first),
                        (bench.Arm("2 at once", ()), second)])
    rows = text.splitlines()[2:]
    assert rows[0] == "| one after the other | 2 | 360 | 180 | 20.0 | 1.00x | 2.00 | 0.980 |"
    assert rows[1] == "| 2 at once | 2 | 240 | 120 | 30.0 | 1.50x | 2.50 | 0.970 |"
