#!/usr/bin/env bash
# neural3d's GPU figures in one pass, sized for a lent GPU machine's few minutes.
#
#   bash bench/neural3d_gpu_check.sh OUT [DATA_PRESET=heldout] [DEVICE=cuda]
#
# In order, each stage's log under OUT/ and its start and end in OUT/stages.log:
#  1. renders DATA_PRESET into data/DATA_PRESET on every core, with the CUDA tests
#     (tests/neural3d/test_neural3d_cuda.py) run meanwhile;
#  2. latency: the first scene trained and measured alone (the local executor; `fast`
#     preset, STEPS steps, marching cubes at 128, one torch thread: the held-out table's
#     budget);
#  3. profile: one `fast` step on DEVICE broken into its parts (bench/neural3d_profile.py
#     parts), and steps of 512 rays against 2048 rays and against finite-difference
#     normals (profile ab);
#  4. throughput: every scene at that budget, JOBS at once (bench/neural3d_gpu_table.sh:
#     the processes executor under CUDA MPS), the GPU's use sampled every 2 s into
#     OUT/gpu_use.csv;
# and packs the results (JSON, tables, not the trained fields) and OUT into data/gpu-check.tgz
# after stages 3 and 4; `metrics.compare --no-run --data data/DATA_PRESET --results ...`
# tables them on any machine. Results go to data/gpu-check/. From the environment: STEPS
# (2000), JOBS (10), WARMUP (the profile's untimed steps, 150). DEVICE=cpu DATA_PRESET=tiny
# STEPS=40 JOBS=2 WARMUP=5 tries it out on a CPU.
set -uo pipefail
[ $# -ge 1 ] || { sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
out=$1 preset=${2:-heldout} device=${3:-cuda}
steps=${STEPS:-2000} jobs=${JOBS:-10} warmup=${WARMUP:-150} work=data/gpu-check
data=data/$preset
mkdir -p "$out" "$work"
stage() { echo "$(date +%T) +${SECONDS}s $*" | tee -a "$out/stages.log"; }
pack() {  # one archive of the results and the logs: data/gpu-check.tgz
  tar czf "$work.tgz" --exclude='*.pt' --exclude='*.ply' --exclude='*.npz' --exclude='*.html' \
    "$work" "$out"
}
export PYTHONUNBUFFERED=1
[ "$device" = cpu ] || nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv \
  > "$out/gpu.csv" 2>&1

stage "render $preset"
python -m dataset.generate --preset "$preset" --out "$data" --workers "$(nproc)" --quiet \
  > "$out/generate.log" 2>&1 &
gen=$!
if [ "$device" != cpu ]; then
  stage "cuda tests"
  timeout 240 python -m pytest -q -p no:cacheprovider tests/neural3d/test_neural3d_cuda.py \
    > "$out/cuda_tests.log" 2>&1
  stage "cuda tests exit $?"
fi
wait $gen
stage "render exit $?"

first=$(ls "$data" | head -1)
scene=$data/$first
stage "alone $first"
timeout 180 python -m metrics.compare --data "$scene" --methods neural3d --device "$device" \
  --neural3d-steps "$steps" --neural3d-threads 1 --neural3d-resolution 128 --executor local \
  --results "$work/results-alone" --out "$work/compare-alone" > "$out/alone.log" 2>&1
stage "alone exit $?"

stage "profile"
timeout 90 python bench/neural3d_profile.py parts --scene "$scene" --device "$device" \
  --threads 1 --warmup "$warmup" --json "$out/profile_parts.json" > "$out/profile_parts.log" 2>&1
timeout 120 python bench/neural3d_profile.py ab --scene "$scene" --device "$device" --threads 1 \
  --warmup "$warmup" --variant 'base:' --variant 'r2048:rays_per_batch=2048' \
  --variant 'fd:model.normals=finite_difference' \
  --json "$out/profile_ab.json" > "$out/profile_ab.log" 2>&1
stage "profile exit $?"
pack

stage "throughput"
smi=
if [ "$device" != cpu ]; then
  nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used --format=csv -l 2 \
    > "$out/gpu_use.csv" 2>/dev/null &
  smi=$!
fi
timeout 300 bash bench/neural3d_gpu_table.sh "$data" "$work/results-street" \
  "$work/compare-street" "$jobs" "$steps" "$device" --neural3d-threads 1 \
  --neural3d-resolution 128 > "$out/street.log" 2>&1
stage "throughput exit $?"
[ -z "$smi" ] || kill "$smi"
pack
stage "packed $(du -h "$work.tgz" | cut -f1)"
