#!/usr/bin/env bash
# Installs everything envelope-bench needs into the current Python environment.
# Idempotent: a second run installs nothing (torch is left alone when it imports).
# PyTorch goes in first, because `torch` from the default index is, on Linux, the CUDA
# build (several GB): the CPU wheel index is asked first, with a short timeout and no retry,
# and the default index only if it does not answer.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
TORCH=torch==2.13.0
CPU_INDEX=https://download.pytorch.org/whl/cpu
export PIP_ROOT_USER_ACTION=ignore PIP_DISABLE_PIP_VERSION_CHECK=1
if ! "$PY" -c "import torch" >/dev/null 2>&1; then
    echo "setup: installing $TORCH, the CPU build, from $CPU_INDEX"
    if ! "$PY" -m pip install --quiet --timeout 10 --retries 0 --index-url "$CPU_INDEX" "$TORCH"
    then
        echo "setup: $CPU_INDEX did not answer; installing $TORCH from the default index" \
             "(on Linux the CUDA build, several GB)"
        "$PY" -m pip install --quiet "$TORCH"
    fi
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
"$PY" -c "import torch, trimesh, embreex, kornia, cv2, skimage, shapely, ray, ifcopenshell, plotly, playwright, cjio, pycolmap, lxml, pyproj, jsonschema, geomeppy, eppy" \
    || { echo "setup: a dependency failed to import; see the messages above" >&2; exit 1; }
echo "setup: done ($("$PY" -c 'import torch; print("torch", torch.__version__, "CPU build" if torch.version.cuda is None else f"CUDA {torch.version.cuda} build")'))"
