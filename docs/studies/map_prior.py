"""Would a map prior help on GeoLife? A study, not part of the library.

What training users did at the same place, heading and speed, as a forecast for a test
user: for each test origin (history 20, horizon 5, the KF-dynamic paper's segmentation:
split where fixes are > 5 s apart, segments of >= 55 points), the training points within
RADIUS m whose last leg heads within 30 degrees of the origin's and whose speed is within
0.5-2x of it (origins moving faster than 1 m/s only). Each neighbour's own future track,
read at the origin's future timestamps, is rotated onto the origin's heading and scaled by
the speed ratio; the prior is the median of those displacements (3 neighbours at least).
Compared with cv-time (the last leg's velocity carried over the actual future times), and
with the mean of the two, on the origins the prior covers. Every third origin is scored.

Coordinates: an equirectangular projection around (39.95 N, 116.35 E), good to ~0.1 %
over Beijing. Splits by user, seeded.

    python3 -m venv /tmp/venv && /tmp/venv/bin/pip install numpy scipy
    /tmp/venv/bin/python docs/studies/map_prior.py ../shared/data/geolife 15 5fold
    /tmp/venv/bin/python docs/studies/map_prior.py ../shared/data/geolife 15 third
"""
import glob, os, sys
import numpy as np
from scipy.spatial import cKDTree

root, RAD, mode = sys.argv[1], float(sys.argv[2]), sys.argv[3]
H, ANG = 5, np.deg2rad(30)
LAT0, LON0, R = 39.95, 116.35, 6371008.8
kx, ky = np.deg2rad(1) * R * np.cos(np.deg2rad(LAT0)), np.deg2rad(1) * R
segs = []
for u in sorted(os.listdir(f"{root}/Data")):
    for f in sorted(glob.glob(f"{root}/Data/{u}/Trajectory/*.plt")):
        a = np.loadtxt(f, delimiter=",", skiprows=6, usecols=(0, 1, 4), ndmin=2)
        t = np.round(a[:, 2] * 86400.0)
        keep = np.concatenate([[True], np.diff(t) > 0])  # repeated timestamps dropped
        a, t = a[keep], t[keep]
        x, y = (a[:, 1] - LON0) * kx, (a[:, 0] - LAT0) * ky
        for s in np.split(np.arange(len(t)), np.where(np.diff(t) > 5)[0] + 1):
            if len(s) >= 55:
                segs.append((u, t[s], x[s], y[s]))
print(f"{len(segs)} segments, {sum(len(s[1]) for s in segs)} points")
users = np.array(sorted({s[0] for s in segs}))
perm = np.random.default_rng(0).permutation(users)
if mode == "5fold":  # train on 4 folds of users, test on the fifth, each fold in turn
    fold = {u: i % 5 for i, u in enumerate(perm)}
    splits = [([j for j, s in enumerate(segs) if fold[s[0]] != f],
               [j for j, s in enumerate(segs) if fold[s[0]] == f]) for f in range(5)]
else:  # one third of the users for training, the rest for testing
    fold = {u: i % 3 for i, u in enumerate(perm)}
    splits = [([j for j, s in enumerate(segs) if fold[s[0]] == 0],
               [j for j, s in enumerate(segs) if fold[s[0]] != 0])]

def future(j, i, tau):
    _, t, x, y = segs[j]
    at = t[i] + tau
    return np.interp(at, t, x) - x[i], np.interp(at, t, y) - y[i], at <= t[-1]

all_cv, cov_cv, cov_map, cov_mean = [], [], [], []
for train, test in splits:
    P, V, S, I = [], [], [], []
    for j in train:
        _, t, x, y = segs[j]
        for i in range(1, len(t) - 1):
            dt = t[i] - t[i - 1]
            P.append((x[i], y[i])); V.append(((x[i] - x[i - 1]) / dt, (y[i] - y[i - 1]) / dt))
            S.append(j); I.append(i)
    P, V = np.array(P), np.array(V)
    tree, sp, hd = cKDTree(P), np.hypot(V[:, 0], V[:, 1]), np.arctan2(V[:, 1], V[:, 0])
    for j in test:
        _, t, x, y = segs[j]
        for i in range(19, len(t) - H, 3):
            dt = t[i] - t[i - 1]
            v = np.array([(x[i] - x[i - 1]) / dt, (y[i] - y[i - 1]) / dt])
            s0, h0 = np.hypot(*v), np.arctan2(v[1], v[0])
            tau = t[i + 1:i + H + 1] - t[i]
            truth = np.stack([x[i + 1:i + H + 1] - x[i], y[i + 1:i + H + 1] - y[i]], 1)
            cv = np.outer(tau, v)
            e_cv = np.hypot(*(cv - truth).T)
            all_cv.append(e_cv)
            if s0 <= 1.0:
                continue
            found = []
            for k in tree.query_ball_point([x[i], y[i]], RAD):
                turn = abs((hd[k] - h0 + np.pi) % (2 * np.pi) - np.pi)
                if 0.5 * s0 <= sp[k] <= 2 * s0 and turn <= ANG:
                    fx, fy, ok = future(S[k], I[k], tau)
                    if ok.all():
                        c, s = np.cos(h0 - hd[k]), np.sin(h0 - hd[k])
                        found.append(np.stack([c * fx - s * fy, s * fx + c * fy], 1) * s0 / sp[k])
            if len(found) >= 3:
                prior = np.median(found, 0)
                cov_cv.append(e_cv)
                cov_map.append(np.hypot(*(prior - truth).T))
                cov_mean.append(np.hypot(*((prior + cv) / 2 - truth).T))

all_cv = np.array(all_cv)
print(f"mode {mode}, radius {RAD} m: {len(all_cv)} origins scored, cv-time {all_cv.mean():.3f} m, "
      f"{(all_cv < 25).mean() * 100:.2f} % within 25 m")
print(f"covered by the prior: {len(cov_cv)} ({len(cov_cv) / len(all_cv) * 100:.1f} %)")
for name, e in [("cv-time", cov_cv), ("map prior", cov_map), ("mean of both", cov_mean)]:
    e = np.array(e)
    steps = " ".join(f"{v:.2f}" for v in e.mean(0))
    print(f"  {name:12} per step [{steps}] m, mean {e.mean():.3f} m, {(e < 25).mean() * 100:.2f} % within 25 m")
