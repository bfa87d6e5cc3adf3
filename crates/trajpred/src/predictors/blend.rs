//! `blend`: a weighted mean of several methods' forecasts, the weights of each forecast step
//! chosen by greedy ensemble selection on forecasts held out by group (issue 27).

use super::auto::{DEFAULT_CANDIDATES, check_selection, fold_of_trajectories, load_member};
use super::cv_cache::{self, FoldJob};
use super::fitted::{At, exact_vec};
use super::invalid;
use held_out::{HeldOut, quantile_edges, regime_of, speed_at};

mod held_out;
use crate::harness::EvalConfig;
use crate::registry::{self, MethodOptions};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use trajpred_core::{Error, Forecast, Predictor, Result, Trajectory};

/// The most forecast steps a saved blend may hold weights for.
const MAX_STEPS: usize = 10_000;

/// The most speed regimes a saved blend may hold.
const MAX_REGIMES: usize = 1_000;

/// Parameters of [`Blend`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BlendParams {
    /// Registry names of the methods to blend (not `blend` or `auto`).
    pub candidates: Vec<String>,
    /// Folds of the cross-validation by group (at most the number of training groups).
    pub folds: usize,
    /// Seed of the deal of groups into folds.
    pub seed: u64,
    /// Rounds of the greedy selection per step: each round adds one copy of one candidate,
    /// so a weight is a multiple of `1 / rounds` at finest.
    pub rounds: usize,
    /// The most speed regimes: the held-out origins are split at quantiles of the last
    /// observed speed into 1 to `max_regimes` regimes, each with its own weights, and the
    /// number is chosen by cross-validation over the held-out folds (1 is the plain blend).
    pub max_regimes: usize,
    /// The rolling origin the held-out forecasts are made on (the run's own settings).
    pub eval: EvalConfig,
}

impl Default for BlendParams {
    fn default() -> Self {
        BlendParams {
            candidates: DEFAULT_CANDIDATES.iter().map(|s| s.to_string()).collect(),
            folds: 5,
            seed: 0,
            rounds: 20,
            max_regimes: 4,
            eval: EvalConfig::default(),
        }
    }
}

/// A member of a fitted blend: a method fitted on all the training data and its weight in
/// each speed regime at each forecast step.
struct Member {
    name: String,
    predictor: Box<dyn Predictor>,
    /// `weights[r][k]`: the weight in regime `r` at step `k`.
    weights: Vec<Vec<f64>>,
}

/// Blends candidate methods: at each forecast step, a weighted mean of their forecasts
/// (`blend` in the registry).
///
/// At [`Predictor::fit_grouped`] the training trajectories' groups (users, vehicles) are
/// dealt into [`BlendParams::folds`] folds; every candidate is fitted on all folds but one
/// and forecasts the held-out one on the harness's rolling origin
/// ([`crate::harness::collect_forecasts`] with [`BlendParams::eval`]), so every training origin
/// gets one held-out forecast per candidate. For each step `k` the weights are then chosen
/// by greedy selection with replacement (Caruana et al., 2004): starting empty, each of
/// [`BlendParams::rounds`] rounds adds the candidate that most lowers the mean Euclidean
/// error of the averaged held-out forecasts at step `k`, and the best round's counts, divided
/// by their sum, are the weights. One round is the single best candidate, so a blend is at
/// worst `auto`'s choice per step on the held-out folds. The weights may differ with the
/// speed of the target: the origins are split into speed regimes at quantiles of their last
/// observed speed (the distance between the last two fixes over their time apart), each
/// regime with its own weights, and the number of regimes (1 to
/// [`BlendParams::max_regimes`]) is the one whose weights, chosen on all held-out folds but
/// one, score best on the remaining fold, over every fold. A candidate that fails to fit or
/// refuses a held-out forecast is left out. The members with a weight are refitted on all
/// the training data.
///
/// Only the trajectories given to `fit` are read; a forecast is a mean of the members'
/// forecasts, so `blend` is causal when every member is. Steps past the fitted horizon use
/// the last step's weights. [`Predictor::fitted_summary`] gives the weights and the held-out
/// errors (the blend's own is measured on the forecasts its weights were chosen on, so it is
/// optimistic).
///
/// ```
/// use trajpred::predictors::{Blend, BlendParams};
/// use trajpred::registry::MethodOptions;
/// use trajpred_core::{Predictor, Trajectory};
/// // straight tracks at 2 m/s: the last velocity is exact
/// let tracks: Vec<Trajectory> = (0..4)
///     .map(|k| Trajectory::uniform(0.0, 1.0, vec![(0..40).map(|i| (2 * i + k) as f64).collect()]))
///     .collect::<Result<_, _>>()?;
/// let params = BlendParams {
///     candidates: vec!["kf-dynamic-literal".into(), "cv-time".into()],
///     ..BlendParams::default()
/// };
/// let mut blend = Blend::new(params, MethodOptions::default())?;
/// blend.fit_grouped(&tracks, &[0, 0, 1, 2])?;
/// assert_eq!(blend.weights("cv-time", 0), Some(&[1.0; 5][..]));
/// // one speed everywhere: a single regime
/// assert!(blend.speed_edges().is_empty());
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub struct Blend {
    params: BlendParams,
    options: MethodOptions,
    members: Vec<Member>,
    /// The speed regimes' edges (increasing; none for a single regime).
    edges: Vec<f64>,
    summary: Option<String>,
}

impl std::fmt::Debug for Blend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Blend")
            .field("params", &self.params)
            .field("summary", &self.summary)
            .finish()
    }
}

impl Blend {
    /// An unfitted blend of `params.candidates`, each built with `options`. Errors for no
    /// candidate, an unknown one, `blend` or `auto` among them, fewer than 2 folds, no
    /// round or bad evaluation settings.
    pub fn new(params: BlendParams, options: MethodOptions) -> Result<Self> {
        check_selection(
            &params.candidates,
            params.folds,
            &params.eval,
            &options,
            |c| {
                (c == "blend" || c == "auto").then(|| {
                    format!(
                        "`{c}` chooses among methods itself and cannot be blended, got {:?}",
                        params.candidates
                    )
                })
            },
        )?;
        if params.rounds == 0 {
            return Err(invalid("rounds", "must be at least 1, got 0"));
        }
        if params.max_regimes == 0 {
            return Err(invalid("max_regimes", "must be at least 1, got 0"));
        }
        Ok(Blend {
            params,
            options,
            members: Vec::new(),
            edges: Vec::new(),
            summary: None,
        })
    }

    /// The weights of `method` at each fitted step in speed regime `regime` (0 is the
    /// slowest; see [`Blend::speed_edges`]), if it is a member and the regime exists.
    pub fn weights(&self, method: &str, regime: usize) -> Option<&[f64]> {
        self.members
            .iter()
            .find(|m| m.name == method)
            .and_then(|m| m.weights.get(regime))
            .map(Vec::as_slice)
    }

    /// The speeds (m/s for tracks in metres and seconds) that split the speed regimes: a
    /// history whose last fixes are `v` apart per second is in the regime of how many edges
    /// `v` exceeds. Empty for a single regime (or an unfitted blend).
    pub fn speed_edges(&self) -> &[f64] {
        &self.edges
    }

    /// Every candidate's held-out forecasts on the same origins, fold by fold.
    fn held_out(
        &self,
        train: &[Trajectory],
        groups: &[usize],
        notes: &mut Vec<String>,
    ) -> Result<HeldOut> {
        let (fold, k) = fold_of_trajectories(groups, self.params.folds, self.params.seed)?;
        let (h, d) = (
            self.params.eval.horizon,
            train.first().map_or(1, |t| t.dim()),
        );
        let cands = &self.params.candidates;
        let (mut truth, mut speed, mut fold_of) = (Vec::new(), Vec::new(), Vec::new());
        let mut forecasts: Vec<Option<Vec<f64>>> = vec![Some(Vec::new()); cands.len()];
        for f in 0..k {
            let held: Vec<Trajectory> = train
                .iter()
                .zip(&fold)
                .filter(|&(_, &g)| g == f)
                .map(|(t, _)| t.clone())
                .collect();
            let mut fold_truth: Option<Vec<f64>> = None;
            for (c, name) in cands.iter().enumerate() {
                let Some(out) = forecasts[c].as_mut() else {
                    continue;
                };
                let build = || registry::build(name, &self.options);
                let (e, o) = (&self.params.eval, &self.options);
                let job = FoldJob::new(name, &build, (train, groups), &fold, e, o);
                match cv_cache::fold_forecasts(&job, f)?.as_ref() {
                    Ok((p, t)) => {
                        match &fold_truth {
                            Some(prev) if prev.len() != t.len() => {
                                notes.push(format!("{name}: out (fold {f}: other origins)"));
                                forecasts[c] = None;
                                continue;
                            }
                            Some(_) => {}
                            None => fold_truth = Some(t.clone()),
                        }
                        out.extend_from_slice(p);
                    }
                    Err(why) => {
                        notes.push(format!("{name}: out ({why})"));
                        forecasts[c] = None;
                    }
                }
            }
            if let Some(t) = fold_truth {
                let speeds: Vec<f64> = held
                    .iter()
                    .flat_map(|tr| {
                        self.params
                            .eval
                            .origins(tr.len())
                            .map(move |o| speed_at(tr, o))
                    })
                    .collect();
                if speeds.len() * h * d != t.len() {
                    return Err(invalid(
                        "eval",
                        format!(
                            "fold {f}: {} origins but {} held-out forecasts",
                            speeds.len(),
                            t.len() / (h * d)
                        ),
                    ));
                }
                fold_of.extend(std::iter::repeat_n(f, speeds.len()));
                speed.extend(speeds);
                truth.extend(t);
            }
        }
        let forecasts: Vec<(usize, Vec<f64>)> = forecasts
            .into_iter()
            .enumerate()
            .filter_map(|(c, f)| f.map(|f| (c, f)))
            .filter(|(_, f)| f.len() == truth.len())
            .collect();
        if forecasts.is_empty() || truth.is_empty() {
            return Err(invalid(
                "candidates",
                format!(
                    "no candidate forecast every held-out origin: {}",
                    if notes.is_empty() {
                        "no origin in any held-out fold".to_string()
                    } else {
                        notes.join("; ")
                    }
                ),
            ));
        }
        Ok(HeldOut {
            horizon: h,
            dim: d,
            truth,
            forecasts,
            speed,
            fold: fold_of,
        })
    }

    fn fitted(&self) -> Result<&[Member]> {
        if self.members.is_empty() {
            return Err(Error::NotFitted {
                method: "blend".into(),
            });
        }
        Ok(&self.members)
    }

    /// The weighted mean of the members' forecasts `each` gives, with the weights of the
    /// speed regime of `history`'s last fixes.
    fn combine(
        &self,
        history: &Trajectory,
        each: impl Fn(&dyn Predictor) -> Result<Forecast>,
    ) -> Result<Forecast> {
        let members = self.fitted()?;
        let regime = regime_of(
            &self.edges,
            speed_at(history, history.len().saturating_sub(1)),
        );
        let mut sum: Vec<Vec<f64>> = Vec::new();
        let mut dim = 0;
        for m in members {
            let f = each(m.predictor.as_ref())?;
            if sum.is_empty() {
                dim = f.dim();
                sum = vec![vec![0.0; dim]; f.horizon()];
            } else if (f.dim(), f.horizon()) != (dim, sum.len()) {
                return Err(invalid(
                    "members",
                    format!(
                        "{} forecast {} steps x {} axes, the others {} x {dim}",
                        m.name,
                        f.horizon(),
                        f.dim(),
                        sum.len()
                    ),
                ));
            }
            let w = &m.weights[regime.min(m.weights.len() - 1)];
            for (k, s) in sum.iter_mut().enumerate() {
                let w = w[k.min(w.len() - 1)];
                for (s, x) in s.iter_mut().zip(f.step(k + 1)) {
                    *s += w * x;
                }
            }
        }
        Forecast::new(dim, sum)
    }
}

impl Predictor for Blend {
    fn name(&self) -> &str {
        "blend"
    }

    /// Every trajectory its own group (see [`Predictor::fit_grouped`]).
    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        self.fit_grouped(train, &super::own_groups(train))
    }

    fn fit_grouped(&mut self, train: &[Trajectory], groups: &[usize]) -> Result<()> {
        super::check_groups(train, groups)?;
        self.members.clear();
        self.edges.clear();
        self.summary = None;
        let mut notes = Vec::new();
        let held = self.held_out(train, groups, &mut notes)?;
        let (h, usable) = (held.horizon, held.forecasts.len());
        let all: Vec<usize> = (0..held.origins()).collect();
        let folds = held.fold.iter().max().map_or(0, |&f| f + 1);
        let mut s = String::from("speed regimes by cross-validation over the held-out folds");
        let mut best = (1usize, f64::INFINITY);
        for r in 1..=self.params.max_regimes {
            let e = held.cv_error(r, self.params.rounds, folds);
            let _ = write!(s, "{} {r}: {e:.3} m", if r == 1 { ":" } else { "," });
            if e < best.1 {
                best = (r, e);
            }
        }
        let speeds: Vec<f64> = held.speed.clone();
        let edges = quantile_edges(speeds, best.0);
        let weights = held.fit_weights(&all, &edges, self.params.rounds);
        let _ = write!(
            s,
            "; chose {} (edges {:?} m/s, {} regimes)",
            best.0,
            edges
                .iter()
                .map(|e| (e * 1000.0).round() / 1000.0)
                .collect::<Vec<_>>(),
            weights.len()
        );
        for (r, wr) in weights.iter().enumerate() {
            for (k, wk) in wr.iter().enumerate() {
                let _ = write!(s, "; regime {r} step {}:", k + 1);
                for (c, &w) in wk.iter().enumerate() {
                    if w > 0.0 {
                        let name = &self.params.candidates[held.forecasts[c].0];
                        let _ = write!(s, " {name} {w:.2}");
                    }
                }
            }
        }
        let _ = write!(s, "; candidates' held-out mean error (m):");
        for (c, f) in &held.forecasts {
            let e = (0..h).map(|j| held.error(j, &all, &step_sum(f, h, held.dim, j), 1.0));
            let name = &self.params.candidates[*c];
            let _ = write!(s, " {name} {:.3}", e.sum::<f64>() / h as f64);
        }
        for n in &notes {
            let _ = write!(s, "; {n}");
        }
        for c in 0..usable {
            let w: Vec<Vec<f64>> = weights
                .iter()
                .map(|wr| wr.iter().map(|wk| wk[c]).collect())
                .collect();
            if w.iter().flatten().all(|&x| x == 0.0) {
                continue;
            }
            let name = self.params.candidates[held.forecasts[c].0].clone();
            let mut p = registry::build(&name, &self.options)?;
            p.fit_grouped(train, groups)?;
            self.members.push(Member {
                name,
                predictor: p,
                weights: w,
            });
        }
        self.edges = edges;
        self.summary = Some(s);
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        self.combine(history, |p| p.forecast(history, horizon))
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        self.combine(history, |p| p.forecast_times(history, times))
    }

    fn min_history(&self) -> usize {
        self.members
            .iter()
            .map(|m| m.predictor.min_history())
            .max()
            .unwrap_or(1)
    }

    /// `{"speed_edges": [...], "members": [{"method", "weights", "params"}, ...]}`: the
    /// speed regimes' edges, and each member with its weights (one list of per-step weights
    /// per regime, slowest first) and what it learned.
    fn fitted_params(&self) -> Result<serde_json::Value> {
        let members = self.fitted()?;
        let mut out = Vec::with_capacity(members.len());
        for m in members {
            let w: Vec<serde_json::Value> = m.weights.iter().map(exact_vec).collect();
            out.push(serde_json::json!({
                "method": m.name,
                "weights": w,
                "params": m.predictor.fitted_params()?,
            }));
        }
        Ok(serde_json::json!({ "speed_edges": exact_vec(&self.edges), "members": out }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let root = At::root("blend", params);
        let [edges_at, members] = root.fields(["speed_edges", "members"])?;
        let mut edges = Vec::new();
        let empty = edges_at.value().as_array().is_some_and(Vec::is_empty);
        let edge_items = if empty {
            Vec::new()
        } else {
            edges_at.items(None, MAX_REGIMES - 1)?
        };
        for e in edge_items {
            let v = e.f64_min(0.0, false)?;
            if edges.last().is_some_and(|&l| v <= l) {
                return Err(e.error(format!(
                    "must exceed the edge before it, {}",
                    edges[edges.len() - 1]
                )));
            }
            edges.push(v);
        }
        let regimes = edges.len() + 1;
        let items = members.items(None, self.params.candidates.len())?;
        let mut loaded: Vec<Member> = Vec::with_capacity(items.len());
        for item in &items {
            let [method, weights, inner] = item.fields(["method", "weights", "params"])?;
            let name = method.str()?;
            if !self.params.candidates.iter().any(|c| c == name) {
                return Err(method.error(format!(
                    "`{name}` is not among this blend's candidates {:?}",
                    self.params.candidates
                )));
            }
            if loaded.iter().any(|m| m.name == name) {
                return Err(method.error(format!("`{name}` is a member twice")));
            }
            // the first member's weights set the fitted horizon, the others must match it
            let steps = loaded.first().map(|m| m.weights[0].len());
            let mut w = Vec::with_capacity(regimes);
            for wr in weights.items(Some(regimes), regimes)? {
                let wr: Vec<f64> = match steps.or(w.first().map(Vec::len)) {
                    Some(n) => wr.items(Some(n), n)?,
                    None => wr.items(None, MAX_STEPS)?,
                }
                .iter()
                .map(|x| x.f64_min(0.0, false))
                .collect::<Result<_>>()?;
                w.push(wr);
            }
            let predictor = load_member("blend", name, &self.options, &inner)?;
            loaded.push(Member {
                name: name.to_string(),
                predictor,
                weights: w,
            });
        }
        let steps = loaded.first().map_or(0, |m| m.weights[0].len());
        for r in 0..regimes {
            for k in 0..steps {
                let total: f64 = loaded.iter().map(|m| m.weights[r][k]).sum();
                if (total - 1.0).abs() > 1e-9 {
                    return Err(members.error(format!(
                        "the weights of regime {r}, step {} sum to {total}, not 1",
                        k + 1
                    )));
                }
            }
        }
        self.members = loaded;
        self.edges = edges;
        self.summary = None;
        Ok(())
    }

    fn fitted_summary(&self) -> Option<String> {
        if self.members.is_empty() {
            return None;
        }
        Some(
            self.summary
                .clone()
                .unwrap_or_else(|| "loaded from saved parameters".into()),
        )
    }
}

/// Step `k` of every origin of forecasts `f` laid out as `HeldOut::truth`.
fn step_sum(f: &[f64], h: usize, d: usize, k: usize) -> Vec<f64> {
    f.chunks(h * d)
        .flat_map(|o| o[k * d..][..d].to_vec())
        .collect()
}
