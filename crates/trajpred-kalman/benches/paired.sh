#!/bin/bash
# Paired timing of two `examples/profile_step_loop` runs on a 2-core machine whose speed drifts:
# run A on core 0 and B on core 1 at once, then swapped, and report per pair the geometric
# mean of the two ratios B/A (which cancels the two cores' different speeds), sorted, with
# the mean ns per step of each side and the median ratio.
#
# usage: paired.sh PAIRS BIN_A LOOP_A BIN_B LOOP_B [STEPS]
#   e.g. cargo build --release -p trajpred-kalman --example profile_step_loop
#        B=target/release/examples/profile_step_loop
#        bash crates/trajpred-kalman/benches/paired.sh 20 $B ads $B kf
set -euo pipefail
pairs=$1; bin_a=$2; loop_a=$3; bin_b=$4; loop_b=$5; steps=${6:-500000}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ns() { awk '{print $(NF-1)}' "$1"; }
for _ in $(seq "$pairs"); do
  taskset -c 0 "$bin_a" "$loop_a" "$steps" 2> "$tmp/a1" & taskset -c 1 "$bin_b" "$loop_b" "$steps" 2> "$tmp/b1"; wait
  taskset -c 1 "$bin_a" "$loop_a" "$steps" 2> "$tmp/a2" & taskset -c 0 "$bin_b" "$loop_b" "$steps" 2> "$tmp/b2"; wait
  awk -v a1="$(ns "$tmp/a1")" -v b1="$(ns "$tmp/b1")" -v a2="$(ns "$tmp/a2")" -v b2="$(ns "$tmp/b2")" \
    'BEGIN { printf "%.3f %.1f %.1f\n", sqrt((b1 * b2) / (a1 * a2)), (a1 + a2) / 2, (b1 + b2) / 2 }'
done | sort -n | awk '{ r[NR] = $1; s = s " " $1; a = a " " $2; b = b " " $3 }
  END { print "ratios B/A" s; print "A ns" a; print "B ns" b; print "median", r[int((NR + 1) / 2)] }'
