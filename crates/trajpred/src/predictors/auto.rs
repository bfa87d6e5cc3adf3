//! `auto`: the method chosen per dataset by cross-validation by group on the training part
//! only (issue 27, "model selection without peeking").

use super::cv_cache::{self, FoldJob};
use super::fitted::At;
use super::invalid;
use crate::harness::{self, EvalConfig};
use crate::registry::{self, MethodOptions};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use trajpred_core::{Error, Forecast, Predictor, Result, Trajectory};

/// The candidates `auto` chooses from by default: every registered method that fits in
/// seconds (`aligned-gbm`: tens of seconds on GeoLife's training users; `aligned-mlp`, with
/// the `neural` feature, about 20 s) and needs no extra file (the particle filters and the
/// papers' networks are left out for
/// their run time, `kf-dynamic` and the 4-D variants for being equal to `naive-kf` or close
/// to it).
pub const DEFAULT_CANDIDATES: &[&str] = &[
    "cv-time",
    "last-position",
    "naive-kf",
    "kf-dynamic-literal",
    "kf-cv",
    "poly1",
    "gsc",
    "hmm",
    "aligned-ridge",
    "aligned-gbm",
    #[cfg(feature = "neural")]
    "aligned-mlp",
];

/// Parameters of [`Auto`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AutoParams {
    /// Registry names of the methods to choose from (not `auto` itself).
    pub candidates: Vec<String>,
    /// Folds of the cross-validation (at most the number of training groups is used).
    pub folds: usize,
    /// Seed of the deal of groups into folds.
    pub seed: u64,
    /// How each held-out fold is scored: the harness's rolling origin with these settings
    /// (the run's own history, horizon, stride and origins per segment).
    pub eval: EvalConfig,
}

impl Default for AutoParams {
    fn default() -> Self {
        AutoParams {
            candidates: DEFAULT_CANDIDATES.iter().map(|s| s.to_string()).collect(),
            folds: 5,
            seed: 0,
            eval: EvalConfig::default(),
        }
    }
}

/// One candidate's cross-validation result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateScore {
    /// Its registry name.
    pub method: String,
    /// Mean Euclidean error over every step of every forecast of each held-out fold (`NaN`
    /// for a fold with no origin).
    pub fold_errors: Vec<f64>,
    /// Forecasts made on each held-out fold.
    pub fold_forecasts: Vec<usize>,
    /// The error pooled over the folds (every forecast counts once); infinite for a
    /// candidate that failed.
    pub pooled_error: f64,
    /// Why the candidate was disqualified (a fit error, a refused forecast), if it was.
    pub failure: Option<String>,
}

/// The folds of a grouped training set: `fold[i]` is the fold of trajectory `i`, dealt by
/// group ([`harness::group_folds`]); the second value is the number of folds used,
/// `min(folds, groups)`. With a single group (one training user, say, or one inside a fold
/// of an outer cross-validation) the trajectories are dealt one by one instead
/// ([`cv_unit`] names which); needs at least two trajectories then.
pub(crate) fn fold_of_trajectories(
    groups: &[usize],
    folds: usize,
    seed: u64,
) -> Result<(Vec<usize>, usize)> {
    let mut labels = groups.to_vec();
    labels.sort_unstable();
    labels.dedup();
    if labels.len() < 2 {
        if groups.len() >= 2 {
            return fold_of_trajectories(&super::own_groups_of(groups.len()), folds, seed);
        }
        return Err(invalid(
            "train",
            format!(
                "cross-validation needs at least 2 training trajectories, got {}",
                groups.len()
            ),
        ));
    }
    let k = folds.min(labels.len());
    let of_label = harness::group_folds(labels.len(), k, seed)?;
    let fold = groups
        .iter()
        .map(|g| labels.binary_search(g).map_or(0, |i| of_label[i]))
        .collect();
    Ok((fold, k))
}

/// What [`fold_of_trajectories`] deals into folds for these groups, for summaries: `"group"`,
/// or `"trajectory (one training group)"`.
pub(crate) fn cv_unit(groups: &[usize]) -> &'static str {
    if groups.iter().any(|&g| g != groups[0]) {
        "group"
    } else {
        "trajectory (one training group)"
    }
}

/// The checks `auto` and `blend` share at construction: at least one candidate, at least 2
/// folds, valid evaluation settings, and every candidate known to the registry (built with
/// `options`) and not refused by `refuse` (which returns the reason).
pub(crate) fn check_selection(
    candidates: &[String],
    folds: usize,
    eval: &EvalConfig,
    options: &MethodOptions,
    refuse: impl Fn(&str) -> Option<String>,
) -> Result<()> {
    if candidates.is_empty() {
        return Err(invalid("candidates", "needs at least one method, got none"));
    }
    if folds < 2 {
        return Err(invalid("folds", format!("must be at least 2, got {folds}")));
    }
    eval.validate()?;
    for c in candidates {
        if let Some(why) = refuse(c) {
            return Err(invalid("candidates", why));
        }
        registry::build(c, options)?;
    }
    Ok(())
}

/// The training trajectories (and their groups) outside fold `f`, and those inside it.
pub(crate) fn fold_split(
    train: &[Trajectory],
    groups: &[usize],
    fold: &[usize],
    f: usize,
) -> (Vec<Trajectory>, Vec<usize>, Vec<Trajectory>) {
    let (mut fit, mut fit_groups, mut held) = (Vec::new(), Vec::new(), Vec::new());
    for ((t, &g), &k) in train.iter().zip(groups).zip(fold) {
        if k == f {
            held.push(t.clone());
        } else {
            fit.push(t.clone());
            fit_groups.push(g);
        }
    }
    (fit, fit_groups, held)
}

/// Chooses among candidate methods by cross-validation by group on the training data, then
/// forecasts with the winner refitted on all of it (`auto` in the registry).
///
/// At [`Predictor::fit_grouped`] the training trajectories' groups (users, vehicles) are
/// dealt into [`AutoParams::folds`] folds. For each fold every candidate is fitted on the
/// other folds and scored on the held-out one by the harness's rolling-origin mean
/// Euclidean error ([`harness::evaluate`] with [`AutoParams::eval`]), the number the
/// leaderboard reports. The candidate with the lowest error pooled over the folds wins (the
/// first listed on a tie; a candidate that fails to fit or refuses a forecast is out); it
/// is refitted on all the training data and answers every forecast.
/// [`Predictor::fitted_summary`] gives the choice and every fold score.
///
/// Only the trajectories given to `fit` are read, so the choice never depends on the test
/// data; it is deterministic for a seed. Plain [`Predictor::fit`] (no groups) treats every
/// trajectory as its own group. The forecast is the chosen method's, so `auto` is causal
/// when every candidate is.
///
/// ```
/// use trajpred::predictors::{Auto, AutoParams};
/// use trajpred::registry::MethodOptions;
/// use trajpred_core::{Predictor, Trajectory};
/// // straight tracks at 2 m/s: the last velocity is exact, a 5-point line too
/// let tracks: Vec<Trajectory> = (0..4)
///     .map(|k| Trajectory::uniform(0.0, 1.0, vec![(0..40).map(|i| (2 * i + k) as f64).collect()]))
///     .collect::<Result<_, _>>()?;
/// let params = AutoParams {
///     candidates: vec!["kf-dynamic-literal".into(), "cv-time".into()],
///     ..AutoParams::default()
/// };
/// let mut auto = Auto::new(params, MethodOptions::default())?;
/// auto.fit_grouped(&tracks, &[0, 0, 1, 2])?;
/// assert_eq!(auto.chosen(), Some("cv-time"));
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub struct Auto {
    params: AutoParams,
    options: MethodOptions,
    chosen: Option<(String, Box<dyn Predictor>)>,
    scores: Vec<CandidateScore>,
    folds_used: usize,
    /// What the folds were dealt by ([`cv_unit`]).
    cv_unit: &'static str,
}

impl std::fmt::Debug for Auto {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Auto")
            .field("params", &self.params)
            .field("chosen", &self.chosen())
            .field("scores", &self.scores)
            .finish()
    }
}

impl Auto {
    /// An unfitted `auto` over `params.candidates`, each built with `options`. Errors for
    /// no candidate, a candidate the registry does not know, `auto` among them, fewer than
    /// 2 folds or bad evaluation settings.
    pub fn new(params: AutoParams, options: MethodOptions) -> Result<Self> {
        check_selection(
            &params.candidates,
            params.folds,
            &params.eval,
            &options,
            |c| {
                (c == "auto").then(|| {
                    format!(
                        "`auto` cannot choose among itself, got {:?}",
                        params.candidates
                    )
                })
            },
        )?;
        Ok(Auto {
            params,
            options,
            chosen: None,
            scores: Vec::new(),
            folds_used: 0,
            cv_unit: "group",
        })
    }

    /// The chosen method's registry name, once fitted.
    pub fn chosen(&self) -> Option<&str> {
        self.chosen.as_ref().map(|(n, _)| n.as_str())
    }

    /// Every candidate's cross-validation result, in the candidates' order (empty before
    /// fitting).
    pub fn scores(&self) -> &[CandidateScore] {
        &self.scores
    }

    fn score(&self, name: &str, train: &[Trajectory], groups: &[usize]) -> Result<CandidateScore> {
        let build = || registry::build(name, &self.options);
        let (p, e) = (&self.params, &self.params.eval);
        let (fold, k) = fold_of_trajectories(groups, p.folds, p.seed)?;
        let job = FoldJob::new(name, &build, (train, groups), &fold, e, &self.options);
        score_folds(&job, k)
    }
}

/// The cross-validated score of one method: `build` makes it unfitted; for each of `folds`
/// folds of groups ([`harness::group_folds`] with `seed`) it is fitted on the other folds and
/// its forecasts on the held-out one ([`harness::collect_forecasts`] with `eval`, the
/// origins [`harness::evaluate`] scores) are scored by their mean Euclidean error, the
/// number the leaderboard reports. What [`Auto`] ranks its candidates by, public so that a
/// tuning script can score variants the same way.
pub fn cross_validate(
    name: &str,
    build: &dyn Fn() -> Result<Box<dyn Predictor>>,
    train: &[Trajectory],
    groups: &[usize],
    folds: usize,
    seed: u64,
    eval: &EvalConfig,
) -> Result<CandidateScore> {
    let (fold, k) = fold_of_trajectories(groups, folds, seed)?;
    let job = FoldJob {
        name,
        build,
        train,
        groups,
        fold: &fold,
        eval,
        shared: None,
    };
    score_folds(&job, k)
}

/// [`cross_validate`] over the `k` folds of `job`.
fn score_folds(job: &FoldJob<'_>, k: usize) -> Result<CandidateScore> {
    let dim = job.train.first().map_or(1, |t| t.dim());
    let mut s = CandidateScore {
        method: job.name.to_string(),
        fold_errors: Vec::with_capacity(k),
        fold_forecasts: Vec::with_capacity(k),
        pooled_error: f64::INFINITY,
        failure: None,
    };
    let (mut sum, mut n) = (0.0, 0usize);
    for f in 0..k {
        let got = cv_cache::fold_forecasts(job, f)?;
        let (forecast, truth) = match got.as_ref() {
            Ok(pair) => pair,
            Err(why) => {
                s.failure = Some(why.clone());
                return Ok(s);
            }
        };
        // one distance per forecast step
        let (fold_sum, steps) =
            forecast
                .chunks(dim)
                .zip(truth.chunks(dim))
                .fold((0.0, 0usize), |(e, c), (p, t)| {
                    let d2: f64 = p.iter().zip(t).map(|(a, b)| (a - b) * (a - b)).sum();
                    (e + d2.sqrt(), c + 1)
                });
        let origins = steps / job.eval.horizon.max(1);
        s.fold_errors.push(if steps > 0 {
            fold_sum / steps as f64
        } else {
            f64::NAN
        });
        s.fold_forecasts.push(origins);
        sum += fold_sum;
        n += steps;
    }
    if n == 0 {
        s.failure = Some("no origin in any held-out fold".into());
    } else {
        s.pooled_error = sum / n as f64;
    }
    Ok(s)
}

impl Predictor for Auto {
    fn name(&self) -> &str {
        "auto"
    }

    /// Every trajectory its own group (see [`Predictor::fit_grouped`]).
    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        self.fit_grouped(train, &super::own_groups(train))
    }

    fn fit_grouped(&mut self, train: &[Trajectory], groups: &[usize]) -> Result<()> {
        super::check_groups(train, groups)?;
        self.chosen = None;
        self.folds_used = fold_of_trajectories(groups, self.params.folds, self.params.seed)?.1;
        self.cv_unit = cv_unit(groups);
        let scores = self
            .params
            .candidates
            .iter()
            .map(|c| self.score(c, train, groups))
            .collect::<Result<Vec<_>>>()?;
        let best = scores
            .iter()
            .enumerate()
            .filter(|(_, s)| s.failure.is_none() && s.pooled_error.is_finite())
            .fold(None::<(usize, f64)>, |acc, (i, s)| match acc {
                Some((_, e)) if e <= s.pooled_error => acc,
                _ => Some((i, s.pooled_error)),
            })
            .map(|(i, _)| i);
        self.scores = scores;
        let Some(i) = best else {
            let why: Vec<String> = self
                .scores
                .iter()
                .map(|s| format!("{}: {}", s.method, s.failure.clone().unwrap_or_default()))
                .collect();
            return Err(invalid(
                "candidates",
                format!("every candidate failed: {}", why.join("; ")),
            ));
        };
        let name = self.params.candidates[i].clone();
        let mut p = registry::build(&name, &self.options)?;
        p.fit_grouped(train, groups)?;
        self.chosen = Some((name, p));
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        self.fitted()?.forecast(history, horizon)
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        self.fitted()?.forecast_times(history, times)
    }

    fn min_history(&self) -> usize {
        self.chosen.as_ref().map_or(1, |(_, p)| p.min_history())
    }

    /// `{"method": <the chosen method>, "params": <its fitted parameters>}`: what `auto`
    /// chose and what that method learned (the cross-validation scores are not saved).
    fn fitted_params(&self) -> Result<serde_json::Value> {
        let (name, p) = self.chosen.as_ref().ok_or_else(|| Error::NotFitted {
            method: "auto".into(),
        })?;
        Ok(serde_json::json!({ "method": name, "params": p.fitted_params()? }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let root = At::root("auto", params);
        let [method, inner] = root.fields(["method", "params"])?;
        let name = method.str()?;
        if !self.params.candidates.iter().any(|c| c == name) {
            return Err(method.error(format!(
                "`{name}` is not among this auto's candidates {:?}",
                self.params.candidates
            )));
        }
        let p = load_member("auto", name, &self.options, &inner)?;
        self.chosen = Some((name.to_string(), p));
        self.scores.clear();
        self.folds_used = 0;
        Ok(())
    }

    fn fitted_summary(&self) -> Option<String> {
        let chosen = self.chosen()?;
        if self.scores.is_empty() {
            return Some(format!("{chosen}, loaded from saved parameters"));
        }
        let mut s = format!(
            "chose {chosen} by {}-fold cross-validation by {} (mean error, m, per fold):",
            self.folds_used, self.cv_unit
        );
        for c in &self.scores {
            match &c.failure {
                Some(why) => {
                    let _ = write!(s, " {}: out ({why});", c.method);
                }
                None => {
                    let folds: Vec<String> =
                        c.fold_errors.iter().map(|e| format!("{e:.3}")).collect();
                    let _ = write!(
                        s,
                        " {} {:.3} [{}];",
                        c.method,
                        c.pooled_error,
                        folds.join(", ")
                    );
                }
            }
        }
        Some(s)
    }
}

/// Builds `name` with `options` and loads its saved parameters from `inner` (a field of
/// `method`'s own parameters); an error inside them is reported at its path under `inner`'s.
pub(crate) fn load_member(
    method: &str,
    name: &str,
    options: &MethodOptions,
    inner: &At<'_>,
) -> Result<Box<dyn Predictor>> {
    let mut p = registry::build(name, options)?;
    p.load_fitted_params(inner.value()).map_err(|e| match e {
        Error::InvalidFitted {
            method: m,
            path,
            reason,
        } => Error::InvalidFitted {
            method: method.into(),
            path: if path.is_empty() {
                inner.path().to_string()
            } else {
                format!("{}.{path}", inner.path())
            },
            reason: format!("{m}: {reason}"),
        },
        other => other,
    })?;
    Ok(p)
}

impl Auto {
    fn fitted(&self) -> Result<&dyn Predictor> {
        self.chosen
            .as_ref()
            .map(|(_, p)| p.as_ref())
            .ok_or_else(|| Error::NotFitted {
                method: "auto".into(),
            })
    }
}
