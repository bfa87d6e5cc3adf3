//! The description of a window that `aligned-gbm` and `aligned-mlp` learn from: every
//! feature in the frame where the window's last velocity points along +x (issue 27).

use super::fitted::At;
use super::{Heading, horizontal_axes as xy};
use serde_json::Value;
use trajpred_core::{Forecast, Result, Trajectory};

/// Which features a window is described by.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Layout {
    /// Past legs described one by one (`k`; the history needs `k + 1` points).
    pub lags: usize,
    /// Points over which the mean interval, the mean velocity and the longest line are
    /// taken (fewer if the history is shorter).
    pub window: usize,
    /// With the window's shape: least-squares lines through the last 5, 10 and `window`
    /// points and a parabola through the last 10 (position at the origin and velocity, and
    /// acceleration, rotated), and the spread of the window's legs (speed: standard
    /// deviation, largest, smallest, median, legs slower than 0.3 m/s; interval: standard
    /// deviation, largest; total turn).
    pub shape: bool,
}

impl Layout {
    /// Features per origin: the last speed, the mean interval, the rotated velocity and
    /// duration of each of the `k` last legs, and the rotated mean velocity of the window;
    /// with the shape features, 18 fitted and 8 spread features more.
    pub(super) fn count(&self) -> usize {
        3 * self.lags + 4 + if self.shape { 26 } else { 0 }
    }

    /// Per feature, `-1` where mirroring the track across its heading negates it (the
    /// across-track components), else `1`; in the order [`Origin::new`] writes them.
    pub(super) fn mirror_signs(&self) -> Vec<f64> {
        let mut s = vec![1.0, 1.0];
        for _ in 0..self.lags {
            s.extend([1.0, -1.0, 1.0]);
        }
        s.extend([1.0, -1.0]);
        if self.shape {
            // three lines (position, velocity) and a parabola (position, velocity,
            // acceleration), each (along, across); then the legs' spread, unsigned
            for _ in 0..9 {
                s.extend([1.0, -1.0]);
            }
            s.extend([1.0; 8]);
        }
        s
    }
}

/// One origin described in the frame where its last velocity points along +x.
pub(super) struct Origin {
    /// The heading.
    pub(super) u: Heading,
    /// The last velocity, rotated (`(|v0|, 0)` unless it is zero).
    pub(super) v0: (f64, f64),
    /// The mean interval of the window, s.
    pub(super) delta: f64,
    /// The features, [`Layout::count`] of them.
    pub(super) feats: Vec<f64>,
}

impl Origin {
    /// The origin `o` of a track (`o >= lags`); `y` is zeros for 1-D tracks.
    pub(super) fn new(p: &Layout, t: &[f64], x: &[f64], y: &[f64], o: usize) -> Self {
        let vel = |j: usize| {
            let dt = t[o - j] - t[o - j - 1];
            (
                (x[o - j] - x[o - j - 1]) / dt,
                (y[o - j] - y[o - j - 1]) / dt,
                dt,
            )
        };
        let legs: Vec<(f64, f64, f64)> = (0..p.lags).map(vel).collect();
        let u = Heading::of(&legs.iter().map(|&(a, b, _)| (a, b)).collect::<Vec<_>>());
        let rot = |a: f64, b: f64| u.rotate((a, b));
        let first = o + 1 - p.window.min(o + 1);
        let span = t[o] - t[first];
        let delta = span / (o - first) as f64;
        let v0 = rot(legs[0].0, legs[0].1);
        let mut feats = Vec::with_capacity(p.count());
        feats.extend([v0.0.hypot(v0.1), delta]);
        for &(a, b, dt) in &legs {
            let (ra, rb) = rot(a, b);
            feats.extend([ra, rb, dt]);
        }
        let mean = rot((x[o] - x[first]) / span, (y[o] - y[first]) / span);
        feats.extend([mean.0, mean.1]);
        if p.shape {
            shape_features(&t[first..=o], &x[first..=o], &y[first..=o], u, &mut feats);
        }
        Origin {
            u,
            v0,
            delta,
            feats,
        }
    }

    /// Rotates an aligned displacement back to the data's axes.
    pub(super) fn unrotate(&self, d: (f64, f64)) -> (f64, f64) {
        self.u.unrotate(d)
    }
}

/// What an aligned learner's corrections are added to: the last velocity carried over the
/// time ahead (`tau v0`, the default and the only form before 2026-12-07), or the last
/// position. Chosen at fit time by which of the two reference forecasts has the lower mean
/// error over the training origins and steps ([`Base::choose`]): where the last velocity
/// misleads more than it helps (T-Drive's minutes between fixes), the learner would
/// otherwise have to learn to cancel `tau v0`, outliers included.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Base {
    Velocity,
    Position,
}

impl Base {
    /// The base displacement `tau` seconds ahead of `org`, in its aligned frame.
    pub(super) fn at(self, org: &Origin, tau: f64) -> (f64, f64) {
        self.of((tau * org.v0.0, tau * org.v0.1))
    }

    /// The base displacement given the last velocity's, `by_velocity`: that one or none.
    pub(super) fn of(self, by_velocity: (f64, f64)) -> (f64, f64) {
        match self {
            Base::Velocity => by_velocity,
            Base::Position => (0.0, 0.0),
        }
    }

    /// The base whose forecast has the lower mean Euclidean error over every origin with
    /// `lags` legs behind it and every step 1 to `horizons` inside the training tracks (the
    /// last velocity on ties), with the two mean errors.
    pub(super) fn choose(train: &[Trajectory], lags: usize, horizons: usize) -> (Base, f64, f64) {
        let (mut ev, mut ep, mut n) = (0.0, 0.0, 0usize);
        for tr in train {
            let t = tr.times();
            let (x, y) = xy(tr);
            for o in lags.max(1)..tr.len().saturating_sub(1) {
                let dt = t[o] - t[o - 1];
                let v = ((x[o] - x[o - 1]) / dt, (y[o] - y[o - 1]) / dt);
                for s in 1..=horizons.min(tr.len() - 1 - o) {
                    let tau = t[o + s] - t[o];
                    let d = (x[o + s] - x[o], y[o + s] - y[o]);
                    ev += (d.0 - tau * v.0).hypot(d.1 - tau * v.1);
                    ep += d.0.hypot(d.1);
                    n += 1;
                }
            }
        }
        let (ev, ep) = (ev / n.max(1) as f64, ep / n.max(1) as f64);
        let base = if ep < ev {
            Base::Position
        } else {
            Base::Velocity
        };
        (base, ev, ep)
    }

    /// A base as saved: `"velocity"` or `"position"`.
    pub(super) fn parse(at: &At) -> Result<Base> {
        match at.str()? {
            "velocity" => Ok(Base::Velocity),
            "position" => Ok(Base::Position),
            other => Err(at.error(format!(
                "expected \"velocity\" or \"position\", got \"{other}\""
            ))),
        }
    }

    pub(super) fn name(self) -> &'static str {
        match self {
            Base::Velocity => "velocity",
            Base::Position => "position",
        }
    }
}

/// The summary's words for the base: nothing for the last velocity chosen without a
/// comparison (loaded), else which and the two training errors.
pub(super) fn base_said(base: Base, errors: Option<(f64, f64)>) -> String {
    match errors {
        Some((ev, ep)) => format!(
            "; corrections added to the last {} (training mean error of the last velocity \
             {ev:.3} m, of the last position {ep:.3} m)",
            base.name()
        ),
        None if base == Base::Position => "; corrections added to the last position".into(),
        None => String::new(),
    }
}

/// The coefficients of the least-squares polynomial of degree 1 or 2 through `(t_i, v_i)`
/// with `t` relative to the last time (so the first is the value at the origin), lowest
/// degree first; zeros when there are fewer points than coefficients. The times must be
/// distinct (a track's are increasing).
fn poly_fit<const D: usize>(t: &[f64], v: &[f64]) -> [f64; D] {
    if t.len() < D {
        return [0.0; D];
    }
    let t0 = t[t.len() - 1];
    let mut m = [[0.0; D]; D];
    let mut r = [0.0; D];
    for (&ti, &vi) in t.iter().zip(v) {
        let s = ti - t0;
        let pw = [1.0, s, s * s];
        for a in 0..D {
            r[a] += pw[a] * vi;
            for b in 0..D {
                m[a][b] += pw[a] * pw[b];
            }
        }
    }
    // Gaussian elimination without pivoting: the moment matrix is positive definite
    // when there are at least as many distinct times as coefficients
    for c in 0..D {
        let pivot = m[c];
        for row in c + 1..D {
            let f = m[row][c] / pivot[c];
            for (mk, pk) in m[row].iter_mut().zip(pivot).skip(c) {
                *mk -= f * pk;
            }
            r[row] -= f * r[c];
        }
    }
    let mut out = [0.0; D];
    for c in (0..D).rev() {
        let tail: f64 = (c + 1..D).map(|k| m[c][k] * out[k]).sum();
        out[c] = (r[c] - tail) / m[c][c];
    }
    out
}

/// The shape features of a window (`t`, `x`, `y` from its first point to the origin), in
/// the frame `u`: see [`Layout::shape`].
fn shape_features(t: &[f64], x: &[f64], y: &[f64], u: Heading, feats: &mut Vec<f64>) {
    let n = t.len();
    let (x0, y0) = (x[n - 1], y[n - 1]);
    let rel = |v: &[f64], at: f64| v.iter().map(|a| a - at).collect::<Vec<f64>>();
    let (xr, yr) = (rel(x, x0), rel(y, y0));
    for k in [5, 10, n] {
        let k = k.min(n);
        let from = n - k;
        let fx = poly_fit::<2>(&t[from..], &xr[from..]);
        let fy = poly_fit::<2>(&t[from..], &yr[from..]);
        for d in 0..2 {
            let (a, b) = u.rotate((fx[d], fy[d]));
            feats.extend([a, b]);
        }
    }
    let from = n - 10.min(n);
    let fx = poly_fit::<3>(&t[from..], &xr[from..]);
    let fy = poly_fit::<3>(&t[from..], &yr[from..]);
    for d in 0..3 {
        let (a, b) = u.rotate((fx[d], fy[d]));
        feats.extend([a, b]);
    }
    let legs: Vec<(f64, f64, f64)> = (1..n)
        .map(|i| {
            let dt = t[i] - t[i - 1];
            let (a, b) = u.rotate(((x[i] - x[i - 1]) / dt, (y[i] - y[i - 1]) / dt));
            (a.hypot(b), b.atan2(a), dt)
        })
        .collect();
    let mean_sd = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / v.len() as f64).sqrt()
    };
    let mut speeds: Vec<f64> = legs.iter().map(|l| l.0).collect();
    let dts: Vec<f64> = legs.iter().map(|l| l.2).collect();
    let speed_sd = mean_sd(&speeds);
    speeds.sort_by(f64::total_cmp);
    let slow = speeds.iter().filter(|&&v| v < 0.3).count() as f64;
    let turn: f64 = legs
        .windows(2)
        .map(|w| {
            let d = w[1].1 - w[0].1;
            (d + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
        })
        .map(f64::abs)
        .sum();
    feats.extend([
        speed_sd,
        speeds[speeds.len() - 1],
        speeds[0],
        speeds[speeds.len() / 2],
        slow,
        mean_sd(&dts),
        dts.iter().copied().fold(0.0, f64::max),
        turn,
    ]);
}

/// The forecast of an aligned learner at `times` (checked by the caller): with `c` the
/// corrections its model gives the history's last origin, one per step (per unit of the
/// time ahead on the window's grid), the displacement `tau` seconds ahead at step `s` is
/// `R' [b(tau) + (tau / (s delta)) c_s]`, `b(tau) = tau v0'` or 0 by `base` ([`Base`]); a
/// third axis follows its last velocity.
pub(super) fn forecast_at(
    (layout, base): (&Layout, Base),
    history: &Trajectory,
    times: &[f64],
    corrections: impl FnOnce(&Origin) -> Result<Vec<(f64, f64)>>,
) -> Result<Forecast> {
    let n = history.len();
    let t = history.times();
    let (x, y) = xy(history);
    let org = Origin::new(layout, t, x, &y, n - 1);
    let c = corrections(&org)?;
    let steps: Vec<Vec<f64>> = times
        .iter()
        .zip(c)
        .enumerate()
        .map(|(i, (&at, (ca, cb)))| {
            let tau = at - t[n - 1];
            let scale = tau / ((i + 1) as f64 * org.delta);
            let b = base.at(&org, tau);
            let d = org.unrotate((b.0 + scale * ca, b.1 + scale * cb));
            super::displaced_point(history, d, tau)
        })
        .collect();
    Forecast::new(history.dim(), steps)
}

/// `horizon` forecast times after the history's end, spaced by the mean interval of its
/// last `window` points (what `forecast` asks an aligned learner for).
pub(super) fn grid_times(history: &Trajectory, window: usize, horizon: usize) -> Vec<f64> {
    let n = history.len();
    let delta = super::step_interval(history, window.min(n));
    let last = history.times()[n - 1];
    (1..=horizon).map(|k| last + k as f64 * delta).collect()
}

impl Layout {
    /// A fitted model's parameters: these settings (`lags`, `window`, `shape_features`), the
    /// `horizons`, `"base": "position"` when the corrections are added to the last position
    /// ([`Base`]; absent for the last velocity) and the model under `key`.
    pub(super) fn saved(&self, horizons: usize, base: Base, key: &str, model: Value) -> Value {
        let mut v = serde_json::json!({
            "lags": self.lags,
            "window": self.window,
            "horizons": horizons,
            "shape_features": self.shape,
        });
        if base != Base::Velocity {
            // (only then: files saved before the choice stay valid and unchanged)
            v["base"] = base.name().into();
        }
        v[key] = model;
        v
    }

    /// Reads parameters written by [`Layout::saved`]: checks the settings against these and
    /// `horizons` (naming the one that differs) and returns the model under `key` and the
    /// base.
    pub(super) fn read_saved<'a>(
        &self,
        horizons: usize,
        root: &At<'a>,
        key: &str,
    ) -> Result<(At<'a>, Base)> {
        let [lags, window, horizons_at, shape, model] = root.fields_and(
            ["lags", "window", "horizons", "shape_features", key],
            &["base"],
        )?;
        let base = match root.optional("base") {
            None => Base::Velocity,
            Some(b) => Base::parse(&b)?,
        };
        let saved_shape = shape.bool()?;
        if saved_shape != self.shape {
            return Err(shape.error(format!(
                "fitted with shape_features {saved_shape}, but this predictor has {}",
                self.shape
            )));
        }
        for (at, ours, key) in [
            (&lags, self.lags, "lags"),
            (&window, self.window, "window"),
            (&horizons_at, horizons, "horizons"),
        ] {
            let saved = at.f64()?;
            if saved != ours as f64 {
                return Err(at.error(format!(
                    "fitted with {key} {saved}, but this predictor has {key} {ours}"
                )));
            }
        }
        Ok((model, base))
    }
}

#[cfg(test)]
mod tests {
    use super::Base;
    use super::{Layout, Origin, poly_fit};
    use trajpred_core::Trajectory;

    #[test]
    fn every_feature_is_the_same_for_a_turned_and_moved_history() {
        // the features are taken in the frame of the last velocity: turning and moving the
        // window must leave every one of them as it was
        let t: Vec<f64> = (0..25)
            .map(|i| i as f64 * 1.5 + 0.4 * ((i * 5) % 3) as f64)
            .collect();
        let x: Vec<f64> = t.iter().map(|t| 8.0 * t - 0.05 * t * t).collect();
        let y: Vec<f64> = t.iter().map(|t| 3.0 * (0.2 * t).sin() * t).collect();
        let (c, s) = (0.7_f64.cos(), 0.7_f64.sin());
        let tx: Vec<f64> = x
            .iter()
            .zip(&y)
            .map(|(a, b)| c * a - s * b + 300.0)
            .collect();
        let ty: Vec<f64> = x
            .iter()
            .zip(&y)
            .map(|(a, b)| s * a + c * b - 120.0)
            .collect();
        let p = Layout {
            lags: 8,
            window: 20,
            shape: true,
        };
        let (a, b) = (
            Origin::new(&p, &t, &x, &y, 24),
            Origin::new(&p, &t, &tx, &ty, 24),
        );
        assert_eq!(a.feats.len(), p.count());
        for (i, (u, v)) in a.feats.iter().zip(&b.feats).enumerate() {
            assert!(
                (u - v).abs() < 1e-9 * (1.0 + u.abs()),
                "feature {i}: {u} against {v}"
            );
        }
    }

    #[test]
    fn poly_fit_recovers_a_parabola_and_a_line_at_the_last_time() {
        let t = [10.0, 11.5, 12.0, 13.7, 15.0, 16.2];
        // v = 3 + 2 s - 0.5 s^2 with s = t - 16.2
        let v: Vec<f64> = t
            .iter()
            .map(|&t| {
                let s = t - 16.2;
                3.0 + 2.0 * s - 0.5 * s * s
            })
            .collect();
        let [a, b, c] = poly_fit::<3>(&t, &v);
        assert!((a - 3.0).abs() < 1e-9 && (b - 2.0).abs() < 1e-9 && (c + 0.5).abs() < 1e-9);
        // the least-squares line through (0, 0), (1, 1), (2, 0), by hand: v = 1/3 at every
        // time, so 1/3 at the last time and slope 0
        let [a, b] = poly_fit::<2>(&[0.0, 1.0, 2.0], &[0.0, 1.0, 0.0]);
        assert!((a - 1.0 / 3.0).abs() < 1e-12 && b.abs() < 1e-12, "{a} {b}");
        assert_eq!(poly_fit::<3>(&[0.0, 1.0], &[1.0, 2.0]), [0.0; 3]);
    }

    /// The two reference errors by hand on a tiny track, and the choice they make: a track
    /// that goes back and forth (every step undoes the last) is forecast better by its last
    /// position, one at a constant velocity by its last velocity.
    #[test]
    fn the_base_is_the_reference_forecast_with_the_lower_training_error() {
        // x = 0, 10, 0, 10, 0 at t = 0..4 (y = 0), lags 1, 2 steps: origins 1, 2, 3
        let zigzag = Trajectory::from_axes(
            (0..5).map(f64::from).collect(),
            vec![vec![0.0, 10.0, 0.0, 10.0, 0.0], vec![0.0; 5]],
        )
        .unwrap();
        // origin 1 (v = +10): step 1 d = -10 (velocity error 20, position 10), step 2 d = 0
        // (20, 0); origin 2 (v = -10): d = +10 (20, 10), d = 0 (20, 0); origin 3: d = -10
        // (20, 10): velocity 100 / 5, position 30 / 5
        let (base, ev, ep) = Base::choose(std::slice::from_ref(&zigzag), 1, 2);
        assert_eq!((base, ev, ep), (Base::Position, 20.0, 6.0));
        let straight = Trajectory::from_axes(
            (0..5).map(f64::from).collect(),
            vec![(0..5).map(|i| 3.0 * f64::from(i)).collect(), vec![0.0; 5]],
        )
        .unwrap();
        let (base, ev, ep) = Base::choose(&[straight], 1, 2);
        assert_eq!(base, Base::Velocity);
        assert_eq!(ev, 0.0);
        // origins 1, 2, 3: displacements 3, 6 | 3, 6 | 3: 21 / 5
        assert!((ep - 4.2).abs() < 1e-12, "{ep}");
    }
}
