"""Times scikit-learn's lars_path (method='lar', full path) on the benchmark data of
benches/lars.rs and benches/lars_timing.rs (same counter-based generator: splitmix64 +
Box-Muller), with one BLAS thread.

Two configurations per size, as benches/lars_timing.rs times ours:
- gram: `lars_path(X, y, Gram='auto')`: the Gram matrix X^T X is computed inside the timed
  call when n_samples > n_features (what `sklearn.linear_model.Lars` does by default);
  for p > n it is not, and the path runs on X;
- no_gram: `lars_path(X, y, Gram=None)`: every step works on X.

Each configuration is timed `reps` times (after one untimed warm-up run); the script prints
the median, the quartiles and the extremes of the wall-clock time, and the thread's CPU time
over the timed runs divided by reps (which leaves out waiting for a core on a shared machine),
in milliseconds.
`max_iter=min(n, p)`: the number of steps our path takes (for p > n it stops when the
residual correlation vanishes, after n steps; scikit-learn's default max_iter=500 would take
300 more steps past the exact fit). The timing protocol is the one
of benches/lars_timing.rs.

Run: /tmp/venv-sk/bin/python crates/trajpred-sparse/benches/sklearn_lars_path.py [--quick]
"""
import os
import sys
import time
import warnings

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from sklearn.linear_model import lars_path  # noqa: E402
from threadpoolctl import threadpool_info, threadpool_limits  # noqa: E402

GOLDEN = np.uint64(0x9E3779B97F4A7C15)
CASES = [(442, 10), (2000, 100), (5000, 500), (200, 1000)]


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


def reps_for(n, p, quick):
    """The same repetition counts as benches/lars_timing.rs."""
    work = n * p * min(n, p)
    if quick:
        return 3
    if work >= 10**9:
        return 11
    if work >= 10**7:
        return 31
    return 201


def summary(times):
    t = np.sort(np.asarray(times)) * 1e3
    q1, med, q3 = np.percentile(t, [25, 50, 75])
    return f"median {med:.4f} ms  IQR [{q1:.4f}, {q3:.4f}]  range [{t[0]:.4f}, {t[-1]:.4f}]  n={len(t)}"


def main():
    quick = "--quick" in sys.argv
    warnings.simplefilter("ignore")
    with threadpool_limits(limits=1):
        blas = ", ".join(
            f"{i['internal_api']} {i.get('version')} threads={i['num_threads']}"
            for i in threadpool_info()
        )
        print(f"# scikit-learn {sklearn.__version__}, numpy {np.__version__}, BLAS: {blas}")
        for n, p in CASES:
            X, y = data(n, p)
            reps = reps_for(n, p, quick)
            for label, gram in [("gram", "auto"), ("no_gram", None)]:
                # as many steps as ours takes (min(n, p)): for p <= n the default full path;
                # for p > n sklearn's default max_iter=500 would go on past the exact fit
                steps = min(n, p)
                alphas, _, _ = lars_path(X, y, method="lar", Gram=gram, max_iter=steps)  # warm-up
                times = []
                c = time.thread_time()
                for _ in range(reps):
                    t = time.perf_counter()
                    lars_path(X, y, method="lar", Gram=gram, max_iter=steps)
                    times.append(time.perf_counter() - t)
                cpu_mean = (time.thread_time() - c) / reps
                print(
                    f"sklearn {label:8} {n}x{p}: {len(alphas)} knots, {summary(times)}"
                    f"  cpu mean {cpu_mean * 1e3:.4f} ms",
                    flush=True,
                )


if __name__ == "__main__":
    main()
