"""filterpy 2.0.0's resamplers at N = 10^4 and 10^6, for comparison with
`cargo bench -p trajpred-particle -- resample` in the same sitting.

    <venv>/bin/python crates/trajpred-particle/benches/filterpy_resampling.py

Prints the median of 11 repeats (each the mean over a few calls), with their min..max, in
seconds per call and in particles per second, and the same as one JSON line per case.
Weights: i.i.d. uniform, normalised (filterpy assumes normalised weights).
"""
import json
import timeit

import numpy as np
from filterpy.monte_carlo import (multinomial_resample, residual_resample,
                                  stratified_resample, systematic_resample)

rng = np.random.default_rng(1)
for n in (10_000, 1_000_000):
    w = rng.random(n)
    w /= w.sum()
    for name, fn in [("residual", residual_resample), ("systematic", systematic_resample),
                     ("stratified", stratified_resample), ("multinomial", multinomial_resample)]:
        number = 20 if n == 10_000 else 1
        ts = sorted(x / number for x in timeit.repeat(lambda: fn(w), number=number, repeat=11))
        t = ts[len(ts) // 2]
        print(f"filterpy {name:12s} N={n:>8d}: median {t * 1e3:9.3f} ms/call "
              f"[{ts[0] * 1e3:.3f} .. {ts[-1] * 1e3:.3f}], {n / t / 1e6:8.2f} M particles/s")
        print(json.dumps({"impl": "filterpy", "workload": f"resample_{name}", "n": n,
                          "median_s": t, "min_s": ts[0], "max_s": ts[-1]}))
