"""Writes the table of one sitting (xtask/perf/sitting.sh OUT_DIR) into docs/performance.md,
between the markers `<!-- sitting:begin -->` and `<!-- sitting:end -->`.

    python3 xtask/perf/table.py OUT_DIR docs/performance.md

Every figure is read from the sitting's outputs: criterion's estimates (median and its 95 %
interval), the peer scripts' medians and ranges, the alternating scripts' summaries.
"""
import glob
import json
import os
import re
import sys

out, doc = sys.argv[1], sys.argv[2]
rows = []


def read(name):
    path = os.path.join(out, name)
    return open(path).read() if os.path.exists(path) else ""


def crit(*parts):
    """criterion median (ns) and its 95 % interval, or None."""
    path = os.path.join(out, "criterion", *parts, "new", "estimates.json")
    if not os.path.exists(path):
        return None
    m = json.load(open(path))["median"]
    ci = m["confidence_interval"]
    return m["point_estimate"], ci["lower_bound"], ci["upper_bound"]


def ns(v):
    if v is None:
        return "not run"
    med, lo, hi = v
    unit, f = ("ns", 1.0) if med < 1e3 else ("µs", 1e3) if med < 1e6 else ("ms", 1e6)
    return f"{med / f:.4g} {unit} [{lo / f:.4g}-{hi / f:.4g}]"


def verdict(ok):
    return "met" if ok else "**not met**"


# LAR: the summary table of crates/trajpred-sparse/benches/compare.sh
for line in read("lars.txt").splitlines():
    m = re.match(r"\| (\d+x\d+) \| (gram|no_gram) \| ([^|]+) \| ([^|]+) \| ([\d.]+)x \|", line)
    if not m:
        continue
    size, cfg, ours, peer, ratio = m.groups()
    ratio = float(ratio)
    if cfg == "gram":
        target, ok = "≥ 5x", ratio >= 5
    elif size == "5000x500":
        target, ok = "no slower", ratio >= 1
    else:
        continue
    rows.append((f"LAR path {size}, {cfg.replace('_', '-')}", ours.strip(),
                 f"scikit-learn `lars_path` {peer.strip()}", f"{ratio:.2f}x faster ({target}: {verdict(ok)})",
                 "median of run medians (range); [sparse.md](sparse.md)"))

# KF steps: criterion, ours and adskalman in one run
for group, what in [("kf_step_cv4_pos2", "constant velocity, 4 states"),
                    ("kf_step_general_cv4_pos2", "damped CV, scaled positions"),
                    ("kf_step_dense6_obs3", "random dense 6 states, 3-D observation")]:
    a, b = crit(group, "trajpred_joseph"), crit(group, "adskalman_joseph")
    if a and b:
        r = a[0] / b[0]
        rows.append((f"KF step (Joseph), {what}", ns(a), f"adskalman 0.18 {ns(b)}",
                     f"{r:.2f}x (≤ 0.5x: {verdict(r <= 0.5)})", "criterion median [95 % interval]; [kalman.md](kalman.md)"))

# UKF step
u = crit("ukf_step_ct5_rb2", "trajpred")
fp = next((json.loads(l) for l in read("filterpy_ukf.txt").splitlines() if l.startswith("{")), None)
if u:
    peer = (f"filterpy {fp['version']} median {fp['median_s'] * 1e6:.1f} µs "
            f"[{fp['min_s'] * 1e6:.1f}-{fp['max_s'] * 1e6:.1f}]") if fp else "filterpy not run"
    rows.append(("UKF step, coordinated turn + range-bearing", ns(u), peer,
                 f"≤ 0.5 µs: {verdict(u[0] <= 500)}" + (f"; {fp['median_s'] * 1e9 / u[0]:.0f}x faster than filterpy" if fp else ""),
                 "criterion median [95 % interval]"))

# resampling, 10^6 particles
base = crit("resample", "baseline_sum", "1000000")
fpr = {j["workload"][9:]: j for j in (json.loads(l) for l in read("filterpy_resampling.txt").splitlines()
                                       if l.startswith("{")) if j["n"] == 1_000_000}
for scheme, need in [("systematic", 300), ("residual", 300), ("stratified", 200), ("multinomial", 200)]:
    v = crit("resample", scheme, "1000000")
    if not v:
        continue
    rate = 1e6 / v[0] * 1e3  # particles per µs * 1e3 = M/s
    peer = f"weight sum {1e6 / base[0] * 1e3:.0f} M/s (the ceiling)" if base else ""
    if scheme in fpr:
        peer += f"; filterpy {1e6 / fpr[scheme]['median_s'] / 1e6:.2f} M/s"
    rows.append((f"{scheme} resampling, 10^6 particles, 2 threads", f"{rate:.0f} M/s ({ns(v)} per call)", peer,
                 f"≥ {need} M/s: {verdict(rate >= need)}", "criterion median; [particle.md](particle.md)"))

# neural: the summary of crates/trajpred-neural/benches/compare.sh
neural = read("neural.txt")
for w, label in [("lstm", "LSTM training epoch (2 x 64, 800 steps, batch 16), 1 thread"),
                 ("kfu", "KFU-LSTM-Net training iteration (batch 16, 200 steps), 1 thread")]:
    ours = re.search(rf"^{w}\s+burn-fused\s+median ([\d.]+) s\s+\[min ([\d.]+) \.\. max ([\d.]+)\]", neural, re.M)
    torch = re.search(rf"^{w}\s+torch\s+median ([\d.]+) s\s+\[min ([\d.]+) \.\. max ([\d.]+)\]", neural, re.M)
    if ours and torch:
        r = float(ours[1]) / float(torch[1])
        rows.append((label, f"{ours[1]} s [{ours[2]}-{ours[3]}]", f"PyTorch {torch[1]} s [{torch[2]}-{torch[3]}]",
                     f"{r:.2f}x (≤ 0.5x: {verdict(r <= 0.5)})", "median of per-process medians [range]; [neural.md](neural.md)"))

# forecast cost against 25 static steps
static_cv = crit("forecast_cost", "static_step_x25_per_forecast")
static_ca = crit("forecast_cost", "static_ca_step_x25_per_forecast")
for name in ["kf-dynamic", "naive-kf", "kf-dynamic-literal", "kf-cv", "kf-ca"]:
    v = crit("forecast_cost", name)
    # each against the static step of its own model: kf-ca's state is the 6-state CA
    static, model = (static_ca, "CA (6 states)") if name == "kf-ca" else (static_cv, "CV (4 states)")
    if v and static:
        r = v[0] / static[0]
        target = f"(≤ 3x: {verdict(r <= 3)})"
        rows.append((f"{name} forecasts, one pass over 216 histories", ns(v), f"25 static {model} steps each {ns(static)}",
                     f"{r:.2f}x {target}", "criterion median [95 % interval]"))

# the reproduction
rep = read("reproduce.txt")
papers = re.findall(r"^([a-z-]+): ([\d.]+) s, written", rep, re.M)
wall = re.search(r"^wall_ms (\d+)", rep, re.M)
if wall:
    w = int(wall[1]) / 1000
    checks = len(re.findall(r"^check .*agree", rep, re.M))
    rows.append(("`cargo xtask reproduce`, all four papers, warm build", f"{w:.1f} s wall",
                 ", ".join(f"{p} {s} s" for p, s in papers), f"≤ 90 s: {verdict(w <= 90)}",
                 f"`--check`: {checks} of {len(papers)} papers agree with docs/results"))

log = read("sitting.txt").splitlines()
stamps = [l for l in log if re.match(r"\d{4}-", l)]
loads = [float(re.search(r"load ([\d.]+)", l)[1]) for l in stamps]
head = (f"Sitting of {stamps[0][:10]}, {stamps[0][11:19]}-{stamps[-1][11:19]} UTC, "
        f"load average (1 min) {min(loads):.2f}-{max(loads):.2f} at the steps' starts; "
        f"{log[0]}. Written by `cargo xtask perf` from the run's outputs.") if stamps else ""
table = [head, "", "| what | ours | peer / reference | ratio (target) | how |", "|---|---|---|---|---|"]
table += ["| " + " | ".join(r) + " |" for r in rows]
text = open(doc).read()
begin, end = "<!-- sitting:begin -->", "<!-- sitting:end -->"
block = begin + "\n" + "\n".join(table) + "\n" + end
if begin in text and end in text:
    text = text[:text.index(begin)] + block + text[text.index(end) + len(end):]
else:
    text = text.rstrip() + "\n\n## The last sitting\n\n" + block + "\n"
open(doc, "w").write(text)
print("\n".join(table))
