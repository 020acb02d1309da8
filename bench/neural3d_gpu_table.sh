#!/usr/bin/env bash
# neural3d's rows of a benchmark on one GPU, several buildings at once.
#
#   bash bench/neural3d_gpu_table.sh DATA RESULTS OUT [JOBS] [STEPS] [DEVICE]
#
# DATA: a folder of scene folders (e.g. data/paper); RESULTS, OUT: metrics.compare's
# --results and --out; JOBS: buildings trained at once (default 8); STEPS: the step
# budget (default 3000); DEVICE: cuda (default; cpu to try the script out). Each building
# is one `python -m metrics.compare --data DATA/<scene> --methods neural3d --device DEVICE`
# into the shared RESULTS folder (a finished result is reused, as always); then one
# `--no-run` comparison over DATA writes the tables into OUT.
#
# One fast-preset training step is a few hundred small kernels, so one process keeps an
# H100 mostly idle; with the CUDA Multi-Process Service (started here when the machine has
# it) 8 processes shared one H100 at 37-46 it/s each (docs/neural3d.md, "On a GPU").
# Per-building logs go to OUT/logs/, start and wall seconds to OUT/logs/times.txt.
set -uo pipefail
if [ $# -lt 3 ]; then
  sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
data=$1 results=$2 out=$3 jobs=${4:-8} steps=${5:-3000} device=${6:-cuda}
[ -d "$data" ] || { echo "error: $data is not a folder of scene folders" >&2; exit 2; }
mkdir -p "$out/logs"
mps=0
if command -v nvidia-cuda-mps-control >/dev/null && nvidia-cuda-mps-control -d 2>/dev/null; then
  mps=1
  echo "CUDA MPS daemon started"
fi
stop_mps() { [ "$mps" = 1 ] && echo quit | nvidia-cuda-mps-control; }
trap 'kill $(jobs -p) 2>/dev/null; stop_mps' INT TERM
t0=$(date +%s)
for scene in "$data"/*/; do
  scene=${scene%/}
  [ -f "$scene/transforms.json" ] || continue
  name=$(basename "$scene")
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
  (
    a=$(date +%s)
    python3 -m metrics.compare --data "$scene" --methods neural3d --device "$device" \
      --neural3d-steps "$steps" --results "$results" --out "$out/logs/$name" \
      > "$out/logs/$name.log" 2>&1
    echo "$name rc=$? start $((a - t0)) s wall $(($(date +%s) - a)) s" >> "$out/logs/times.txt"
  ) &
  echo "[$(($(date +%s) - t0)) s] started $name"
done
wait
stop_mps
python3 -m metrics.compare --data "$data" --methods neural3d --device "$device" \
  --neural3d-steps "$steps" --results "$results" --out "$out" --no-run
