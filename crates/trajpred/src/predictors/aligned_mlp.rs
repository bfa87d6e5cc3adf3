//! `aligned-mlp`: a network that corrects the last velocity, learned in the heading-aligned
//! frame of `aligned-gbm` from the same features, fitted to the mean distance (issue 27).

use super::aligned_features::{Base, Layout, Origin, base_said, forecast_at, grid_times};
use super::fitted::{At, exact_vec};
use super::{horizontal_axes as xy, invalid};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use trajpred_core::{Error, Forecast, Predictor, Result, Trajectory, check_forecast_args};
use trajpred_neural::{Dense, DistanceMlp, DistanceMlpConfig, PlanarRows};

const NAME: &str = "aligned-mlp";
/// The most layers and the widest layer a saved network may have (checked before anything
/// is allocated).
const MAX_LAYERS: usize = 16;
const MAX_WIDTH: f64 = 4096.0;

/// Parameters of [`AlignedMlp`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlignedMlpParams {
    /// Past legs described to the network (`k`; the history needs `k + 1` points).
    pub lags: usize,
    /// Points over which the mean interval, the mean velocity and the longest line are
    /// taken (fewer if the history is shorter).
    pub window: usize,
    /// Steps the network answers (the longest forecast).
    pub horizons: usize,
    /// Also describe the window's shape, as
    /// [`AlignedGbmParams::shape_features`](super::AlignedGbmParams::shape_features).
    pub shape_features: bool,
    /// At most this many training origins (an even stride through them when there are
    /// more), which bounds the time a fit takes.
    pub max_samples: usize,
    /// The network and its training.
    pub network: DistanceMlpConfig,
    /// Networks trained with seeds `network.seed`, `network.seed + 1`, ... (in parallel),
    /// whose corrections are averaged.
    pub members: usize,
}

impl Default for AlignedMlpParams {
    /// `aligned-gbm`'s features (8 lags, a window of 20, the shape) for 6 steps, at most
    /// 400,000 origins, and 4 members of [`DistanceMlpConfig::default`]: two hidden layers
    /// of 256, 20 epochs of 1024 origins, Adam from 3e-3 annealed to 0 along a cosine
    /// (chosen by cross-validation by user on GeoLife's training users,
    /// `docs/accuracy.md`).
    fn default() -> Self {
        AlignedMlpParams {
            lags: 8,
            window: 20,
            horizons: 6,
            shape_features: true,
            max_samples: 400_000,
            network: DistanceMlpConfig::default(),
            members: 4,
        }
    }
}

impl AlignedMlpParams {
    fn layout(&self) -> Layout {
        Layout {
            lags: self.lags,
            window: self.window,
            shape: self.shape_features,
        }
    }

    fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("lags", self.lags),
            ("horizons", self.horizons),
            ("max_samples", self.max_samples),
            ("members", self.members),
        ] {
            if v == 0 {
                return Err(invalid(name, "must be at least 1, got 0"));
            }
        }
        if self.window < 2 {
            return Err(invalid(
                "window",
                format!("must be at least 2, got {}", self.window),
            ));
        }
        self.network
            .validate()
            .map_err(|e| Error::from_crate(NAME.to_string(), e))
    }
}

/// A network that corrects the last velocity in the heading-aligned frame (`aligned-mlp` in
/// the registry).
///
/// The same description of the history as [`AlignedGbm`](super::AlignedGbm)'s (the last
/// speed, the mean interval `delta`, the last legs, the mean velocity and the window's
/// shape, all in the frame where the last velocity `v0` points along +x) goes through a
/// ReLU network ([`DistanceMlp`]) to one correction `c_s` per step, used as the trees' are:
///
/// ```text
/// d(tau) = R' [ tau v0' + (tau / (s delta)) c_s(features) ]
/// ```
///
/// All steps come out of one network, trained on the training origins by the mean over
/// steps of the distance between the forecast and the fix: the leaderboard's own measure,
/// so no clipping or reweighting is needed. Weights are seeded
/// ([`DistanceMlpConfig::seed`]): the same data and seed give the same network.
///
/// ```
/// use trajpred::predictors::{AlignedMlp, AlignedMlpParams};
/// use trajpred_core::{Predictor, Trajectory};
/// // tracks that brake: 10 m/s, losing 0.2 m/s every second
/// let track = |k: usize| -> Result<Trajectory, trajpred_core::Error> {
///     let x = (0..40).map(|i| { let t = i as f64; 10.0 * t - 0.1 * t * t + k as f64 }).collect();
///     Trajectory::uniform(0.0, 1.0, vec![x, vec![0.0; 40]])
/// };
/// let train: Vec<Trajectory> = (0..20).map(track).collect::<Result<_, _>>()?;
/// let mut p = AlignedMlpParams::default();
/// p.network.batch_size = 32;
/// p.network.epochs = 40;
/// let mut m = AlignedMlp::new(p)?;
/// m.fit(&train)?;
/// let hist = track(3)?.prefix(21)?; // origin at t = 20 s, speed there 6 m/s
/// let f = m.forecast_times(&hist, &[21.0, 22.0, 23.0, 24.0, 25.0])?;
/// let truth = 10.0 * 25.0 - 0.1 * 625.0 + 3.0;
/// let last_velocity = (10.0 * 20.0 - 0.1 * 400.0 + 3.0) + 5.0 * 6.1; // cv-time, 2.5 m off
/// assert!((f.step(5)[0] - truth).abs() < 0.5, "{}", f.step(5)[0]);
/// assert!((last_velocity - truth).abs() > 2.0);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub struct AlignedMlp {
    params: AlignedMlpParams,
    /// The members; empty before fitting.
    model: Vec<DistanceMlp>,
    /// Training origins of the last fit, for the summary.
    samples: usize,
    /// What the corrections are added to, chosen at fit time.
    base: Base,
    /// The training mean errors of the two bases when fitted here (velocity, position).
    base_errors: Option<(f64, f64)>,
}

impl AlignedMlp {
    /// An unfitted model; errors for bad parameters, naming the first.
    pub fn new(params: AlignedMlpParams) -> Result<Self> {
        params.validate()?;
        Ok(AlignedMlp {
            params,
            model: Vec::new(),
            samples: 0,
            base: Base::Velocity,
            base_errors: None,
        })
    }
}

/// Row-major training rows of every origin with `horizons` steps ahead inside its track:
/// the features, the targets (per step, the displacement at the step's time `tau` minus the
/// base's, `tau v0` or none, aligned) and the scales `tau / (s delta)`.
#[derive(Default)]
struct Rows {
    feats: Vec<f64>,
    targets: Vec<f64>,
    scales: Vec<f64>,
    n: usize,
}

impl Rows {
    fn push(&mut self, p: &AlignedMlpParams, base: Base, tr: &Trajectory) {
        let t = tr.times();
        let (x, y) = xy(tr);
        let layout = p.layout();
        for o in p.lags..tr.len().saturating_sub(p.horizons) {
            let org = Origin::new(&layout, t, x, &y, o);
            for s in 1..=p.horizons {
                let tau = t[o + s] - t[o];
                let r = org.u.rotate((x[o + s] - x[o], y[o + s] - y[o]));
                let b = base.at(&org, tau);
                self.targets.extend([r.0 - b.0, r.1 - b.1]);
                self.scales.push(tau / (s as f64 * org.delta));
            }
            self.feats.extend(org.feats);
            self.n += 1;
        }
    }

    /// At most `max` rows, an even stride through them.
    fn thin(self, max: usize, f: usize, h: usize) -> Rows {
        if self.n <= max {
            return self;
        }
        let mut out = Rows::default();
        for i in (0..max).map(|k| k * self.n / max) {
            out.feats.extend_from_slice(&self.feats[i * f..(i + 1) * f]);
            out.targets
                .extend_from_slice(&self.targets[i * 2 * h..(i + 1) * 2 * h]);
            out.scales
                .extend_from_slice(&self.scales[i * h..(i + 1) * h]);
            out.n += 1;
        }
        out
    }
}

impl Predictor for AlignedMlp {
    fn name(&self) -> &str {
        NAME
    }

    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        self.model.clear();
        let p = &self.params;
        let (base, ev, ep) = Base::choose(train, p.lags, p.horizons);
        let mut rows = Rows::default();
        for tr in train {
            rows.push(p, base, tr);
        }
        let (f, h) = (p.layout().count(), p.horizons);
        let rows = rows.thin(p.max_samples, f, h);
        if rows.n < 2 {
            return Err(Error::TooShort {
                what: "training origins with every step ahead",
                needed: 2,
                got: rows.n,
            });
        }
        let data = PlanarRows {
            features: f,
            rows: &rows.feats,
            pairs: h,
            targets: &rows.targets,
            scales: &rows.scales,
        };
        let model = (0..p.members as u64)
            .into_par_iter()
            .map(|k| {
                let cfg = DistanceMlpConfig {
                    seed: p.network.seed.wrapping_add(k),
                    ..p.network.clone()
                };
                DistanceMlp::fit(&cfg, data).map_err(|e| Error::from_crate(NAME.to_string(), e))
            })
            .collect::<Result<Vec<_>>>()?;
        self.model = model;
        self.samples = rows.n;
        self.base = base;
        self.base_errors = Some((ev, ep));
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        self.forecast_times(history, &grid_times(history, self.params.window, horizon))
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        check_forecast_args(history, times.len(), self.min_history())?;
        if self.model.is_empty() {
            return Err(Error::NotFitted {
                method: NAME.into(),
            });
        }
        super::check_fitted_times(NAME, self.params.horizons, history, times)?;
        forecast_at((&self.params.layout(), self.base), history, times, |org| {
            let mut c = vec![(0.0, 0.0); self.params.horizons];
            let share = 1.0 / self.model.len() as f64;
            for m in &self.model {
                let out = m
                    .predict(&org.feats)
                    .map_err(|e| Error::from_crate(NAME.to_string(), e))?;
                for (ci, o) in c.iter_mut().zip(out.chunks_exact(2)) {
                    ci.0 += share * o[0];
                    ci.1 += share * o[1];
                }
            }
            Ok(c)
        })
    }

    fn min_history(&self) -> usize {
        self.params.lags + 1
    }

    /// `{"lags", "window", "horizons", "shape_features"}` (checked against this predictor's
    /// parameters on loading), `"base": "position"` when the corrections are added to the
    /// last position, and `"networks"`: per member, the [`DistanceMlp`] (input centre
    /// and spread, the layers' weights and biases).
    fn fitted_params(&self) -> Result<serde_json::Value> {
        if self.model.is_empty() {
            return Err(Error::NotFitted {
                method: NAME.into(),
            });
        }
        let p = &self.params;
        let networks: Vec<serde_json::Value> = self
            .model
            .iter()
            .map(|m| {
                let layers: Vec<serde_json::Value> = m
                    .layers()
                    .iter()
                    .map(|l| {
                        serde_json::json!({
                            "inputs": l.inputs,
                            "outputs": l.outputs,
                            "weights": exact_vec(&l.w),
                            "biases": exact_vec(&l.b),
                        })
                    })
                    .collect();
                serde_json::json!({
                    "center": exact_vec(m.center()),
                    "spread": exact_vec(m.spread()),
                    "layers": layers,
                })
            })
            .collect();
        Ok(p.layout()
            .saved(p.horizons, self.base, "networks", networks.into()))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let root = At::root(NAME, params);
        let p = &self.params;
        let (networks, base) = p.layout().read_saved(p.horizons, &root, "networks")?;
        let (f, h) = (p.layout().count(), p.horizons);
        let model = networks
            .items(None, 1 << 10)?
            .iter()
            .map(|network| {
                let [center, spread, layers] = network.fields(["center", "spread", "layers"])?;
                let numbers = |at: &At<'_>, len: usize| -> Result<Vec<f64>> {
                    Ok(at.vector(len, At::f64)?.as_slice().to_vec())
                };
                let layers = layers
                    .items(None, MAX_LAYERS)?
                    .iter()
                    .map(|l| {
                        let [i, o, w, b] = l.fields(["inputs", "outputs", "weights", "biases"])?;
                        let count = |at: &At<'_>| -> Result<usize> {
                            let v = at.f64_min(1.0, false)?;
                            if v.fract() != 0.0 || v > MAX_WIDTH {
                                return Err(at.error(format!(
                                    "expected a whole number from 1 to {MAX_WIDTH}, got {v}"
                                )));
                            }
                            Ok(v as usize)
                        };
                        let (inputs, outputs) = (count(&i)?, count(&o)?);
                        Ok(Dense {
                            inputs,
                            outputs,
                            w: numbers(&w, inputs * outputs)?,
                            b: numbers(&b, outputs)?,
                        })
                    })
                    .collect::<Result<Vec<_>>>()?;
                DistanceMlp::from_parts(h, numbers(&center, f)?, numbers(&spread, f)?, layers)
                    .map_err(|e| network.error(e.to_string()))
            })
            .collect::<Result<Vec<_>>>()?;
        self.model = model;
        self.samples = 0;
        self.base = base;
        self.base_errors = None;
        Ok(())
    }

    fn fitted_summary(&self) -> Option<String> {
        let m = self.model.first()?;
        // (loaded parameters do not say how many origins trained them)
        let origins = match self.samples {
            0 => "loaded from saved parameters".to_string(),
            n => format!("{n} training origins"),
        };
        Some(format!(
            "{} network(s) of {} features to {} steps; {origins}{}",
            self.model.len(),
            m.features(),
            m.pairs(),
            base_said(self.base, self.base_errors)
        ))
    }
}
