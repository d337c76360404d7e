#!/usr/bin/env bash
# On a machine with a real GPU (issue 14): samples/s of every sampler at 2^28 samples per run
# (sampling + histogram, GPU timestamps, median of 5), then the main job judged on that GPU.
# Usage: bash bench/device.sh [SAMPLES]   (OUT=DIR, default out/device; LOBES=path to a built binary)
# It refuses a software adapter (llvmpipe, WARP, SwiftShader) unless ALLOW_SOFTWARE=1: its numbers
# are those of a CPU, which `lobes bench` and bench/mitsuba_compare.py already measure.
set -euo pipefail
cd "$(dirname "$0")/.."
SAMPLES=${1:-268435456}
OUT=${OUT:-out/device}
LOBES=${LOBES:-target/release/lobes}
[ -x "$LOBES" ] || cargo build --release
mkdir -p "$OUT"
"$LOBES" bench --gpu-only --samples "$SAMPLES" --runs 5 | tee "$OUT/bench.txt"
adapter=$(head -n 1 "$OUT/bench.txt")
if [[ "${ALLOW_SOFTWARE:-0}" != 1 ]] && grep -qiE 'llvmpipe|lavapipe|warp|swiftshader' <<<"$adapter"; then
    echo "bench/device.sh: $adapter is a software adapter; set ALLOW_SOFTWARE=1 to measure it anyway" >&2
    exit 3
fi
# The main job on this GPU: every case must pass its χ² test here too (exit 1 otherwise).
"$LOBES" run --out "$OUT/run" | tail -n 20
