"""The timing loop, arguments and summary shared by the PyTorch reference benchmarks
(`pytorch_lstm_epoch.py`, `pytorch_kfu_iteration.py`), written once so that both time and
report the same way.
"""

import json
import math
import statistics
import sys
import time

import torch


def add_common_args(ap, repeat):
    """Adds `--threads`, `--warmup`, `--repeat` (default `repeat`) and `--json` to `ap`."""
    ap.add_argument("--threads", type=int, default=1, help="torch.set_num_threads; 0 = default")
    ap.add_argument("--warmup", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=repeat)
    ap.add_argument("--json", action="store_true", help="print one JSON line instead of text")


def set_threads(a):
    """Applies `--threads` (0 keeps PyTorch's default thread count)."""
    if a.threads > 0:
        torch.set_num_threads(a.threads)


def timed(step, warmup, repeat):
    """Calls `step()` (one timed unit of work; returns its loss) `warmup + repeat` times and
    returns the wall times (time.perf_counter) of the last `repeat` calls and every loss.
    Exits with an error when a loss is not finite."""
    times, losses = [], []
    for i in range(warmup + repeat):
        t0 = time.perf_counter()
        value = step()
        dt = time.perf_counter() - t0
        if not math.isfinite(value):
            sys.exit(f"loss diverged: {value}")
        losses.append(value)
        if i >= warmup:
            times.append(dt)
    return times, losses


def summary(times, losses):
    """Median, quartiles, min and max of `times` (never the minimum alone), and the first and
    last loss."""
    q = statistics.quantiles(times, n=4, method="inclusive")
    return {
        "median_s": statistics.median(times),
        "p25_s": q[0],
        "p75_s": q[2],
        "min_s": min(times),
        "max_s": max(times),
        "first_loss": losses[0],
        "last_loss": losses[-1],
    }


def spread(res, unit):
    """`median ... s/<unit> [p25 ..., p75 ...; min ..., max ...]` of a `summary`."""
    return (
        f"median {res['median_s']:.4f} s/{unit} "
        f"[p25 {res['p25_s']:.4f}, p75 {res['p75_s']:.4f}; min {res['min_s']:.4f}, "
        f"max {res['max_s']:.4f}]"
    )


def emit(res, as_json, text):
    """Prints `res` as one JSON line when `as_json`, else `text`."""
    print(json.dumps(res) if as_json else text)
