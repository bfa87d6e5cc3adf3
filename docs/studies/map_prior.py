"""Would a map prior help on GeoLife or T-Drive? A study, not part of the library.

What training users did at the same place, heading and speed, as a forecast for a test
user: for each test origin (history 20, horizon 5; GeoLife as the KF-dynamic paper segments
it, split where fixes are > 5 s apart, segments of >= 55 points; T-Drive split where a taxi
is silent for > 300 s, segments of >= 25 points, as in docs/accuracy.md), the training points
within
RADIUS m whose last leg heads within 30 degrees of the origin's and whose speed is within
0.5-2x of it (origins moving faster than 1 m/s only). Each neighbour's own future track,
read at the origin's future timestamps, is rotated onto the origin's heading and scaled by
the speed ratio; the prior is the median of those displacements (3 neighbours at least).
Compared with a reference, and with the mean of the two, on the origins the prior covers:
on GeoLife cv-time (the last leg's velocity carried over the actual future times), on
T-Drive the last position (the better of the two there). Every third origin is scored on
GeoLife, every origin on T-Drive.

Coordinates: an equirectangular projection around (39.95 N, 116.35 E), good to ~0.1 %
over Beijing. Splits by user, seeded.

    python3 -m venv /tmp/venv && /tmp/venv/bin/pip install numpy scipy
    /tmp/venv/bin/python docs/studies/map_prior.py geolife ../shared/data/geolife 15 5fold
    /tmp/venv/bin/python docs/studies/map_prior.py geolife ../shared/data/geolife 15 third
    /tmp/venv/bin/python docs/studies/map_prior.py tdrive ../shared/data/tdrive 100 5fold
    /tmp/venv/bin/python docs/studies/map_prior.py tdrive ../shared/data/tdrive 200 third
"""
import glob, os, sys
import numpy as np
from scipy.spatial import cKDTree

dataset, root, RAD, mode = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
tdrive = dataset == "tdrive"
REF = "last-position" if tdrive else "cv-time"
H, ANG = 5, np.deg2rad(30)
LAT0, LON0, R = (39.95, 116.4, 6371008.8) if tdrive else (39.95, 116.35, 6371008.8)
kx, ky = np.deg2rad(1) * R * np.cos(np.deg2rad(LAT0)), np.deg2rad(1) * R
segs = []


def split(u, t, x, y, gap, least):
    for s in np.split(np.arange(len(t)), np.where(np.diff(t) > gap)[0] + 1):
        if len(s) >= least:
            segs.append((u, t[s], x[s], y[s]))


if tdrive:  # "id,YYYY-MM-DD HH:MM:SS,lon,lat"; greater Beijing only, in time order
    for f in sorted(glob.glob(f"{root}/taxi_log_2008_by_id/*.txt")):
        rows = [l.split(",") for l in open(f).read().split("\n") if l]
        if len(rows) < 25:
            continue
        t = np.array([np.datetime64(r[1].replace(" ", "T"), "s").astype(np.int64) for r in rows], float)
        lon, lat = np.array([float(r[2]) for r in rows]), np.array([float(r[3]) for r in rows])
        ok = (lon >= 115.4) & (lon <= 117.6) & (lat >= 39.4) & (lat <= 41.1)
        o = np.argsort(t[ok], kind="stable")
        t, lon, lat = t[ok][o], lon[ok][o], lat[ok][o]
        keep = np.concatenate([[True], np.diff(t) > 0])[: len(t)]  # repeated timestamps dropped
        t, lon, lat = t[keep], lon[keep], lat[keep]
        split(os.path.basename(f)[:-4], t, (lon - LON0) * kx, (lat - LAT0) * ky, 300, 25)
else:
    for u in sorted(os.listdir(f"{root}/Data")):
        for f in sorted(glob.glob(f"{root}/Data/{u}/Trajectory/*.plt")):
            a = np.loadtxt(f, delimiter=",", skiprows=6, usecols=(0, 1, 4), ndmin=2)
            t = np.round(a[:, 2] * 86400.0)
            keep = np.concatenate([[True], np.diff(t) > 0])  # repeated timestamps dropped
            a, t = a[keep], t[keep]
            split(u, t, (a[:, 1] - LON0) * kx, (a[:, 0] - LAT0) * ky, 5, 55)
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
        for i in range(19, len(t) - H, 1 if tdrive else 3):
            dt = t[i] - t[i - 1]
            v = np.array([(x[i] - x[i - 1]) / dt, (y[i] - y[i - 1]) / dt])
            s0, h0 = np.hypot(*v), np.arctan2(v[1], v[0])
            tau = t[i + 1:i + H + 1] - t[i]
            truth = np.stack([x[i + 1:i + H + 1] - x[i], y[i + 1:i + H + 1] - y[i]], 1)
            cv = np.zeros((H, 2)) if tdrive else np.outer(tau, v)  # the reference
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
print(f"{dataset}, mode {mode}, radius {RAD} m: {len(all_cv)} origins scored, {REF} {all_cv.mean():.3f} m, "
      f"{(all_cv < 25).mean() * 100:.2f} % within 25 m")
print(f"covered by the prior: {len(cov_cv)} ({len(cov_cv) / len(all_cv) * 100:.1f} %)")
for name, e in [(REF, cov_cv), ("map prior", cov_map), ("mean of both", cov_mean)]:
    e = np.array(e)
    steps = " ".join(f"{v:.2f}" for v in e.mean(0))
    print(f"  {name:13} per step [{steps}] m, mean {e.mean():.3f} m, {(e < 25).mean() * 100:.2f} % within 25 m")
