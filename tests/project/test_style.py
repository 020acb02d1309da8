"""The code passes ruff (the project's lint configuration in pyproject.toml)."""

import importlib.util
import subprocess
import sys

import pytest
from paths import REPO_ROOT

ROOT = REPO_ROOT


def test_ruff_clean():
    # The ruff of the running Python, whatever the PATH says.
    if importlib.util.find_spec("ruff") is None:
        pytest.fail(f"ruff is not installed for {sys.executable}: run `bash scripts/setup.sh`")
    out = subprocess.run(
        [sys.executable, "-m", "ruff", "check", "."], cwd=ROOT, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stdout + out.stderr
