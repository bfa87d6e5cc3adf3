//! `aligned-gbm`: gradient-boosted trees that correct the last velocity, learned in the
//! heading-aligned frame of `aligned-ridge` (issue 27).

use super::fitted::At;
use super::trees::Ensemble;
use super::{Heading, horizontal_axes as xy, invalid};
use forust_ml::gradientbooster::{GrowPolicy, MissingNodeTreatment};
use forust_ml::objective::ObjectiveType;
use forust_ml::sampler::SampleMethod;
use forust_ml::{GradientBooster, Matrix};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use trajpred_core::{Error, Forecast, Predictor, Result, Trajectory, check_forecast_args};

const NAME: &str = "aligned-gbm";

/// Parameters of [`AlignedGbm`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlignedGbmParams {
    /// Past legs described to the trees (`k`; the history needs `k + 1` points).
    pub lags: usize,
    /// Points over which the mean interval and the mean velocity are taken (fewer if the
    /// history is shorter).
    pub window: usize,
    /// Steps the model is fitted for (the longest forecast it answers).
    pub horizons: usize,
    /// Boosting rounds of each model.
    pub iterations: usize,
    /// Shrinkage of each tree.
    pub learning_rate: f64,
    /// Leaves per tree (trees grow best leaf first).
    pub max_leaves: usize,
    /// Smallest number of samples in a leaf (squared loss: the hessian sum).
    pub min_leaf_samples: f64,
    /// Targets are clipped at this quantile of their absolute value, per model, so that the
    /// squared loss is not led by the few wild fixes (0.5 < q <= 1; 1: no clipping).
    pub clip_quantile: f64,
    /// At most this many origins per model (an even stride through them when there are
    /// more), which bounds the time a fit takes.
    pub max_samples: usize,
    /// Also describe the window's shape: least-squares lines through the last 5, 10 and
    /// `window` points and a parabola through the last 10 (position at the origin and
    /// velocity, and acceleration, rotated), and the spread of the window's legs (speed:
    /// standard deviation, largest, smallest, median, legs slower than 0.3 m/s; interval:
    /// standard deviation, largest; total turn).
    pub shape_features: bool,
    /// Reweighted passes after the first fit: each fits the unclipped targets again,
    /// weighing every origin by `1 / max(r, robust_floor)` (normalised to a mean of 1) with
    /// `r` the Euclidean size of its residual under the previous pass (along and across
    /// together), as Weiszfeld's iteration does for the geometric median, so that the fit
    /// aims at the mean distance, the leaderboard's measure. 0: the clipped fit alone.
    pub robust_passes: usize,
    /// The smallest residual (m) a weight is computed from, so that an origin fitted
    /// exactly does not take all the weight.
    pub robust_floor: f64,
    /// Also fit every training origin mirrored across its track (every across-track
    /// feature and target negated: a left turn seen as the right turn it mirrors), which
    /// doubles the origins and the fitting time. Default `false`.
    #[serde(default)]
    pub mirror: bool,
}

impl Default for AlignedGbmParams {
    fn default() -> Self {
        AlignedGbmParams {
            lags: 8,
            window: 20,
            horizons: 6,
            iterations: 200,
            learning_rate: 0.1,
            max_leaves: 31,
            min_leaf_samples: 100.0,
            clip_quantile: 0.8,
            max_samples: 100_000,
            shape_features: true,
            robust_passes: 1,
            robust_floor: 1.0,
            mirror: false,
        }
    }
}

impl AlignedGbmParams {
    fn validate(&self) -> Result<()> {
        let at_least_one = |name, v: usize| {
            if v == 0 {
                Err(invalid(name, "must be at least 1, got 0"))
            } else {
                Ok(())
            }
        };
        at_least_one("lags", self.lags)?;
        at_least_one("horizons", self.horizons)?;
        at_least_one("iterations", self.iterations)?;
        at_least_one("max_samples", self.max_samples)?;
        if self.window < 2 {
            return Err(invalid(
                "window",
                format!("must be at least 2, got {}", self.window),
            ));
        }
        if self.max_leaves < 2 {
            return Err(invalid(
                "max_leaves",
                format!("must be at least 2, got {}", self.max_leaves),
            ));
        }
        if !(self.learning_rate.is_finite() && self.learning_rate > 0.0) {
            return Err(invalid(
                "learning_rate",
                format!("must be finite and positive, got {}", self.learning_rate),
            ));
        }
        if !(self.min_leaf_samples.is_finite() && self.min_leaf_samples >= 0.0) {
            return Err(invalid(
                "min_leaf_samples",
                format!(
                    "must be finite and non-negative, got {}",
                    self.min_leaf_samples
                ),
            ));
        }
        if !(self.robust_floor.is_finite() && self.robust_floor > 0.0) {
            return Err(invalid(
                "robust_floor",
                format!("must be finite and positive, got {}", self.robust_floor),
            ));
        }
        if !(self.clip_quantile > 0.5 && self.clip_quantile <= 1.0) {
            return Err(invalid(
                "clip_quantile",
                format!("must be in (0.5, 1], got {}", self.clip_quantile),
            ));
        }
        Ok(())
    }

    /// Features per origin: the last speed, the mean interval, the rotated velocity and
    /// duration of each of the `k` last legs, and the rotated mean velocity of the window;
    /// with the shape features, 18 fitted and 8 spread features more.
    fn features(&self) -> usize {
        3 * self.lags + 4 + if self.shape_features { 26 } else { 0 }
    }

    /// Per feature, `-1` where mirroring the track across its heading negates it (the
    /// across-track components), else `1`; in the order [`Origin::new`] writes them.
    fn mirror_signs(&self) -> Vec<f64> {
        let mut s = vec![1.0, 1.0];
        for _ in 0..self.lags {
            s.extend([1.0, -1.0, 1.0]);
        }
        s.extend([1.0, -1.0]);
        if self.shape_features {
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
struct Origin {
    /// The heading.
    u: Heading,
    /// The last velocity, rotated (`(|v0|, 0)` unless it is zero).
    v0: (f64, f64),
    /// The mean interval of the window, s.
    delta: f64,
    /// The features, [`AlignedGbmParams::features`] of them.
    feats: Vec<f64>,
}

impl Origin {
    /// The origin `o` of a track (`o >= lags`); `y` is zeros for 1-D tracks.
    fn new(p: &AlignedGbmParams, t: &[f64], x: &[f64], y: &[f64], o: usize) -> Self {
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
        let mut feats = Vec::with_capacity(p.features());
        feats.extend([v0.0.hypot(v0.1), delta]);
        for &(a, b, dt) in &legs {
            let (ra, rb) = rot(a, b);
            feats.extend([ra, rb, dt]);
        }
        let mean = rot((x[o] - x[first]) / span, (y[o] - y[first]) / span);
        feats.extend([mean.0, mean.1]);
        if p.shape_features {
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
    fn unrotate(&self, d: (f64, f64)) -> (f64, f64) {
        self.u.unrotate(d)
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
/// the frame `u`: see [`AlignedGbmParams::shape_features`].
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

/// Training samples of one step: features row by row, and the two normalised targets.
#[derive(Default)]
struct Samples {
    rows: Vec<Vec<f64>>,
    along: Vec<f64>,
    across: Vec<f64>,
}

/// The samples of step `s` (from 1) of one track: every origin with `lags` legs behind it
/// and step `s` inside the track. The target is the displacement at the step's own time
/// `tau` minus the last velocity's, in the aligned frame, divided by `tau / (s delta)` (the
/// correction per unit of the time ahead, on the window's time grid).
fn samples(p: &AlignedGbmParams, tr: &Trajectory, s: usize, into: &mut Samples) {
    let t = tr.times();
    let (x, y) = xy(tr);
    for o in p.lags..tr.len().saturating_sub(s) {
        let org = Origin::new(p, t, x, &y, o);
        let tau = t[o + s] - t[o];
        let d = (x[o + s] - x[o], y[o + s] - y[o]);
        let r = org.u.rotate(d);
        let scale = s as f64 * org.delta / tau;
        into.along.push((r.0 - tau * org.v0.0) * scale);
        into.across.push((r.1 - tau * org.v0.1) * scale);
        into.rows.push(org.feats);
    }
}

/// The `q` quantile of `|v|` (nearest rank).
fn abs_quantile(v: &[f64], q: f64) -> f64 {
    let mut a: Vec<f64> = v.iter().map(|x| x.abs()).collect();
    a.sort_by(f64::total_cmp);
    let i = ((a.len() as f64 - 1.0) * q).round() as usize;
    a.get(i).copied().unwrap_or(0.0)
}

/// Fits one squared-loss booster on column-major `data` and `target`: clipped at
/// `clip_quantile` when `weights` is `None`, else as it is with those weights.
fn fit_booster(
    p: &AlignedGbmParams,
    data: &[f64],
    rows: usize,
    target: &[f64],
    weights: Option<&[f64]>,
) -> Result<GradientBooster> {
    let c = match weights {
        None => abs_quantile(target, p.clip_quantile),
        Some(_) => f64::INFINITY,
    };
    let y: Vec<f64> = target.iter().map(|v| v.clamp(-c, c)).collect();
    let matrix = Matrix::new(data, rows, p.features());
    let mut b = GradientBooster::new(
        ObjectiveType::SquaredLoss,
        p.iterations,
        p.learning_rate as f32,
        usize::MAX, // depth: bounded by the leaves
        p.max_leaves,
        0.0, // l1
        1.0, // l2
        0.0, // gamma
        0.0, // max delta step
        p.min_leaf_samples as f32,
        0.0,   // base score (recomputed: initialize_base_score)
        256,   // histogram bins
        false, // one thread per booster: the boosters are fitted in parallel
        false, // no missing values
        None,
        1.0, // no subsampling: no randomness
        0.2,
        0.1,
        1.0,
        0,
        f64::NAN,
        false,
        SampleMethod::None,
        GrowPolicy::LossGuide,
        None,
        None,
        true,
        HashSet::new(),
        MissingNodeTreatment::AssignToParent,
        0,
        false,
    )
    .map_err(|e| Error::method(NAME, e))?;
    let fitted = match weights {
        None => b.fit_unweighted(&matrix, &y, None),
        Some(w) => b.fit(&matrix, &y, w, None),
    };
    fitted.map_err(|e| Error::method(NAME, e))?;
    Ok(b)
}

/// Gradient-boosted trees that correct the last velocity, learned in the heading-aligned
/// frame (`aligned-gbm` in the registry).
///
/// At an origin the frame is rotated so that the last velocity `v0` points along +x (as in
/// [`AlignedRidge`](super::AlignedRidge)). The trees see, from the history alone: the last
/// speed, the mean interval `delta` of the last `window` points, the rotated velocity and
/// the duration of each of the last `lags` legs, the rotated mean velocity over the
/// window and (by default) the window's shape: least-squares lines and a parabola through
/// its last points, and the spread of its legs' speeds, intervals and turns
/// ([`AlignedGbmParams::shape_features`]). Per step `s` two boosters (along and across the track) predict the departure
/// `c_s` of the future displacement from `tau v0`, per unit of time ahead on the history's
/// grid, so a forecast `tau` seconds ahead is
///
/// ```text
/// d(tau) = R' [ tau v0' + (tau / (s delta)) c_s(features) ]
/// ```
///
/// (with no trees it is `cv-time`). They are fitted first by squared loss on targets clipped
/// at the 0.8 quantile of their size (the leaderboard's mean error is led by typical
/// forecasts, the squares by a few wild fixes), then once more on the unclipped targets
/// weighed by the inverse of the first fit's Euclidean residual (a Weiszfeld step towards
/// the geometric median, [`AlignedGbmParams::robust_passes`]); 200 rounds of 31-leaf trees
/// grown best leaf first, shrinkage 0.1, at least 100 origins a leaf (chosen by
/// cross-validation by user on the training users, `docs/accuracy.md`). Fitting has no randomness: the same data give the
/// same trees. The horizontal axes are modelled; a third axis follows its last velocity.
///
/// ```
/// use trajpred::predictors::{AlignedGbm, AlignedGbmParams};
/// use trajpred_core::{Predictor, Trajectory};
/// // tracks that brake: 10 m/s, losing 0.2 m/s every second
/// let track = |k: usize| -> Result<Trajectory, trajpred_core::Error> {
///     let x = (0..40).map(|i| { let t = i as f64; 10.0 * t - 0.1 * t * t + k as f64 }).collect();
///     Trajectory::uniform(0.0, 1.0, vec![x, vec![0.0; 40]])
/// };
/// let train: Vec<Trajectory> = (0..20).map(track).collect::<Result<_, _>>()?;
/// let params = AlignedGbmParams { min_leaf_samples: 1.0, ..Default::default() };
/// let mut m = AlignedGbm::new(params)?;
/// m.fit(&train)?;
/// let hist = track(3)?.prefix(21)?; // origin at t = 20 s, speed there 6 m/s
/// let f = m.forecast_times(&hist, &[21.0, 22.0, 23.0, 24.0, 25.0])?;
/// let truth = 10.0 * 25.0 - 0.1 * 625.0 + 3.0;
/// let last_velocity = (10.0 * 20.0 - 0.1 * 400.0 + 3.0) + 5.0 * 6.1; // cv-time, 2.5 m off
/// assert!((f.step(5)[0] - truth).abs() < 0.1, "{}", f.step(5)[0]);
/// assert!((last_velocity - truth).abs() > 2.0);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub struct AlignedGbm {
    params: AlignedGbmParams,
    /// Per step, the along- and across-track tree ensembles; empty before fitting.
    models: Vec<[Ensemble; 2]>,
    /// Training origins per step (after the stride), for the summary.
    samples: Vec<usize>,
}

impl AlignedGbm {
    /// An unfitted model; errors for bad parameters, naming the first.
    pub fn new(params: AlignedGbmParams) -> Result<Self> {
        params.validate()?;
        Ok(AlignedGbm {
            params,
            models: Vec::new(),
            samples: Vec::new(),
        })
    }

    /// The column-major features and targets of step `s`, at most `max_samples` origins
    /// (each twice with [`AlignedGbmParams::mirror`]).
    fn step_data(&self, train: &[Trajectory], s: usize) -> (Vec<f64>, usize, [Vec<f64>; 2]) {
        let p = &self.params;
        let mut all = Samples::default();
        for tr in train {
            samples(p, tr, s, &mut all);
        }
        let n = all.rows.len();
        let keep: Vec<usize> = if n > p.max_samples {
            (0..p.max_samples).map(|i| i * n / p.max_samples).collect()
        } else {
            (0..n).collect()
        };
        let copies: &[f64] = if p.mirror { &[1.0, -1.0] } else { &[1.0] };
        let signs = p.mirror_signs();
        let mut data = Vec::with_capacity(copies.len() * keep.len() * p.features());
        for (j, sign) in signs.iter().enumerate() {
            for c in copies {
                // mirrored: the across-track features negated
                let f = if *c < 0.0 { *sign } else { 1.0 };
                data.extend(keep.iter().map(|&i| f * all.rows[i][j]));
            }
        }
        let mut along = Vec::with_capacity(copies.len() * keep.len());
        let mut across = Vec::with_capacity(copies.len() * keep.len());
        for c in copies {
            along.extend(keep.iter().map(|&i| all.along[i]));
            across.extend(keep.iter().map(|&i| c * all.across[i]));
        }
        (data, copies.len() * keep.len(), [along, across])
    }
}

impl Predictor for AlignedGbm {
    fn name(&self) -> &str {
        NAME
    }

    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        self.models.clear();
        self.samples.clear();
        let steps: Vec<(Vec<f64>, usize, [Vec<f64>; 2])> = (1..=self.params.horizons)
            .into_par_iter()
            .map(|s| self.step_data(train, s))
            .collect();
        if let Some(s) = steps.iter().position(|(_, rows, _)| *rows < 2) {
            return Err(Error::TooShort {
                what: "training origins of a step",
                needed: 2,
                got: steps[s].1,
            });
        }
        let p = &self.params;
        let jobs: Vec<(usize, usize)> = (0..steps.len()).flat_map(|s| [(s, 0), (s, 1)]).collect();
        let mut weights: Vec<Option<Vec<f64>>> = vec![None; steps.len()];
        let mut boosters: Vec<GradientBooster> = Vec::new();
        for pass in 0..=p.robust_passes {
            boosters = jobs
                .par_iter()
                .map(|&(s, axis)| {
                    let (data, rows, targets) = &steps[s];
                    fit_booster(p, data, *rows, &targets[axis], weights[s].as_deref())
                })
                .collect::<Result<_>>()?;
            if pass == p.robust_passes {
                break;
            }
            weights = steps
                .par_iter()
                .zip(boosters.par_chunks(2))
                .map(|((data, rows, [along, across]), b)| {
                    let m = Matrix::new(data, *rows, p.features());
                    let (pa, pb) = (b[0].predict(&m, false), b[1].predict(&m, false));
                    let mut w: Vec<f64> = (0..*rows)
                        .map(|i| {
                            let r = (along[i] - pa[i]).hypot(across[i] - pb[i]);
                            1.0 / r.max(p.robust_floor)
                        })
                        .collect();
                    let mean = w.iter().sum::<f64>() / w.len() as f64;
                    w.iter_mut().for_each(|v| *v /= mean);
                    Some(w)
                })
                .collect();
        }
        let boosters: Vec<Ensemble> = boosters
            .iter()
            .map(|b| Ensemble::from_booster(b, p.features()))
            .collect();
        let mut it = boosters.into_iter();
        while let (Some(a), Some(b)) = (it.next(), it.next()) {
            self.models.push([a, b]);
        }
        self.samples = steps.iter().map(|(_, rows, _)| *rows).collect();
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let n = history.len();
        let delta = super::step_interval(history, self.params.window.min(n));
        let last = history.times()[n - 1];
        let times: Vec<f64> = (1..=horizon).map(|k| last + k as f64 * delta).collect();
        self.forecast_times(history, &times)
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        check_forecast_args(history, times.len(), self.min_history())?;
        if self.models.is_empty() {
            return Err(Error::NotFitted {
                method: NAME.into(),
            });
        }
        super::check_fitted_times(NAME, self.models.len(), history, times)?;
        let n = history.len();
        let t = history.times();
        let (x, y) = xy(history);
        let org = Origin::new(&self.params, t, x, &y, n - 1);
        let steps: Vec<Vec<f64>> = times
            .iter()
            .zip(&self.models)
            .enumerate()
            .map(|(i, (&at, [along, across]))| {
                let tau = at - t[n - 1];
                let scale = tau / ((i + 1) as f64 * org.delta);
                let c = (along.predict(&org.feats), across.predict(&org.feats));
                let (dx, dy) =
                    org.unrotate((tau * org.v0.0 + scale * c.0, tau * org.v0.1 + scale * c.1));
                super::displaced_point(history, (dx, dy), tau)
            })
            .collect();
        Forecast::new(history.dim(), steps)
    }

    fn min_history(&self) -> usize {
        self.params.lags + 1
    }

    /// `{"lags", "window", "horizons", "shape_features"}` (checked against this predictor's
    /// parameters on loading) and `"models"`: per step, the along- and across-track tree ensembles
    /// (`{"base", "trees"}`, each tree node by node).
    fn fitted_params(&self) -> Result<serde_json::Value> {
        if self.models.is_empty() {
            return Err(Error::NotFitted {
                method: NAME.into(),
            });
        }
        let models: Vec<serde_json::Value> = self
            .models
            .iter()
            .map(|[a, b]| serde_json::json!([a.to_json(), b.to_json()]))
            .collect();
        let p = &self.params;
        Ok(serde_json::json!({
            "lags": p.lags,
            "window": p.window,
            "horizons": p.horizons,
            "shape_features": p.shape_features,
            "models": models,
        }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let root = At::root(NAME, params);
        let [lags, window, horizons, shape, models] =
            root.fields(["lags", "window", "horizons", "shape_features", "models"])?;
        let p = &self.params;
        let saved_shape = shape.bool()?;
        if saved_shape != p.shape_features {
            return Err(shape.error(format!(
                "fitted with shape_features {saved_shape}, but this predictor has {}",
                p.shape_features
            )));
        }
        for (at, ours, key) in [
            (&lags, p.lags, "lags"),
            (&window, p.window, "window"),
            (&horizons, p.horizons, "horizons"),
        ] {
            let saved = at.f64()?;
            if saved != ours as f64 {
                return Err(at.error(format!(
                    "fitted with {key} {saved}, but this predictor has {key} {ours}"
                )));
            }
        }
        let max_trees = 1 << 20;
        let models = models
            .items(Some(p.horizons), p.horizons)?
            .iter()
            .map(|step| {
                let [a, b] = <[At<'_>; 2]>::try_from(step.items(Some(2), 2)?)
                    .map_err(|_| step.error("expected 2 ensembles"))?;
                Ok([
                    Ensemble::from_json(&a, p.features(), max_trees)?,
                    Ensemble::from_json(&b, p.features(), max_trees)?,
                ])
            })
            .collect::<Result<Vec<_>>>()?;
        self.models = models;
        self.samples.clear();
        Ok(())
    }

    fn fitted_summary(&self) -> Option<String> {
        if self.models.is_empty() {
            return None;
        }
        let trees: Vec<String> = self
            .models
            .iter()
            .map(|[a, b]| format!("{}+{}", a.trees(), b.trees()))
            .collect();
        Some(format!(
            "trees per step (along+across) {}; training origins per step {:?}",
            trees.join(", "),
            self.samples
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::{AlignedGbmParams, Origin, poly_fit};

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
        let p = AlignedGbmParams::default();
        let (a, b) = (
            Origin::new(&p, &t, &x, &y, 24),
            Origin::new(&p, &t, &tx, &ty, 24),
        );
        assert_eq!(a.feats.len(), p.features());
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
}
