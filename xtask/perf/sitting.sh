#!/usr/bin/env bash
# One sitting of every speed comparison of docs/performance.md, ours beside the peer, on an
# otherwise idle machine: `cargo xtask perf` runs this, then `table.py` writes the table.
#
#   bash xtask/perf/sitting.sh OUT_DIR [RUNS]
#
# Peers run from throwaway virtual environments, made here when missing (PyPI):
#   PY_SK (scikit-learn), PY_FP (filterpy), PY_TORCH (PyTorch); defaults under /tmp.
# Every step logs the load average before it to OUT_DIR/sitting.txt.
set -euo pipefail
out=${1:?usage: sitting.sh OUT_DIR [RUNS]}
runs=${2:-5}
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
mkdir -p "$out"
out=$(cd "$out" && pwd)
target=${CARGO_TARGET_DIR:-$root/target}
PY_SK=${PY_SK:-/tmp/venv-sk/bin/python}
PY_FP=${PY_FP:-/tmp/venv-fp/bin/python}
PY_TORCH=${PY_TORCH:-/tmp/venv-torch-fused/bin/python}

venv() { # python path, packages...
  local py=$1; shift
  if [ ! -x "$py" ]; then
    python3 -m venv "$(dirname "$(dirname "$py")")"
    "$py" -m pip install -q "$@"
  fi
}
venv "$PY_SK" scikit-learn numpy threadpoolctl
venv "$PY_FP" filterpy numpy scipy
venv "$PY_TORCH" torch numpy

log() { echo "$(date -u +%FT%TZ) load $(cut -d' ' -f1-3 /proc/loadavg): $*" | tee -a "$out/sitting.txt"; }
: > "$out/sitting.txt"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(free -g | awk '/Mem/ {print $2}') GiB" >> "$out/sitting.txt"
log "build (not timed)"
cargo build -q --release -p xtask
cargo bench -q --no-run -p trajpred-kalman --bench kalman
cargo bench -q --no-run -p trajpred-particle --bench particle
cargo bench -q --no-run -p trajpred --bench forecast_cost
rm -rf "$target/criterion/kf_step_"* "$target/criterion/ukf_step_"* "$target/criterion/resample" \
  "$target/criterion/forecast_cost"

log "LAR: ours and scikit-learn alternating, $runs runs"
bash crates/trajpred-sparse/benches/compare.sh "$runs" "$PY_SK" > "$out/lars.txt"
log "KF and UKF steps: criterion, ours and adskalman in one run"
cargo bench -q -p trajpred-kalman --bench kalman -- --noplot > "$out/kalman.txt" 2>&1
log "UKF step: filterpy"
"$PY_FP" crates/trajpred-kalman/benches/filterpy_ukf_step.py > "$out/filterpy_ukf.txt"
log "resampling: criterion"
cargo bench -q -p trajpred-particle --bench particle -- --noplot '^resample/' > "$out/particle.txt" 2>&1
log "resampling: filterpy"
"$PY_FP" crates/trajpred-particle/benches/filterpy_resampling.py > "$out/filterpy_resampling.txt"
log "neural: ours and PyTorch alternating, $runs rounds"
PYTHON=$PY_TORCH bash crates/trajpred-neural/benches/compare.sh "$runs" fused > "$out/neural.txt" 2>&1
log "forecast cost: criterion"
cargo bench -q -p trajpred --bench forecast_cost -- --noplot > "$out/forecast_cost.txt" 2>&1
log "cargo xtask reproduce (warm build), checked against docs/results"
start=$(date +%s%N)
"$target/release/xtask" reproduce --check --out "$out/reproduce" > "$out/reproduce.txt" 2>&1 || true
echo "wall_ms $(( ($(date +%s%N) - start) / 1000000 ))" >> "$out/reproduce.txt"
log "end"
mkdir -p "$out/criterion"
cp -r "$target/criterion/"{kf_step_*,ukf_step_*,resample,forecast_cost} "$out/criterion/"
