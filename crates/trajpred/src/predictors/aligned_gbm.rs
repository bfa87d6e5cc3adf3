//! `aligned-gbm`: gradient-boosted trees that correct the last velocity, learned in the
//! heading-aligned frame of `aligned-ridge` (issue 27).

use super::aligned_features::{Base, Layout, Origin, base_said, forecast_at, grid_times};
use super::fitted::At;
use super::trees::Ensemble;
use super::{horizontal_axes as xy, invalid};
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
    /// The features the trees see.
    fn layout(&self) -> Layout {
        Layout {
            lags: self.lags,
            window: self.window,
            shape: self.shape_features,
        }
    }

    /// Features per origin.
    fn features(&self) -> usize {
        self.layout().count()
    }

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
/// `tau` minus the base's ([`Base`]: the last velocity's or none), in the aligned frame,
/// divided by `tau / (s delta)` (the correction per unit of the time ahead, on the window's
/// time grid).
fn samples(p: &AlignedGbmParams, base: Base, tr: &Trajectory, s: usize, into: &mut Samples) {
    let t = tr.times();
    let (x, y) = xy(tr);
    for o in p.lags..tr.len().saturating_sub(s) {
        let org = Origin::new(&p.layout(), t, x, &y, o);
        let tau = t[o + s] - t[o];
        let d = (x[o + s] - x[o], y[o + s] - y[o]);
        let r = org.u.rotate(d);
        let scale = s as f64 * org.delta / tau;
        let b = base.at(&org, tau);
        into.along.push((r.0 - b.0) * scale);
        into.across.push((r.1 - b.1) * scale);
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
    /// What the corrections are added to, chosen at fit time.
    base: Base,
    /// The training mean errors of the two bases when fitted here (velocity, position).
    base_errors: Option<(f64, f64)>,
}

impl AlignedGbm {
    /// An unfitted model; errors for bad parameters, naming the first.
    pub fn new(params: AlignedGbmParams) -> Result<Self> {
        params.validate()?;
        Ok(AlignedGbm {
            params,
            models: Vec::new(),
            samples: Vec::new(),
            base: Base::Velocity,
            base_errors: None,
        })
    }

    /// The column-major features and targets of step `s`, at most `max_samples` origins
    /// (each twice with [`AlignedGbmParams::mirror`]).
    fn step_data(&self, train: &[Trajectory], s: usize) -> (Vec<f64>, usize, [Vec<f64>; 2]) {
        let p = &self.params;
        let mut all = Samples::default();
        for tr in train {
            samples(p, self.base, tr, s, &mut all);
        }
        let n = all.rows.len();
        let keep: Vec<usize> = if n > p.max_samples {
            (0..p.max_samples).map(|i| i * n / p.max_samples).collect()
        } else {
            (0..n).collect()
        };
        let copies: &[f64] = if p.mirror { &[1.0, -1.0] } else { &[1.0] };
        let signs = p.layout().mirror_signs();
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
        let (base, ev, ep) = Base::choose(train, self.params.lags, self.params.horizons);
        self.base = base;
        self.base_errors = Some((ev, ep));
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
        self.forecast_times(history, &grid_times(history, self.params.window, horizon))
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        check_forecast_args(history, times.len(), self.min_history())?;
        if self.models.is_empty() {
            return Err(Error::NotFitted {
                method: NAME.into(),
            });
        }
        super::check_fitted_times(NAME, self.models.len(), history, times)?;
        forecast_at((&self.params.layout(), self.base), history, times, |org| {
            Ok(self
                .models
                .iter()
                .take(times.len())
                .map(|[along, across]| (along.predict(&org.feats), across.predict(&org.feats)))
                .collect())
        })
    }

    fn min_history(&self) -> usize {
        self.params.lags + 1
    }

    /// `{"lags", "window", "horizons", "shape_features"}` (checked against this predictor's
    /// parameters on loading), `"base": "position"` when the corrections are added to the
    /// last position, and `"models"`: per step, the along- and across-track tree ensembles
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
        Ok(p.layout()
            .saved(p.horizons, self.base, "models", models.into()))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let root = At::root(NAME, params);
        let p = &self.params;
        let (models, base) = p.layout().read_saved(p.horizons, &root, "models")?;
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
        self.base = base;
        self.base_errors = None;
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
        // (loaded parameters do not say how many origins trained them)
        let origins = if self.samples.is_empty() {
            "loaded from saved parameters".to_string()
        } else {
            format!("training origins per step {:?}", self.samples)
        };
        Some(format!(
            "trees per step (along+across) {}; {origins}{}",
            trees.join(", "),
            base_said(self.base, self.base_errors)
        ))
    }
}
