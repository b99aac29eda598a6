#!/usr/bin/env bash
# Our native generation against a PyTorch reference of the same shapes, in one run.
#
#   scripts/speed_reference.sh [ROUNDS]   (default 3 rounds of 5 timed generations each)
#
# Alternates `coma bench --train-steps 0` (the default model, burn's flex backend) with
# scripts/torch_reference.py (the same base transformer with random weights, the same
# generation loop) so both see the same machine load, then prints each side's median of the
# rounds' medians, their ratio, achieved GFLOP/s, and two ceilings: a large sgemm in torch and
# cores × clock × 32 FLOP per cycle (two 8-wide FMA pipes, as on this machine's AMD EPYC).
# Torch is installed in its own environment ($COMA_TORCH_VENV, default
# ~/.cache/coma-torch-venv), never for the tests. Both run on 2 threads.
set -euo pipefail
cd "$(dirname "$0")/.."
rounds="${1:-3}"
venv="${COMA_TORCH_VENV:-$HOME/.cache/coma-torch-venv}"
if ! "$venv/bin/python" -c "import torch, numpy" 2>/dev/null; then
    echo "installing torch 2.9.0 into $venv (a few minutes, once)" >&2
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q torch==2.9.0 numpy
fi
cargo build --release -p coma --quiet
target="${CARGO_TARGET_DIR:-target}"
coma="$target/release/coma"
export RAYON_NUM_THREADS=2
ours=()
theirs=()
peak=""
for round in $(seq "$rounds"); do
    ms=$("$coma" bench --train-steps 0 --repeat 5 | sed -n 's/^| base tokens, 196 frames (10 guided iterations), median of [0-9]* | \([0-9.]*\) ms |$/\1/p')
    [ -n "$ms" ] || { echo "coma bench printed no generation time" >&2; exit 1; }
    ours+=("$ms")
    args=(--repeat 5 --threads 2)
    [ "$round" = 1 ] && args+=(--peak)
    out=$("$venv/bin/python" scripts/torch_reference.py "${args[@]}" 2>/dev/null)
    theirs+=("$(echo "$out" | head -1 | python3 -c 'import json,sys;print(json.load(sys.stdin)["median_ms"])')")
    gflop=$(echo "$out" | head -1 | python3 -c 'import json,sys;print(json.load(sys.stdin)["gflop"])')
    [ "$round" = 1 ] && peak=$(echo "$out" | sed -n 2p | python3 -c 'import json,sys;print(json.load(sys.stdin)["sgemm_2048_gflops"])')
    echo "round $round: ours ${ours[-1]} ms, torch ${theirs[-1]} ms" >&2
done
python3 - "$gflop" "$peak" "${ours[*]}" "${theirs[*]}" <<'EOF'
import os, statistics, sys
gflop, peak = float(sys.argv[1]), float(sys.argv[2])
ours = [float(x) for x in sys.argv[3].split()]
theirs = [float(x) for x in sys.argv[4].split()]
mhz = max(float(l.split(":")[1]) for l in open("/proc/cpuinfo") if l.startswith("cpu MHz"))
ceiling = 2 * mhz / 1e3 * 32
o, t = statistics.median(ours), statistics.median(theirs)
print(f"base generation, 196 frames, 10 guided iterations, {gflop:.1f} GFLOP of matrix products, 2 threads")
print(f"  ours (coma bench, burn flex):   {o:7.1f} ms  {gflop / o * 1e3:6.1f} GFLOP/s  (rounds: {', '.join(f'{x:.0f}' for x in ours)})")
print(f"  PyTorch reference (random weights): {t:7.1f} ms  {gflop / t * 1e3:6.1f} GFLOP/s  (rounds: {', '.join(f'{x:.0f}' for x in theirs)})")
print(f"  ratio ours / PyTorch: {o / t:.2f}")
print(f"  ceilings: 2048² sgemm in torch {peak:.0f} GFLOP/s; 2 cores × {mhz / 1e3:.2f} GHz × 32 FLOP/cycle = {ceiling:.0f} GFLOP/s")
EOF
