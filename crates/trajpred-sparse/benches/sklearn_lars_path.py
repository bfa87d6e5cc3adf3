"""Times scikit-learn's lars_path (method='lar', full path) on the benchmark data of
benches/lars.rs (same counter-based generator: splitmix64 + Box-Muller), single-threaded.

Run: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 /work/venv/bin/python \
     crates/trajpred-sparse/benches/sklearn_lars_path.py
"""
import os
import time
import warnings

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from sklearn.linear_model import lars_path  # noqa: E402

GOLDEN = np.uint64(0x9E3779B97F4A7C15)


def splitmix(k):
    with np.errstate(over="ignore"):
        z = (k + np.uint64(1)) * GOLDEN
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        return z ^ (z >> np.uint64(31))


def uniform(k):
    return ((splitmix(k) >> np.uint64(11)).astype(np.float64) + 0.5) * (1.0 / 2.0**53)


def normal(k):
    k = np.asarray(k, dtype=np.uint64)
    u1, u2 = uniform(np.uint64(2) * k), uniform(np.uint64(2) * k + np.uint64(1))
    return np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2)


def data(n, p):
    X = normal(np.arange(n * p, dtype=np.uint64)).reshape(n, p)
    beta = normal(np.arange(n * p, n * p + p, dtype=np.uint64))
    y = X @ beta + normal(np.arange(n * p + p, n * p + p + n, dtype=np.uint64))
    return X, y


def main():
    warnings.simplefilter("ignore")
    print(f"scikit-learn {sklearn.__version__}, numpy {np.__version__}, single-threaded BLAS")
    for n, p in [(442, 10), (2000, 100), (5000, 500)]:
        X, y = data(n, p)
        alphas, _, _ = lars_path(X, y, method="lar")
        reps = 5 if p >= 500 else 50
        best = float("inf")
        times = []
        for _ in range(reps):
            t = time.perf_counter()
            lars_path(X, y, method="lar")
            dt = time.perf_counter() - t
            times.append(dt)
            best = min(best, dt)
        print(f"{n}x{p}: {len(alphas)} knots, median {np.median(times)*1e3:.3f} ms, best {best*1e3:.3f} ms")


if __name__ == "__main__":
    main()
