"""Time filterpy's UKF predict+update on the benchmark problem of benches/kalman.rs
(5-state coordinated turn, range-bearing observation, Merwe points alpha=0.5, beta=2,
kappa=-2), so the Rust figure can be set beside it in the same session.

Run:  <venv>/bin/python crates/trajpred-kalman/benches/filterpy_ukf_step.py
Prints the median per step over 15 batches of 2000 steps, with the min..max of the batches,
and the same as one JSON line.
"""
import json
import math
import timeit

import numpy as np
import filterpy
from filterpy.common import Q_discrete_white_noise
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

SENSOR = np.array([-20.0, 15.0])
DT = 0.5


def fx(x, dt):
    px, vx, py, vy, w = x
    s, c = math.sin(w * dt), math.cos(w * dt)
    return np.array([px + s / w * vx - (1 - c) / w * vy, c * vx - s * vy,
                     py + (1 - c) / w * vx + s / w * vy, s * vx + c * vy, w])


def hx(x):
    dx, dy = x[0] - SENSOR[0], x[2] - SENSOR[1]
    return np.array([math.hypot(dx, dy), math.atan2(dy, dx)])


def residual(a, b):
    y = a - b
    y[1] = (y[1] + math.pi) % (2 * math.pi) - math.pi
    return y


def main():
    Q = np.zeros((5, 5))
    blk = Q_discrete_white_noise(dim=2, dt=DT, var=0.2)
    Q[0:2, 0:2] = blk
    Q[2:4, 2:4] = blk
    Q[4, 4] = DT * DT * 1e-3
    points = MerweScaledSigmaPoints(5, alpha=0.5, beta=2.0, kappa=-2.0)
    ukf = UnscentedKalmanFilter(dim_x=5, dim_z=2, dt=DT, hx=hx, fx=fx, points=points,
                                residual_z=residual)
    ukf.Q, ukf.R = Q, np.diag([0.5, 1e-3])
    x0 = np.array([0.5, 7.0, -0.5, 2.5, 0.1])
    P0 = np.diag([2.0, 1.0, 2.0, 1.0, 0.01])
    z = np.array([27.4, -0.586])

    def step():
        # the same work as the Rust benchmark: one predict + update from a fixed state
        ukf.x, ukf.P = x0.copy(), P0.copy()
        ukf.predict()
        ukf.update(z)

    n, repeat = 2000, 15
    per_step = sorted(t / n for t in timeit.repeat(step, number=n, repeat=repeat))
    median = per_step[len(per_step) // 2]
    print(f"filterpy {filterpy.__version__} UKF predict+update (CT 5-state, range-bearing): "
          f"median {median * 1e6:.2f} us per step [min {per_step[0] * 1e6:.2f} .. max "
          f"{per_step[-1] * 1e6:.2f}] over {repeat} batches of {n}")
    print(json.dumps({"impl": "filterpy", "workload": "ukf_step", "version": filterpy.__version__,
                      "median_s": median, "min_s": per_step[0], "max_s": per_step[-1],
                      "batches": repeat, "steps_per_batch": n}))


if __name__ == "__main__":
    main()
