#!/usr/bin/env bash
# neural3d's rows of a benchmark on one GPU, several buildings at once.
#
#   bash bench/neural3d_gpu_table.sh DATA RESULTS OUT [JOBS] [STEPS] [DEVICE] [ARGS...]
#
# DATA: a folder of scene folders (e.g. data/paper); RESULTS, OUT: metrics.compare's
# --results and --out; JOBS: buildings trained at once on the GPU (default 8); STEPS: the
# step budget (default 3000; `preset` for the preset's own); DEVICE: cuda (default; cpu to
# try the script out, JOBS then being the cores filled, one thread a building); ARGS: more
# options of metrics.compare (e.g. --neural3d-preset gpu). It is the normal path of the comparison:
# `python -m metrics.compare --data DATA --methods neural3d --device cuda
# --neural3d-runs-per-gpu JOBS`, whose `auto` executor trains JOBS buildings at once,
# each in its own process (docs/cluster.md), with the CUDA Multi-Process Service started
# around it when the machine has it (one fast-preset step is a few hundred small kernels,
# so one process keeps an H100 mostly idle; docs/neural3d.md, "On a GPU"). The command's
# log goes to OUT.log and its wall seconds to the last line of that log.
set -uo pipefail
if [ $# -lt 3 ]; then
  sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
data=$1 results=$2 out=$3 jobs=${4:-8} steps=${5:-3000} device=${6:-cuda}
shift $(($# < 6 ? $# : 6))
budget=()
[ "$steps" = preset ] || budget=(--neural3d-steps "$steps")
[ -d "$data" ] || { echo "error: $data is not a folder of scene folders" >&2; exit 2; }
mps=0
if [ "$device" != cpu ] && command -v nvidia-cuda-mps-control >/dev/null \
    && nvidia-cuda-mps-control -d 2>/dev/null; then
  mps=1
  echo "CUDA MPS daemon started"
fi
stop_mps() { if [ "$mps" = 1 ]; then echo quit | nvidia-cuda-mps-control; fi; }
trap stop_mps EXIT
if [ "$device" = cpu ]; then
  share=(--neural3d-threads 1 --cpus "$jobs")
else
  share=(--neural3d-runs-per-gpu "$jobs")
fi
t0=$(date +%s)
python3 -m metrics.compare --data "$data" --methods neural3d --device "$device" \
  "${budget[@]}" "${share[@]}" "$@" --results "$results" --out "$out" 2>&1 \
  | tee "$out.log"
rc=${PIPESTATUS[0]}
echo "wall $(($(date +%s) - t0)) s, exit code $rc" | tee -a "$out.log"
exit "$rc"
