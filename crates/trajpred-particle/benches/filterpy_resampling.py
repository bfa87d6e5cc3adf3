"""filterpy 2.0.0's resamplers at N = 10^4 and 10^6, for comparison with
`cargo bench -p trajpred-particle -- resample` in the same sitting.

    /work/venv/bin/python crates/trajpred-particle/benches/filterpy_resampling.py

Prints the best of 5 repeats (each the mean over a few calls) in seconds per call and in
particles per second. Weights: i.i.d. uniform, normalised (filterpy assumes normalised weights).
"""
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
        t = min(timeit.repeat(lambda: fn(w), number=number, repeat=5)) / number
        print(f"filterpy {name:12s} N={n:>8d}: {t * 1e3:9.3f} ms/call, {n / t / 1e6:8.2f} M particles/s")
