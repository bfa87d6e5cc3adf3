//! Group sparse coding ([`Gsc`]) and MSTPM-GSKF ([`Gskf`]): the multi-step predictor of the
//! GSKF paper (`docs/papers.md` A.3-A.4), per axis.
//!
//! GSC: for each axis, the T horizon models `x_hat_{i+t} = A[t] . w_i + b[t]` fitted by LAR on
//! the Hankel designs of the training series (`trajpred-sparse`).
//!
//! GSKF: the GSC prediction `X_hat^0(i)` is the prior `X(k|k-1)` of an improved one-step-ahead
//! Kalman filter (`trajpred_kalman::Ikf`) whose state is the vector of the T predicted values,
//! `H = I_T`, corrected with the previous residual (eq. 12-13):
//! `X(k|k) = X(k|k-1) + P(k|k-1) S(k-1)^-1 V(k-1)`. The residual of horizon row `t` at origin
//! `i` is the most recent one observable at time `i`: `V_t = x_i - X_hat^0_t(i - t)`. Nothing
//! after the origin is used.

use super::fitted::{At, exact, exact_matrix, exact_vec};
use super::invalid;
use nalgebra::{DMatrix, DVector, Dyn};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use trajpred_core::{
    Error, Forecast, Gaussian, Predictor, Result, Trajectory, check_forecast_args,
};
use trajpred_sparse::{GroupSparseCoder, Lars};

mod axis;
mod correct;
mod diverged;
mod gain;
mod steps;

use axis::{AxisFilter, errors, in_sample_error};

pub use diverged::Diverged;

/// Parameters of [`Gsc`] and [`Gskf`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GskfParams {
    /// Window length m (the paper: 2..8, 6 for the multi-step tables).
    pub window: usize,
    /// Number of horizons T predicted at once (the paper: 1..6). Forecasts may ask for up to T
    /// steps.
    pub horizons: usize,
    /// Process noise `Q = q I`; `None` chooses q on the training series (see
    /// `docs/gskf.md`). Ignored by [`Gsc`].
    pub q: Option<f64>,
    /// The multipliers of the mean GSC residual variance tried when `q` is `None`.
    pub q_grid: Vec<f64>,
    /// When fitted on trajectories of several groups (`fit_grouped`), stop each axis's LAR
    /// paths where held-out groups say (the full path or 1 to m - 1 steps, by 5-fold
    /// cross-validation by group; see `docs/gskf.md`). One group, or `false`: the full path.
    pub choose_steps: bool,
    /// Fit and forecast each axis in the frame of each window's last value
    /// ([`trajpred_sparse::GscParams::relative`]; default `false`, the paper's absolute
    /// values). The frame makes a forecast move with the track (a shifted history gives a
    /// shifted forecast), which absolute values give only where each row of `A` sums to 1;
    /// see `docs/gskf.md`. Saved with the fitted parameters and checked on loading.
    #[serde(default)]
    pub relative: bool,
    /// With `choose_steps` and trajectories of several groups, each axis also chooses its
    /// frame, absolute values or the frame of each window's last value, on the same held-out
    /// groups as its LAR steps (ties go to absolute values, the paper's); `relative` is then
    /// only the frame of a fit without groups. Default `true` (since 2026-12-07; see
    /// `docs/gskf.md`); parameters saved before it read back as `false`.
    #[serde(default)]
    pub choose_frame: bool,
    /// When `q` is `None`: the residual lags of the gains fitted to the training series that
    /// are tried beside the IKF's (a gain fitted by least squares on the residual vectors of
    /// the `lags + 1` most recent origins; see `docs/gskf.md`). Chosen on held-out groups with
    /// several groups, else on the last quarter of the training origins against the IKF with
    /// the `q` chosen in sample. Empty: the paper's IKF only. Default `[0, 1, 2, 4]` (since
    /// 2026-12-07); parameters saved before it read back as empty. Each at most 64. The gains
    /// with fewer lags are fitted beside the chosen one, and a history shorter than
    /// `window + horizons + lags` is corrected with the one of as many lags as it has the
    /// points for.
    #[serde(default)]
    pub gain_lags: Vec<usize>,
}

impl Default for GskfParams {
    fn default() -> Self {
        GskfParams {
            window: 6,
            horizons: 6,
            q: None,
            q_grid: vec![1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0],
            choose_steps: true,
            relative: false,
            choose_frame: true,
            gain_lags: vec![0, 1, 2, 4],
        }
    }
}

impl GskfParams {
    fn validate(&self) -> Result<()> {
        if self.window == 0 {
            return Err(invalid("window", "m must be at least 1, got 0"));
        }
        if self.horizons == 0 {
            return Err(invalid("horizons", "T must be at least 1, got 0"));
        }
        if let Some(q) = self.q
            && !(q.is_finite() && q >= 0.0)
        {
            return Err(invalid(
                "q",
                format!("must be finite and non-negative, got {q}"),
            ));
        }
        if let Some(&l) = self.gain_lags.iter().find(|&&l| l > gain::MAX_LAGS) {
            return Err(invalid(
                "gain_lags",
                format!("each must be at most {}, got {l}", gain::MAX_LAGS),
            ));
        }
        if self.q.is_none()
            && (self.q_grid.is_empty() || self.q_grid.iter().any(|g| !(g.is_finite() && *g >= 0.0)))
        {
            return Err(invalid(
                "q_grid",
                format!(
                    "needs at least one multiplier, each finite and non-negative, got {:?}",
                    self.q_grid
                ),
            ));
        }
        Ok(())
    }
}

fn sparse_error(e: trajpred_sparse::Error) -> Error {
    Error::from_crate("gsc", e)
}

fn kalman_error(e: trajpred_kalman::KalmanError) -> Error {
    Error::from_crate("gskf", e)
}

/// The training series of axis `a`: one per trajectory long enough for the GSC designs.
fn axis_series(train: &[Trajectory], axis: usize, needed: usize) -> Vec<&[f64]> {
    train
        .iter()
        .filter(|t| t.len() >= needed)
        .map(|t| t.axis(axis))
        .collect()
}

/// The GSC of one axis in `fit`'s frame; `fit.steps` stops every horizon's LAR path after
/// that many steps (`None`: the full path, whose end is least squares).
fn fit_gsc(
    params: &GskfParams,
    series: &[&[f64]],
    fit: steps::AxisFit,
) -> Result<GroupSparseCoder> {
    let mut gsc = GroupSparseCoder::params(params.window, params.horizons).relative(fit.relative);
    if let Some(s) = fit.steps {
        gsc = gsc.lars(Lars::params().max_steps(s));
    }
    gsc.fit_many(series).map_err(sparse_error)
}

/// The GSC prediction made at origin `i` (window ending at index `i`) of `x`.
fn gsc_at(gsc: &GroupSparseCoder, x: &[f64], i: usize) -> Result<Vec<f64>> {
    let m = gsc.window();
    gsc.predict(&x[i + 1 - m..=i]).map_err(sparse_error)
}

/// The residual vector `V` at origin `i`: `V_t = x_i - X_hat^0_t(i - t)`, `t = 1..=T`.
fn residuals(gsc: &GroupSparseCoder, x: &[f64], i: usize) -> Result<DVector<f64>> {
    let t_max = gsc.horizons();
    let mut v = DVector::zeros(t_max);
    for t in 1..=t_max {
        v[t - 1] = x[i] - gsc_at(gsc, x, i - t)?[t - 1];
    }
    Ok(v)
}

/// The fitted parameters of one axis's coder: `A` (T x m, row by row), `b` and the residual
/// variances (length T).
fn coder_json(gsc: &GroupSparseCoder) -> serde_json::Map<String, serde_json::Value> {
    let mut m = serde_json::Map::new();
    m.insert("a".into(), exact_matrix(gsc.coefficients()));
    m.insert("b".into(), exact_vec(gsc.intercepts().iter()));
    m.insert(
        "residual_variances".into(),
        exact_vec(gsc.residual_variances()),
    );
    if gsc.is_relative() {
        // (only then: files saved before the frame existed stay valid)
        m.insert("relative".into(), true.into());
    }
    m
}

/// The fields `keys` of a saved axis and its frame: a `"relative": true` may stand beside
/// them, and must agree with `params.relative` unless `params.choose_frame` (a coder read in
/// the wrong frame would forecast wrongly).
fn axis_fields<'a, const N: usize>(
    params: &GskfParams,
    ax: &At<'a>,
    keys: [&str; N],
    optional: &[&str],
) -> Result<([At<'a>; N], bool)> {
    let saved = match ax.value().get("relative") {
        None => false,
        Some(v) => v
            .as_bool()
            .ok_or_else(|| ax.error("`relative`: expected true or false"))?,
    };
    if saved != params.relative && !params.choose_frame {
        let frame = |rel: bool| {
            if rel {
                "the frame of each window's last value"
            } else {
                "absolute values"
            }
        };
        return Err(ax.error(format!(
            "fitted in {}, but this method is set to {} (`relative` = {})",
            frame(saved),
            frame(params.relative),
            params.relative
        )));
    }
    let allowed: Vec<&str> = optional.iter().copied().chain(["relative"]).collect();
    Ok((ax.fields_and(keys, &allowed)?, saved))
}

/// Reads a coder back from its fields `a`, `b`, `residual_variances`, with the shape the
/// options give (T x m).
fn coder_from(
    params: &GskfParams,
    (a, b, rv): (&At, &At, &At),
    relative: bool,
) -> Result<GroupSparseCoder> {
    let t = params.horizons;
    let a_m = a.matrix(t, params.window)?;
    let b_v = b.vector(t, At::f64)?;
    let rv_v = rv.vector(t, |x| x.f64_min(0.0, false))?;
    GroupSparseCoder::from_parts(a_m, b_v, rv_v.as_slice().to_vec())
        .map(|g| g.in_relative_frame(relative))
        .map_err(|e| a.error(e.to_string()))
}

/// The axes of fitted parameters `{"axes": [...]}`, one per axis (1 to 3).
fn axes_of<'a>(method: &'a str, params: &'a serde_json::Value) -> Result<Vec<At<'a>>> {
    let [axes] = At::root(method, params).fields(["axes"])?;
    axes.items(None, trajpred_core::MAX_AXES)
}

fn not_fitted(method: &str) -> Error {
    Error::NotFitted {
        method: method.into(),
    }
}

/// Group sparse coding alone (`docs/papers.md` A.3): per axis, `X_hat = A w + b`.
///
/// ```
/// use trajpred::predictors::{Gsc, GskfParams};
/// use trajpred_core::{Predictor, Trajectory};
/// let x: Vec<f64> = (0..300).map(|i| (0.1 * i as f64).sin()).collect();
/// let tr = Trajectory::uniform(0.0, 1.0, vec![x.clone()])?;
/// let mut p = Gsc::new(GskfParams { window: 4, horizons: 3, ..Default::default() })?;
/// p.fit(&[tr.prefix(250)?])?;
/// let f = p.forecast(&tr.prefix(260)?, 3)?;
/// assert!((f.step(3)[0] - x[262]).abs() < 1e-8); // a sinusoid is an exact linear recurrence
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Gsc {
    params: GskfParams,
    #[serde(skip)]
    axes: Vec<GroupSparseCoder>,
    #[serde(skip)]
    summary: Option<String>,
}

impl Gsc {
    /// A validated, unfitted predictor.
    pub fn new(params: GskfParams) -> Result<Self> {
        params.validate()?;
        Ok(Gsc {
            params,
            axes: Vec::new(),
            summary: None,
        })
    }

    /// The fitted coder of each axis.
    pub fn coders(&self) -> &[GroupSparseCoder] {
        &self.axes
    }
}

/// Checks a forecast's arguments against the fitted axes ([`check_history`]; `sizes` is the
/// shortest history and the fitted horizons), then forecasts every axis from the end of
/// `history` with `forecast_axis(model, that axis's values, index of the last point)`.
fn forecast_axes<A, R>(
    history: &Trajectory,
    horizon: usize,
    (needed, horizons): (usize, usize),
    axes: &[A],
    method: &str,
    forecast_axis: impl Fn(&A, &[f64], usize) -> Result<R>,
) -> Result<Vec<R>> {
    check_history(history, horizon, needed, horizons, axes.len(), method)?;
    let i = history.len() - 1;
    axes.iter()
        .enumerate()
        .map(|(a, m)| forecast_axis(m, history.axis(a), i))
        .collect()
}

fn check_history(
    history: &Trajectory,
    horizon: usize,
    needed: usize,
    horizons: usize,
    dim: usize,
    method: &str,
) -> Result<()> {
    check_forecast_args(history, horizon, needed)?;
    if dim == 0 {
        return Err(Error::NotFitted {
            method: method.into(),
        });
    }
    if horizon > horizons {
        return Err(invalid(
            "horizon",
            format!("{method} was fitted for T = {horizons} horizons, asked for {horizon}"),
        ));
    }
    if history.dim() != dim {
        return Err(Error::DimensionMismatch {
            what: "history vs fitted axes",
            expected: dim,
            got: history.dim(),
        });
    }
    Ok(())
}

/// Every axis's GSC; `fits[a]` gives axis `a`'s frame and where its LAR paths stop (the full path in `params.relative`'s frame where `fits` is
/// shorter).
fn fit_axes(
    params: &GskfParams,
    train: &[Trajectory],
    fits: &[steps::AxisFit],
) -> Result<Vec<GroupSparseCoder>> {
    let dim = train
        .first()
        .ok_or(Error::Empty {
            what: "training trajectories",
        })?
        .dim();
    if let Some(bad) = train.iter().find(|t| t.dim() != dim) {
        return Err(Error::DimensionMismatch {
            what: "training trajectories",
            expected: dim,
            got: bad.dim(),
        });
    }
    let needed = params.window + params.horizons + 1;
    (0..dim)
        .map(|a| {
            let fit = fits.get(a).copied().unwrap_or(steps::AxisFit {
                relative: params.relative,
                steps: None,
            });
            fit_gsc(params, &axis_series(train, a, needed), fit)
        })
        .collect()
}

impl Predictor for Gsc {
    fn name(&self) -> &str {
        "gsc"
    }

    /// The full LAR path on every axis (no groups to hold out).
    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        self.axes = fit_axes(&self.params, train, &[])?;
        self.summary = None;
        Ok(())
    }

    /// With trajectories of several groups and `choose_steps`, each axis's LAR paths stop
    /// where held-out groups say (see `docs/gskf.md`); otherwise as [`Predictor::fit`].
    fn fit_grouped(&mut self, train: &[Trajectory], groups: &[usize]) -> Result<()> {
        super::check_groups(train, groups)?;
        if !self.params.choose_steps || distinct(groups) < 2 {
            return self.fit(train);
        }
        let (steps, said) = steps::choose_steps(&self.params, train, groups)?;
        self.axes = fit_axes(&self.params, train, &steps)?;
        self.summary = Some(said);
        Ok(())
    }

    fn fitted_summary(&self) -> Option<String> {
        self.summary.clone()
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        let sizes = (self.min_history(), self.params.horizons);
        let per_axis = forecast_axes(history, horizon, sizes, &self.axes, "gsc", gsc_at)?;
        let steps: Vec<Vec<f64>> = (0..horizon)
            .map(|k| per_axis.iter().map(|p| p[k]).collect())
            .collect();
        Forecast::new(history.dim(), steps)
    }

    fn min_history(&self) -> usize {
        self.params.window
    }

    /// `{"axes": [{"a", "b", "residual_variances"}, ...]}`, one coder per axis.
    fn fitted_params(&self) -> Result<serde_json::Value> {
        if self.axes.is_empty() {
            return Err(not_fitted("gsc"));
        }
        let axes = self.axes.iter().map(|g| coder_json(g).into()).collect();
        Ok(serde_json::json!({ "axes": serde_json::Value::Array(axes) }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let axes = axes_of("gsc", params)?
            .iter()
            .map(|ax| {
                let ([a, b, rv], rel) =
                    axis_fields(&self.params, ax, ["a", "b", "residual_variances"], &[])?;
                coder_from(&self.params, (&a, &b, &rv), rel)
            })
            .collect::<Result<_>>()?;
        self.axes = axes;
        Ok(())
    }
}

/// MSTPM-GSKF (`docs/papers.md` A.4): GSC corrected by the improved one-step-ahead Kalman filter.
///
/// `fit` fits the GSC per axis, sets `R` to the diagonal of the GSC training residual
/// variances, and `Q = q I` with `q` chosen on the training series when not given. The
/// forecast carries the per-step covariance (diagonal across axes).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Gskf {
    params: GskfParams,
    #[serde(skip)]
    axes: Vec<AxisFilter>,
    #[serde(skip)]
    summary: Option<String>,
}

impl Gskf {
    /// A validated, unfitted predictor.
    pub fn new(params: GskfParams) -> Result<Self> {
        params.validate()?;
        Ok(Gskf {
            params,
            axes: Vec::new(),
            summary: None,
        })
    }

    /// The q chosen (or given) for each axis, once fitted; `None` where the Kalman
    /// correction is off (the cross-validation found no `q` that beats the plain GSC) or
    /// its gain is fitted to the data instead ([`Gskf::fitted_gain_lags`]).
    pub fn process_noise(&self) -> Vec<Option<f64>> {
        self.axes
            .iter()
            .map(|a| (a.correct && a.gain.is_none()).then_some(a.q))
            .collect()
    }

    /// For each axis, once fitted, the residual lags of its fitted gain (see
    /// [`GskfParams::gain_lags`]); `None` where the gain is the IKF's or there is no
    /// correction.
    pub fn fitted_gain_lags(&self) -> Vec<Option<usize>> {
        self.axes
            .iter()
            .map(|a| a.gain.as_ref().map(|g| g.lags()))
            .collect()
    }

    /// Chooses per axis, on the training series, the `q` of the grid with the lowest
    /// in-sample mean squared error (one group: nothing to hold out), then between that IKF
    /// and the gains fitted with `gain_lags` on the last quarter of the training origins
    /// ([`gain::choose_in_time`]). Returns the filters and what was chosen, in words.
    fn fit_in_sample(&self, train: &[Trajectory]) -> Result<(Vec<AxisFilter>, String)> {
        let coders = fit_axes(&self.params, train, &[])?;
        let needed = self.params.window + self.params.horizons + 1;
        let mut said = String::new();
        let mut axes = Vec::with_capacity(coders.len());
        for (a, gsc) in coders.into_iter().enumerate() {
            let scale = mean_residual_variance(&gsc);
            let Some(q) = self.params.q else {
                let series = axis_series(train, a, needed);
                let mut best: Option<(f64, AxisFilter)> = None;
                for &g in &self.params.q_grid {
                    let Ok(f) = AxisFilter::new(gsc.clone(), (g * scale).max(1e-300)) else {
                        continue;
                    };
                    let e = in_sample_error(&f, &series)?;
                    if best.as_ref().is_none_or(|(b, _)| e < *b) {
                        best = Some((e, f));
                    }
                }
                let riccati = best.map(|(_, f)| f).ok_or(Error::NotPositiveDefinite {
                    what: "GSKF covariance recursion for every q of the grid",
                })?;
                let (f, why) = gain::choose_in_time(riccati, &series, &self.params.gain_lags)?;
                if !why.is_empty() {
                    let _ = write!(said, "{}axis {a}: {why}", if a > 0 { "; " } else { "" });
                }
                axes.push(f);
                continue;
            };
            axes.push(AxisFilter::new(gsc, q)?);
        }
        Ok((axes, said))
    }
}

/// Folds of [`Gskf`]'s and [`Gsc`]'s cross-validations by group.
const CV_FOLDS: usize = 5;

/// How many different groups `groups` holds.
fn distinct(groups: &[usize]) -> usize {
    let mut g = groups.to_vec();
    g.sort_unstable();
    g.dedup();
    g.len()
}

/// The mean of a coder's per-horizon residual variances, the unit of `q`.
fn mean_residual_variance(gsc: &GroupSparseCoder) -> f64 {
    gsc.residual_variances().iter().sum::<f64>() / gsc.residual_variances().len() as f64
}

impl Predictor for Gskf {
    fn name(&self) -> &str {
        "gskf"
    }

    /// Every trajectory its own group (see [`Predictor::fit_grouped`]).
    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        self.fit_grouped(train, &super::own_groups(train))
    }

    /// With `q` given, or fewer than two groups, `q` is chosen from the grid by the in-sample
    /// error on the training series; otherwise per axis between the plain GSC and each `q`
    /// of the grid by cross-validation by group (see `docs/gskf.md`).
    fn fit_grouped(&mut self, train: &[Trajectory], groups: &[usize]) -> Result<()> {
        super::check_groups(train, groups)?;
        self.axes.clear();
        self.summary = None;
        if self.params.q.is_some() || distinct(groups) < 2 {
            let (axes, said) = self.fit_in_sample(train)?;
            self.axes = axes;
            self.summary = (!said.is_empty()).then_some(said);
        } else {
            let (steps, steps_said) = match self.params.choose_steps {
                true => steps::choose_steps(&self.params, train, groups)?,
                false => (Vec::new(), "full LAR paths".to_string()),
            };
            let (axes, said) = correct::choose(&self.params, train, groups, &steps)?;
            self.axes = axes;
            self.summary = Some(format!("{said}; {steps_said}"));
        }
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        let sizes = (self.min_history(), self.params.horizons);
        let per_axis: Vec<Gaussian<f64, Dyn>> =
            forecast_axes(history, horizon, sizes, &self.axes, "gskf", |f, x, i| {
                f.predict(x, i)
            })?;
        let steps: Vec<Vec<f64>> = (0..horizon)
            .map(|k| per_axis.iter().map(|g| g.mean[k]).collect())
            .collect();
        let covs = (0..horizon)
            .map(|k| {
                DMatrix::from_diagonal(&DVector::from_iterator(
                    per_axis.len(),
                    per_axis.iter().map(|g| g.covariance[(k, k)]),
                ))
            })
            .collect();
        Forecast::new(history.dim(), steps)?.with_covariances(covs)
    }

    fn min_history(&self) -> usize {
        // the residual of horizon T needs the prediction made T steps ago (a fitted gain
        // with lags uses the gain of fewer lags on shorter histories)
        self.params.window + self.params.horizons
    }

    fn fitted_summary(&self) -> Option<String> {
        (!self.axes.is_empty()).then(|| {
            let q: Vec<String> = self
                .axes
                .iter()
                .map(|a| match (a.correct, &a.gain) {
                    (true, Some(g)) => format!("fitted gain ({} lags)", g.lags()),
                    (true, None) => format!("{:.3e}", a.q),
                    (false, _) => "off".into(),
                })
                .collect();
            let mut s = format!("q per axis = [{}]", q.join(", "));
            if let Some(said) = &self.summary {
                let _ = write!(s, " ({said})");
            }
            s
        })
    }

    /// `{"axes": [{"a", "b", "residual_variances", "q", "correct"}, ...]}`: per axis the GSC,
    /// the process noise and whether the Kalman correction is on, and where the gain is
    /// fitted, `"gain": {"lags", "k", "variances"}` (for each number of lags `l` from 0 to
    /// `lags`, the gain `T x T (l + 1)` row by row and its residual variances); `R` and the
    /// converged covariances follow from them (recomputed on loading, by the same code, so to
    /// the same bits).
    fn fitted_params(&self) -> Result<serde_json::Value> {
        if self.axes.is_empty() {
            return Err(not_fitted("gskf"));
        }
        let axes = self
            .axes
            .iter()
            .map(|f| {
                let mut m = coder_json(&f.gsc);
                m.insert("q".into(), exact(f.q));
                m.insert("correct".into(), f.correct.into());
                if let Some(g) = &f.gain {
                    m.insert("gain".into(), gain::to_json(g));
                }
                serde_json::Value::Object(m)
            })
            .collect();
        Ok(serde_json::json!({ "axes": serde_json::Value::Array(axes) }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let axes = axes_of("gskf", params)?
            .iter()
            .map(|ax| {
                let ([a, b, rv, q, correct], rel) = axis_fields(
                    &self.params,
                    ax,
                    ["a", "b", "residual_variances", "q", "correct"],
                    &["gain"],
                )?;
                let gsc = coder_from(&self.params, (&a, &b, &rv), rel)?;
                let on = correct
                    .value()
                    .as_bool()
                    .ok_or_else(|| correct.error("expected true or false"))?;
                let q = q.f64_min(0.0, false)?;
                if let Some(g) = ax.optional("gain") {
                    if !on {
                        return Err(g.error("a fitted gain on an axis whose correction is off"));
                    }
                    AxisFilter::fitted(gsc, gain::from_json(&g, self.params.horizons)?)
                } else if on {
                    AxisFilter::new(gsc, q).map_err(|e| ax.error(e.to_string()))
                } else {
                    AxisFilter::plain(gsc)
                }
            })
            .collect::<Result<_>>()?;
        self.axes = axes;
        self.summary = None;
        Ok(())
    }
}
