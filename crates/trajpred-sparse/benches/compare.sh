#!/usr/bin/env bash
# Ours (benches/lars_timing.rs) and scikit-learn (benches/sklearn_lars_path.py) in one sitting,
# alternating, RUNS times each, with the load average before every run; then a summary: per
# configuration the median of the runs' medians, the range of the runs' medians, and the
# ratio peer / ours. Usage (from the repository root):
#   crates/trajpred-sparse/benches/compare.sh [RUNS] [PYTHON]    (defaults: 5, /tmp/venv-sk/bin/python)
# PYTHON needs scikit-learn, numpy and threadpoolctl. The log goes to stdout.
#   crates/trajpred-sparse/benches/compare.sh --summary LOG [PYTHON]   (the table of a saved log)
set -euo pipefail
summary() {
"$1" - "$2" <<'PY'
import re, sys, statistics as st
runs = {}
for line in open(sys.argv[1]):
    m = re.match(r"(ours|sklearn)\s+(\w+)\s+(\d+x\d+): (\d+) knots, median ([\d.]+) ms.*n=(\d+)\s+cpu mean ([\d.naN]+) ms", line)
    if m:
        who, cfg, size, knots, med, reps, cpu = m.groups()
        # the scheduler's CPU counter moves at context switches and ticks: a batch shorter
        # than ~50 ms in all is not measured reliably
        cpu = float(cpu) if float(cpu) * int(reps) >= 50 else float("nan")
        runs.setdefault((size, cfg, who), []).append((float(med), cpu))
print("\n| size | config | ours: median of run medians (range) | scikit-learn (range) | ratio | ours CPU/fit | scikit-learn CPU/fit | CPU ratio |")
print("|---|---|---|---|---|---|---|---|")
for size in ["442x10", "2000x100", "5000x500", "200x1000"]:
    for cfg in ["gram", "no_gram"]:
        o, s = runs.get((size, cfg, "ours")), runs.get((size, cfg, "sklearn"))
        if not o or not s:
            continue
        om, sm = st.median(x[0] for x in o), st.median(x[0] for x in s)
        oc, sc = st.median(x[1] for x in o), st.median(x[1] for x in s)
        g = lambda v: "n/a" if v != v else f"{v:.4g} ms"
        ratio = "n/a" if oc != oc or sc != sc else f"{sc / oc:.2f}x"
        print(f"| {size} | {cfg} | {om:.4g} ms ({min(x[0] for x in o):.4g}-{max(x[0] for x in o):.4g}) | "
              f"{sm:.4g} ms ({min(x[0] for x in s):.4g}-{max(x[0] for x in s):.4g}) | {sm / om:.2f}x | "
              f"{g(oc)} | {g(sc)} | {ratio} |")
PY
}
if [ "${1:-}" = "--summary" ]; then
  summary "${3:-/tmp/venv-sk/bin/python}" "$2"
  exit 0
fi
RUNS=${1:-5}
PY=${2:-/tmp/venv-sk/bin/python}
DIR=$(cd "$(dirname "$0")" && pwd)
cargo bench -q -p trajpred-sparse --bench lars_timing --no-run -j 2 2>/dev/null
BIN=$(cargo bench -q -p trajpred-sparse --bench lars_timing --no-run -j 2 --message-format=json 2>/dev/null \
  | "$PY" -c 'import json,sys
for l in sys.stdin:
    m = json.loads(l)
    if m.get("reason") == "compiler-artifact" and m["target"]["name"] == "lars_timing" and m.get("executable"):
        print(m["executable"])')
LOG=$(mktemp)
echo "# $(date -u +%FT%TZ) $(uname -n) $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)" | tee -a "$LOG"
for r in $(seq 1 "$RUNS"); do
  echo "## run $r ours, load: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$LOG"
  "$BIN" | tee -a "$LOG"
  echo "## run $r sklearn, load: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$LOG"
  OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 "$PY" "$DIR/sklearn_lars_path.py" | tee -a "$LOG"
done
echo "# $(date -u +%FT%TZ) end, load: $(cut -d' ' -f1-3 /proc/loadavg)"
summary "$PY" "$LOG"
