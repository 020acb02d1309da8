#!/usr/bin/env bash
# Installs everything envelope-bench needs into the current Python environment.
# Idempotent: a second run installs nothing. The CPU build of PyTorch goes in first,
# because an unpinned `torch` requirement would pull several GB of CUDA packages.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
export PIP_ROOT_USER_ACTION=ignore PIP_DISABLE_PIP_VERSION_CHECK=1
if ! "$PY" -c "import torch" >/dev/null 2>&1; then
    echo "setup: installing the CPU build of PyTorch (torch==2.13.0)"
    "$PY" -m pip install --quiet torch==2.13.0
fi
# The HTML report's browser test drives Debian's chromium (Playwright cannot download its own).
if ! command -v chromium >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "setup: installing chromium (apt-get) for the report's browser test"
        apt-get update -qq && apt-get install -y -qq chromium >/dev/null
    else
        echo "setup: chromium is missing; install Debian's chromium for the report's browser test"
    fi
fi
# [cluster]: Ray (pinned), for `--executor ray` and its tests.
"$PY" -m pip install --quiet --disable-pip-version-check -e ".[test,cluster]"
"$PY" -c "import torch, trimesh, embreex, kornia, cv2, skimage, shapely, ray, ifcopenshell, plotly, playwright, cjio, lxml, pyproj, jsonschema, geomeppy, eppy" \
    || { echo "setup: a dependency failed to import; see the messages above" >&2; exit 1; }
echo "setup: done ($("$PY" -c 'import torch; print("torch", torch.__version__)'))"
