#!/usr/bin/env bash
# Alternating speed comparison with PyTorch, one thread each, in one sitting:
# `runs` rounds of (burn LSTM epoch, PyTorch LSTM epoch, burn KFU iteration, PyTorch KFU
# iteration), each a fresh process that drops 3 warm-up epochs/iterations and reports the
# median (and quartiles, min, max) of the next 10. Prints every process's JSON line, the
# load average before each round, then per workload and side the median of the per-process
# medians with its min..max across processes, and the ratio burn / PyTorch of those medians.
#
#   PYTHON=/path/to/venv/bin/python bash crates/trajpred-neural/benches/compare.sh [runs] [fused|composed]
set -euo pipefail
runs=${1:-5}
mode=${2:-fused}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
py=${PYTHON:-python3}
export RAYON_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
cargo build --release -q -p trajpred-neural --example profile_speed --manifest-path "$root/Cargo.toml"
bin=${CARGO_TARGET_DIR:-$root/target}/release/examples/profile_speed
out=$(mktemp)
for i in $(seq "$runs"); do
    echo "# round $i: $(uptime)"
    "$bin" lstm "$mode" 3 10 | tee -a "$out"
    "$py" "$here/pytorch_lstm_epoch.py" --threads 1 --warmup 3 --repeat 10 --json | tee -a "$out"
    "$bin" kfu "$mode" 3 10 | tee -a "$out"
    "$py" "$here/pytorch_kfu_iteration.py" --threads 1 --warmup 3 --repeat 10 --json | tee -a "$out"
done
echo "# after: $(uptime)"
python3 - "$out" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
for w in ("lstm", "kfu"):
    med = {}
    for side in sorted({r["impl"] for r in rows if r["workload"] == w}):
        m = [r["median_s"] for r in rows if r["workload"] == w and r["impl"] == side]
        med[side] = statistics.median(m)
        print(f"{w:5} {side:14} median {med[side]:.4f} s  [min {min(m):.4f} .. max {max(m):.4f}] over {len(m)} processes")
    burn = [v for k, v in med.items() if k.startswith("burn")]
    if burn and "torch" in med:
        print(f"{w:5} ratio burn / torch = {burn[0] / med['torch']:.2f}")
PY
rm -f "$out"
