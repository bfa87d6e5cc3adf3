//! `blend`: a weighted mean of several methods' forecasts, the weights of each forecast step
//! chosen by greedy ensemble selection on forecasts held out by group (issue 27).

use super::auto::{DEFAULT_CANDIDATES, fold_of_trajectories, fold_split, load_member};
use super::fitted::{At, exact_vec};
use super::invalid;
use crate::harness::{self, EvalConfig, ForecastPair};
use crate::registry::{self, MethodOptions};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use trajpred_core::{Error, Forecast, Point, Predictor, Result, Trajectory};

/// The most forecast steps a saved blend may hold weights for.
const MAX_STEPS: usize = 10_000;

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
            eval: EvalConfig::default(),
        }
    }
}

/// A member of a fitted blend: a method fitted on all the training data and its weight at
/// each forecast step.
struct Member {
    name: String,
    predictor: Box<dyn Predictor>,
    weights: Vec<f64>,
}

/// The held-out forecasts of every candidate on the same origins, and the truth.
struct HeldOut {
    horizon: usize,
    dim: usize,
    /// `truth[(i * horizon + k) * dim + a]`
    truth: Vec<f64>,
    /// One per usable candidate: its index among the candidates and its forecasts, laid out
    /// like `truth`.
    forecasts: Vec<(usize, Vec<f64>)>,
}

impl HeldOut {
    fn origins(&self) -> usize {
        self.truth.len() / (self.horizon * self.dim)
    }

    /// Mean error at step `k` of the forecast `sum / m` (`sum` laid out as one step of
    /// `truth`, per origin).
    fn error(&self, k: usize, sum: &[f64], m: f64) -> f64 {
        let (h, d) = (self.horizon, self.dim);
        let n = self.origins();
        let mut total = 0.0;
        for i in 0..n {
            let t = &self.truth[(i * h + k) * d..][..d];
            let s = &sum[i * d..][..d];
            total += t
                .iter()
                .zip(s)
                .map(|(t, s)| (s / m - t).powi(2))
                .sum::<f64>()
                .sqrt();
        }
        total / n as f64
    }

    /// Greedy selection with replacement at step `k` (Caruana et al., 2004): each round adds
    /// the candidate whose copy lowers the held-out mean error most; the counts of the best
    /// round are kept. Returns the counts per usable candidate, the rounds they sum to and
    /// the error.
    fn select(&self, k: usize, rounds: usize) -> (Vec<usize>, usize, f64) {
        let (h, d, n) = (self.horizon, self.dim, self.origins());
        let step = |f: &[f64], i: usize| -> [f64; 3] {
            let mut p = [0.0; 3];
            p[..d].copy_from_slice(&f[(i * h + k) * d..][..d]);
            p
        };
        let mut sum = vec![0.0; n * d];
        let mut counts = vec![0usize; self.forecasts.len()];
        let mut best = (counts.clone(), 0usize, f64::INFINITY);
        let mut trial = vec![0.0; n * d];
        for round in 1..=rounds {
            let mut pick = None::<(usize, f64)>;
            for (c, (_, f)) in self.forecasts.iter().enumerate() {
                for i in 0..n {
                    let p = step(f, i);
                    for a in 0..d {
                        trial[i * d + a] = sum[i * d + a] + p[a];
                    }
                }
                let e = self.error(k, &trial, round as f64);
                if pick.is_none_or(|(_, b)| e < b) {
                    pick = Some((c, e));
                }
            }
            let Some((c, e)) = pick else { break };
            counts[c] += 1;
            for i in 0..n {
                let p = step(&self.forecasts[c].1, i);
                for a in 0..d {
                    sum[i * d + a] += p[a];
                }
            }
            if e < best.2 {
                best = (counts.clone(), round, e);
            }
        }
        best
    }
}

/// Blends candidate methods: at each forecast step, a weighted mean of their forecasts
/// (`blend` in the registry).
///
/// At [`Predictor::fit_grouped`] the training trajectories' groups (users, vehicles) are
/// dealt into [`BlendParams::folds`] folds; every candidate is fitted on all folds but one
/// and forecasts the held-out one on the harness's rolling origin
/// ([`harness::collect_forecasts`] with [`BlendParams::eval`]), so every training origin
/// gets one held-out forecast per candidate. For each step `k` the weights are then chosen
/// by greedy selection with replacement (Caruana et al., 2004): starting empty, each of
/// [`BlendParams::rounds`] rounds adds the candidate that most lowers the mean Euclidean
/// error of the averaged held-out forecasts at step `k`, and the best round's counts, divided
/// by their sum, are the weights. One round is the single best candidate, so a blend is at
/// worst `auto`'s choice per step on the held-out folds. A candidate that fails to fit or
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
/// assert_eq!(blend.weights("cv-time"), Some(&[1.0; 5][..]));
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub struct Blend {
    params: BlendParams,
    options: MethodOptions,
    members: Vec<Member>,
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
        if params.candidates.is_empty() {
            return Err(invalid("candidates", "needs at least one method, got none"));
        }
        if params.folds < 2 {
            return Err(invalid(
                "folds",
                format!("must be at least 2, got {}", params.folds),
            ));
        }
        if params.rounds == 0 {
            return Err(invalid("rounds", "must be at least 1, got 0"));
        }
        params.eval.validate()?;
        for c in &params.candidates {
            if c == "blend" || c == "auto" {
                return Err(invalid(
                    "candidates",
                    format!(
                        "`{c}` chooses among methods itself and cannot be blended, got {:?}",
                        params.candidates
                    ),
                ));
            }
            registry::build(c, &options)?;
        }
        Ok(Blend {
            params,
            options,
            members: Vec::new(),
            summary: None,
        })
    }

    /// The weights of `method` at each fitted step, if it is a member.
    pub fn weights(&self, method: &str) -> Option<&[f64]> {
        self.members
            .iter()
            .find(|m| m.name == method)
            .map(|m| m.weights.as_slice())
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
        let mut truth = Vec::new();
        let mut forecasts: Vec<Option<Vec<f64>>> = vec![Some(Vec::new()); cands.len()];
        for f in 0..k {
            let (fit, fit_groups, held) = fold_split(train, groups, &fold, f);
            let mut fold_truth: Option<Vec<f64>> = None;
            for (c, name) in cands.iter().enumerate() {
                let Some(out) = forecasts[c].as_mut() else {
                    continue;
                };
                let mut p = registry::build(name, &self.options)?;
                let got = match p.fit_grouped(&fit, &fit_groups) {
                    Err(e) => Err(format!("fold {f}: fit: {e}")),
                    Ok(()) => harness::collect_forecasts(p.as_ref(), &held, &self.params.eval)?
                        .map_err(|why| format!("fold {f}: {why}")),
                };
                match got {
                    Ok(pairs) => {
                        let flat = |pick: fn(&ForecastPair) -> &Vec<Point>| {
                            pairs
                                .iter()
                                .flat_map(|pair| pick(pair).iter())
                                .flat_map(|x| x.as_ref().to_vec())
                                .collect::<Vec<f64>>()
                        };
                        let t = flat(|p| &p.1);
                        match &fold_truth {
                            Some(prev) if prev.len() != t.len() => {
                                notes.push(format!("{name}: out (fold {f}: other origins)"));
                                forecasts[c] = None;
                                continue;
                            }
                            Some(_) => {}
                            None => fold_truth = Some(t),
                        }
                        out.extend(flat(|p| &p.0));
                    }
                    Err(why) => {
                        notes.push(format!("{name}: out ({why})"));
                        forecasts[c] = None;
                    }
                }
            }
            truth.extend(fold_truth.unwrap_or_default());
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

    /// The weighted mean of the members' forecasts `each` gives.
    fn combine(&self, each: impl Fn(&dyn Predictor) -> Result<Forecast>) -> Result<Forecast> {
        let members = self.fitted()?;
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
            for (k, s) in sum.iter_mut().enumerate() {
                let w = m.weights[k.min(m.weights.len() - 1)];
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
        self.summary = None;
        let mut notes = Vec::new();
        let held = self.held_out(train, groups, &mut notes)?;
        let (h, usable) = (held.horizon, held.forecasts.len());
        // weights[k][c]: candidate c's weight at step k
        let mut weights = vec![vec![0.0; usable]; h];
        let mut s = String::from("weights per step");
        for (k, wk) in weights.iter_mut().enumerate() {
            let (counts, rounds, e) = held.select(k, self.params.rounds);
            let _ = write!(s, "; step {}: {e:.3} m held out,", k + 1);
            for (c, &n) in counts.iter().enumerate() {
                wk[c] = n as f64 / rounds as f64;
                if n > 0 {
                    let name = &self.params.candidates[held.forecasts[c].0];
                    let _ = write!(s, " {name} {n}/{rounds}");
                }
            }
        }
        let _ = write!(s, "; candidates' held-out mean error (m):");
        for (c, f) in &held.forecasts {
            let e = (0..h).map(|j| held.error(j, &step_sum(f, h, held.dim, j), 1.0));
            let name = &self.params.candidates[*c];
            let _ = write!(s, " {name} {:.3}", e.sum::<f64>() / h as f64);
        }
        for n in &notes {
            let _ = write!(s, "; {n}");
        }
        for c in 0..usable {
            let w: Vec<f64> = weights.iter().map(|wk| wk[c]).collect();
            if w.iter().all(|&x| x == 0.0) {
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
        self.summary = Some(s);
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        self.combine(|p| p.forecast(history, horizon))
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        self.combine(|p| p.forecast_times(history, times))
    }

    fn min_history(&self) -> usize {
        self.members
            .iter()
            .map(|m| m.predictor.min_history())
            .max()
            .unwrap_or(1)
    }

    /// `{"members": [{"method", "weights", "params"}, ...]}`: each member, its weight at
    /// every step and what it learned.
    fn fitted_params(&self) -> Result<serde_json::Value> {
        let members = self.fitted()?;
        let mut out = Vec::with_capacity(members.len());
        for m in members {
            out.push(serde_json::json!({
                "method": m.name,
                "weights": exact_vec(&m.weights),
                "params": m.predictor.fitted_params()?,
            }));
        }
        Ok(serde_json::json!({ "members": out }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let root = At::root("blend", params);
        let [members] = root.fields(["members"])?;
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
            let w: Vec<f64> = match loaded.first() {
                Some(m) => weights.items(Some(m.weights.len()), m.weights.len())?,
                None => weights.items(None, MAX_STEPS)?,
            }
            .iter()
            .map(|x| x.f64_min(0.0, false))
            .collect::<Result<_>>()?;
            let predictor = load_member("blend", name, &self.options, &inner)?;
            loaded.push(Member {
                name: name.to_string(),
                predictor,
                weights: w,
            });
        }
        let steps = loaded.first().map_or(0, |m| m.weights.len());
        for k in 0..steps {
            let total: f64 = loaded.iter().map(|m| m.weights[k]).sum();
            if (total - 1.0).abs() > 1e-9 {
                return Err(members.error(format!(
                    "the weights of step {} sum to {total}, not 1",
                    k + 1
                )));
            }
        }
        self.members = loaded;
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

#[cfg(test)]
mod tests {
    use super::HeldOut;

    /// Worked by hand: the truth is 0 at both origins; candidate A says +1 and +3, B says -1
    /// and -3. Round 1 takes A (the first of two equal errors, 2); round 2 adds B, whose mean
    /// with A is exact (error 0); round 3 can only make it worse (1/3 or 1). So the weights are
    /// 1/2 and 1/2, reached at round 2 with error 0.
    #[test]
    fn greedy_selection_matches_the_hand_worked_case() {
        let held = HeldOut {
            horizon: 1,
            dim: 1,
            truth: vec![0.0, 0.0],
            forecasts: vec![(0, vec![1.0, 3.0]), (1, vec![-1.0, -3.0])],
        };
        assert_eq!(held.select(0, 1), (vec![1, 0], 1, 2.0));
        assert_eq!(held.select(0, 5), (vec![1, 1], 2, 0.0));
        // a third candidate at 0 everywhere wins alone at round 1
        let held = HeldOut {
            forecasts: vec![
                (0, vec![1.0, 3.0]),
                (1, vec![-1.0, -3.0]),
                (2, vec![0.0, 0.0]),
            ],
            ..held
        };
        assert_eq!(held.select(0, 5), (vec![0, 0, 1], 1, 0.0));
    }

    /// Step `k` is scored on step `k` only: two steps, a candidate exact at step 2 only.
    #[test]
    fn each_step_is_selected_on_its_own_errors() {
        // origins x steps x 1 axis: truth (0, 10) at both origins
        let held = HeldOut {
            horizon: 2,
            dim: 1,
            truth: vec![0.0, 10.0, 0.0, 10.0],
            forecasts: vec![
                (0, vec![0.0, 0.0, 0.0, 0.0]),
                (1, vec![5.0, 10.0, 5.0, 10.0]),
            ],
        };
        assert_eq!(held.select(0, 3), (vec![1, 0], 1, 0.0));
        assert_eq!(held.select(1, 3), (vec![0, 1], 1, 0.0));
    }
}
