"""scripts/setup.sh installs the CPU build of PyTorch when the CPU wheel index answers, falls
back to the default index when it does not, says which build went in, and leaves a torch that
imports alone. Run against a stand-in ``python`` that records its pip calls (no network, no
install): its torch is a module written on "install", imported with the site packages off."""

import os
import stat
import subprocess
import sys

import pytest
from paths import REPO_ROOT

CPU_INDEX = "https://download.pytorch.org/whl/cpu"

FAKE_PYTHON = """#!/usr/bin/env bash
# A stand-in python for scripts/setup.sh: records pip calls, and "installs" a torch module.
if [ "$1" = -m ] && [ "$2" = pip ]; then
    echo "pip ${*:3}" >> "$FAKE/calls"
    case " $* " in
        *" --index-url @CPU_INDEX@ "*)
            [ "$FAKE_CPU_INDEX" = up ] || exit 1
            build='"2.13.0+cpu", None' ;;
        *" torch==2.13.0 "*) build='"2.13.0", "12.8"' ;;
        *) exit 0 ;;
    esac
    mkdir -p "$FAKE/site/torch"
    printf 'import types\\n__version__, cuda = %s\\n' "$build" > "$FAKE/site/torch/__init__.py"
    echo 'version = types.SimpleNamespace(cuda=cuda)' >> "$FAKE/site/torch/__init__.py"
    exit 0
fi
case "$2" in  # the check that every dependency imports: only torch is faked here
    *trimesh*) [ -d "$FAKE/site/torch" ]; exit ;;
esac
PYTHONPATH="$FAKE/site" exec @PYTHON@ -S "$@"
""".replace("@CPU_INDEX@", CPU_INDEX).replace("@PYTHON@", sys.executable)


def run_setup(tmp_path, *, cpu_index: str, torch_present: bool) -> tuple[str, list[str]]:
    """Run scripts/setup.sh with the stand-in python; its output and the pip calls."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for name, text in (("python", FAKE_PYTHON), ("chromium", "#!/bin/sh\n")):
        (bin_dir / name).write_text(text)
        (bin_dir / name).chmod(stat.S_IRWXU)
    if torch_present:
        (tmp_path / "site" / "torch").mkdir(parents=True)
        (tmp_path / "site" / "torch" / "__init__.py").write_text(
            "import types\n__version__ = '2.13.0+cpu'\n"
            "version = types.SimpleNamespace(cuda=None)\n")
    env = {**os.environ, "PYTHON": str(bin_dir / "python"), "FAKE": str(tmp_path),
           "FAKE_CPU_INDEX": cpu_index, "PATH": f"{bin_dir}:{os.environ['PATH']}"}
    done = subprocess.run(["bash", str(REPO_ROOT / "scripts" / "setup.sh")], env=env,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    calls = tmp_path / "calls"
    return done.stdout, calls.read_text().splitlines() if calls.is_file() else []


def test_the_cpu_index_is_asked_first_with_a_short_timeout(tmp_path):
    out, calls = run_setup(tmp_path, cpu_index="up", torch_present=False)
    assert calls[0] == (f"pip install --quiet --timeout 10 --retries 0 --index-url {CPU_INDEX} "
                        "torch==2.13.0")
    assert len(calls) == 2 and calls[1].startswith("pip install --quiet")
    assert "-e .[test,cluster]" in calls[1]
    assert out.strip().endswith("setup: done (torch 2.13.0+cpu CPU build)")


def test_the_default_index_when_the_cpu_index_does_not_answer(tmp_path):
    out, calls = run_setup(tmp_path, cpu_index="down", torch_present=False)
    assert calls[1] == "pip install --quiet torch==2.13.0"
    assert "-e .[test,cluster]" in calls[2] and len(calls) == 3
    assert f"{CPU_INDEX} did not answer" in out
    assert out.strip().endswith("setup: done (torch 2.13.0 CUDA 12.8 build)")


@pytest.mark.parametrize("cpu_index", ["up", "down"])
def test_a_torch_that_imports_is_left_alone(tmp_path, cpu_index):
    out, calls = run_setup(tmp_path, cpu_index=cpu_index, torch_present=True)
    assert len(calls) == 1 and "-e .[test,cluster]" in calls[0]
    assert "installing torch" not in out
    assert out.strip().endswith("setup: done (torch 2.13.0+cpu CPU build)")
