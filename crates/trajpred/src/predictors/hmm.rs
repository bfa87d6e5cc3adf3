//! The HMM motion-state predictor of `docs/papers.md` B.2 (the KF-dynamic paper's "HMM" baseline).
//!
//! Training displacement vectors are clustered into K motion states by k-means; the states of
//! consecutive displacements give a transition matrix by counting (observed states, Laplace
//! smoothing); an isotropic Gaussian around each centroid is the emission model. To forecast,
//! the state distribution is forward-filtered over the history's displacements, pushed through
//! the transition matrix step by step, and the expected centroid is added to the last point.

use super::fitted::{At, exact, exact_vec};
use super::invalid;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use trajpred_core::{Error, Forecast, Predictor, Result, Trajectory, check_forecast_args};

/// Parameters of [`Hmm`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HmmParams {
    /// Number of motion states K; `None` chooses it on the training data among `candidates`.
    pub states: Option<usize>,
    /// The K tried when `states` is `None`.
    pub candidates: Vec<usize>,
    /// Seed of the k-means++ initialisation.
    pub seed: u64,
    /// Most Lloyd iterations of k-means.
    pub max_iterations: usize,
    /// Most recent displacements used by the forward filter.
    pub filter_window: usize,
    /// Steps ahead K is chosen for: the mean position error over steps 1..=`horizon` of
    /// forecasts on held-out training trajectories (the run's forecast horizon).
    #[serde(default = "default_horizon")]
    pub horizon: usize,
}

fn default_horizon() -> usize {
    5
}

impl Default for HmmParams {
    fn default() -> Self {
        HmmParams {
            states: None,
            candidates: vec![2, 4, 8, 16, 32, 64, 128],
            seed: 0,
            max_iterations: 100,
            filter_window: 50,
            horizon: default_horizon(),
        }
    }
}

/// What [`Hmm::fit`](Predictor::fit) learns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HmmModel {
    /// Number of axes of the displacements.
    pub dim: usize,
    /// The K centroids (mean displacement of each motion state).
    pub centroids: Vec<Vec<f64>>,
    /// Row-stochastic K x K transition matrix, `transition[i][j] = P(s' = j | s = i)`.
    pub transition: Vec<Vec<f64>>,
    /// Initial state distribution.
    pub initial: Vec<f64>,
    /// Variance of the isotropic Gaussian emission around each centroid.
    pub emission_variance: f64,
}

/// Most motion states a loaded HMM may have (the transition matrix is K x K, and each
/// forecast step costs K^2).
pub const MAX_HMM_STATES: usize = 4096;

/// How far a row of probabilities may sum from 1 (the fitted rows are normalised counts, off
/// by a few units of rounding).
const PROBABILITY_SUM_TOLERANCE: f64 = 1e-9;

/// `k` probabilities in [0, 1] summing to 1 within [`PROBABILITY_SUM_TOLERANCE`].
fn probabilities(at: &At, k: usize) -> Result<Vec<f64>> {
    let v: Vec<f64> = at
        .items(Some(k), k)?
        .iter()
        .map(|p| {
            let x = p.f64()?;
            if (0.0..=1.0).contains(&x) {
                Ok(x)
            } else {
                Err(p.error(format!("a probability must be in [0, 1], got {x}")))
            }
        })
        .collect::<Result<_>>()?;
    let s: f64 = v.iter().sum();
    if (s - 1.0).abs() > PROBABILITY_SUM_TOLERANCE {
        return Err(at.error(format!("probabilities must sum to 1, sum to {s}")));
    }
    Ok(v)
}

impl HmmModel {
    fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "centroids": self.centroids.iter().map(exact_vec).collect::<Vec<_>>(),
            "transition": self.transition.iter().map(exact_vec).collect::<Vec<_>>(),
            "initial": exact_vec(&self.initial),
            "emission_variance": exact(self.emission_variance),
        })
    }

    fn from_json(params: &serde_json::Value) -> Result<Self> {
        let [c, tr, init, ev] = At::root("hmm", params).fields([
            "centroids",
            "transition",
            "initial",
            "emission_variance",
        ])?;
        let rows = c.items(None, MAX_HMM_STATES)?;
        let k = rows.len();
        let dim = rows[0].items(None, trajpred_core::MAX_AXES)?.len();
        let centroids = rows
            .iter()
            .map(|r| r.items(Some(dim), dim)?.iter().map(At::f64).collect())
            .collect::<Result<_>>()?;
        let transition = tr
            .items(Some(k), k)?
            .iter()
            .map(|r| probabilities(r, k))
            .collect::<Result<_>>()?;
        Ok(HmmModel {
            dim,
            centroids,
            transition,
            initial: probabilities(&init, k)?,
            emission_variance: ev.f64_min(0.0, true)?,
        })
    }
}

/// HMM motion-state predictor (`docs/papers.md` B.2). Assumes a uniform sampling step (resample
/// first).
///
/// ```
/// use trajpred::predictors::{Hmm, HmmParams};
/// use trajpred_core::{Predictor, Trajectory};
/// // a walker that alternates steps of +1 and +3 along x
/// let x: Vec<f64> = (0..40).map(|i| (i / 2 * 4 + (i % 2)) as f64).collect();
/// let tr = Trajectory::uniform(0.0, 1.0, vec![x.clone(), vec![0.0; 40]])?;
/// let mut p = Hmm::new(HmmParams { states: Some(2), ..Default::default() })?;
/// p.fit(std::slice::from_ref(&tr))?;
/// let f = p.forecast(&tr, 2)?;
/// // the last displacement was +1, so the next is +3 and then +1 (up to the Laplace
/// // smoothing of the counted transitions: 1 pseudo-count against 19 observed)
/// assert!((f.step(1)[0] - (x[39] + 3.0)).abs() < 0.2);
/// assert!((f.step(2)[0] - (x[39] + 4.0)).abs() < 0.4);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hmm {
    params: HmmParams,
    model: Option<HmmModel>,
}

impl Hmm {
    /// A validated, unfitted predictor.
    pub fn new(params: HmmParams) -> Result<Self> {
        if params.states == Some(0) {
            return Err(invalid("states", "K must be at least 1, got 0"));
        }
        if params.states.is_none()
            && (params.candidates.is_empty() || params.candidates.contains(&0))
        {
            return Err(invalid(
                "candidates",
                format!(
                    "need at least one K, each at least 1, got {:?}",
                    params.candidates
                ),
            ));
        }
        if params.max_iterations == 0 {
            return Err(invalid("max_iterations", "must be at least 1, got 0"));
        }
        if params.filter_window == 0 {
            return Err(invalid("filter_window", "must be at least 1, got 0"));
        }
        if params.horizon == 0 {
            return Err(invalid("horizon", "must be at least 1, got 0"));
        }
        Ok(Hmm {
            params,
            model: None,
        })
    }

    /// The fitted model, if `fit` has run.
    pub fn model(&self) -> Option<&HmmModel> {
        self.model.as_ref()
    }
}

fn displacements(tr: &Trajectory) -> Vec<Vec<f64>> {
    (1..tr.len())
        .map(|i| {
            let (a, b) = (tr.point(i - 1), tr.point(i));
            b.iter().zip(a.iter()).map(|(b, a)| b - a).collect()
        })
        .collect()
}

fn sq_dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| (a - b) * (a - b)).sum()
}

fn nearest(c: &[Vec<f64>], x: &[f64]) -> usize {
    let mut best = (0, f64::INFINITY);
    for (j, cj) in c.iter().enumerate() {
        let d = sq_dist(cj, x);
        if d < best.1 {
            best = (j, d);
        }
    }
    best.0
}

/// Points per rayon task of [`assign_nearest`] (below it one task: its results are the same).
const ASSIGN_CHUNK: usize = 4096;

/// Assigns each point of `flat` (`dim` values a point) to its nearest centroid of `cflat`
/// (the first of equals, as [`nearest`]), in parallel over chunks of points; returns whether
/// any assignment changed.
///
/// Per point, the squared distances to all centroids are formed first, coordinate by
/// coordinate over a transposed copy of the centroids (each distance the same sum, in the
/// same order, as [`sq_dist`]: they vectorise across centroids), then their minimum, then
/// the first centroid at it: the answer of [`nearest`]'s running comparison, without its
/// chain of dependent compares.
fn assign_nearest(flat: &[f64], cflat: &[f64], dim: usize, assign: &mut [usize]) -> bool {
    let k = cflat.len() / dim.max(1);
    // by coordinate: `by_axis[a * k + j]` is coordinate `a` of centroid `j`
    let by_axis: Vec<f64> = (0..dim)
        .flat_map(|a| cflat.chunks_exact(dim).map(move |c| c[a]))
        .collect();
    let near = |x: &[f64], ds: &mut [f64]| {
        ds.fill(-0.0);
        for (&xa, ca) in x.iter().zip(by_axis.chunks_exact(k)) {
            for (d, &c) in ds.iter_mut().zip(ca) {
                *d += (c - xa) * (c - xa);
            }
        }
        let m = ds.iter().copied().fold(f64::INFINITY, f64::min);
        if m < f64::INFINITY {
            ds.iter().position(|&d| d == m).unwrap_or(0)
        } else {
            0
        }
    };
    let pass = |(a, x): (&mut [usize], &[f64])| {
        let mut changed = false;
        let mut ds = vec![0.0; k];
        for (a, x) in a.iter_mut().zip(x.chunks_exact(dim)) {
            let j = near(x, &mut ds);
            changed |= *a != j;
            *a = j;
        }
        changed
    };
    assign
        .par_chunks_mut(ASSIGN_CHUNK)
        .zip(flat.par_chunks(ASSIGN_CHUNK * dim))
        .map(pass)
        .reduce(|| false, |a, b| a | b)
}

/// k-means with k-means++ seeding (seeded), Lloyd iterations; an emptied cluster is re-seeded
/// with the point farthest from its centroid.
fn kmeans(data: &[Vec<f64>], k: usize, seed: u64, max_iter: usize) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut centroids = vec![data[rng.random_range(0..data.len())].clone()];
    let mut d2: Vec<f64> = data.iter().map(|x| sq_dist(x, &centroids[0])).collect();
    while centroids.len() < k {
        let total: f64 = d2.iter().sum();
        let next = if total > 0.0 {
            let mut u = rng.random::<f64>() * total;
            let mut idx = data.len() - 1;
            for (i, w) in d2.iter().enumerate() {
                if u < *w {
                    idx = i;
                    break;
                }
                u -= w;
            }
            idx
        } else {
            rng.random_range(0..data.len())
        };
        centroids.push(data[next].clone());
        for (d, x) in d2.iter_mut().zip(data) {
            *d = d.min(sq_dist(x, &centroids[centroids.len() - 1]));
        }
    }
    let dim = data[0].len();
    // the points and centroids flat (row after row), so that a Lloyd pass reads contiguous
    // memory; the distances are summed as in `sq_dist`, so the assignments are the same
    let flat: Vec<f64> = data.iter().flatten().copied().collect();
    let mut assign = vec![usize::MAX; data.len()];
    for _ in 0..max_iter {
        let cflat: Vec<f64> = centroids.iter().flatten().copied().collect();
        let changed = assign_nearest(&flat, &cflat, dim, &mut assign);
        if !changed {
            break;
        }
        let mut sums = vec![vec![0.0; dim]; k];
        let mut counts = vec![0usize; k];
        for (a, x) in assign.iter().zip(data) {
            counts[*a] += 1;
            for (s, v) in sums[*a].iter_mut().zip(x) {
                *s += v;
            }
        }
        for j in 0..k {
            if counts[j] > 0 {
                centroids[j] = sums[j].iter().map(|s| s / counts[j] as f64).collect();
            } else {
                // re-seed an empty cluster with the worst-fitted point
                let far = (0..data.len())
                    .max_by(|&a, &b| {
                        sq_dist(&data[a], &centroids[assign[a]])
                            .total_cmp(&sq_dist(&data[b], &centroids[assign[b]]))
                    })
                    .unwrap_or(0);
                centroids[j] = data[far].clone();
            }
        }
    }
    centroids
}

fn train(seqs: &[Vec<Vec<f64>>], k: usize, params: &HmmParams) -> Result<HmmModel> {
    let all: Vec<Vec<f64>> = seqs.iter().flatten().cloned().collect();
    if all.len() < k {
        return Err(Error::TooShort {
            what: "training displacements for the HMM",
            needed: k,
            got: all.len(),
        });
    }
    let dim = all[0].len();
    let centroids = kmeans(&all, k, params.seed, params.max_iterations);
    // counted transitions with Laplace smoothing
    let mut counts = vec![vec![1.0; k]; k];
    let mut initial = vec![1.0; k];
    let mut sse = 0.0;
    for seq in seqs {
        let states: Vec<usize> = seq.iter().map(|d| nearest(&centroids, d)).collect();
        if let Some(&s0) = states.first() {
            initial[s0] += 1.0;
        }
        for w in states.windows(2) {
            counts[w[0]][w[1]] += 1.0;
        }
        sse += seq
            .iter()
            .zip(&states)
            .map(|(d, &s)| sq_dist(d, &centroids[s]))
            .sum::<f64>();
    }
    let transition = counts
        .into_iter()
        .map(|row| {
            let s: f64 = row.iter().sum();
            row.into_iter().map(|c| c / s).collect()
        })
        .collect();
    let total: f64 = initial.iter().sum();
    let initial = initial.into_iter().map(|c| c / total).collect();
    // isotropic emission variance; floored so identical displacements do not give zero
    let scale = all.iter().map(|d| sq_dist(d, &vec![0.0; dim])).sum::<f64>() / all.len() as f64;
    let emission_variance = (sse / (all.len() * dim) as f64).max(1e-12 * scale.max(1e-12));
    Ok(HmmModel {
        dim,
        centroids,
        transition,
        initial,
        emission_variance,
    })
}

/// `dist` pushed through the transition matrix `t` (row-major, `k x k`),
/// `out[j] = sum_i dist[i] T[i][j]`. Each `out[j]` is one sum over `i` in order, exactly as a
/// plain `.sum()` forms it (from `-0.0`, a product then an addition each); [`BLOCK`] of them
/// are carried side by side, reading a contiguous piece of each row, so that the additions
/// run in vectors and do not wait for each other. The last `k % BLOCK` are plain sums.
fn push_through(t: &[Vec<f64>], dist: &[f64]) -> Vec<f64> {
    let k = dist.len();
    let mut out = vec![0.0; k];
    let mut blocks = out.chunks_exact_mut(BLOCK);
    for (b, o) in (&mut blocks).enumerate() {
        let cols = b * BLOCK..(b + 1) * BLOCK;
        let mut acc = [-0.0f64; BLOCK];
        for (row, &p) in t.iter().zip(dist) {
            for (a, &v) in acc.iter_mut().zip(&row[cols.clone()]) {
                *a += p * v;
            }
        }
        o.copy_from_slice(&acc);
    }
    let done = k - blocks.into_remainder().len();
    for (j, o) in out.iter_mut().enumerate().skip(done) {
        *o = t.iter().zip(dist).map(|(row, &p)| p * row[j]).sum();
    }
    out
}

/// Outputs carried together by [`push_through`].
const BLOCK: usize = 16;

impl HmmModel {
    /// Forward-filtered distribution of the state of the last displacement.
    fn filter(&self, disp: &[Vec<f64>]) -> Vec<f64> {
        let mut alpha = self.initial.clone();
        for (t, d) in disp.iter().enumerate() {
            let prior: Vec<f64> = if t == 0 {
                self.initial.clone()
            } else {
                push_through(&self.transition, &alpha)
            };
            let log_e: Vec<f64> = self
                .centroids
                .iter()
                .map(|c| -sq_dist(c, d) / (2.0 * self.emission_variance))
                .collect();
            let m = log_e.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let mut post: Vec<f64> = prior
                .iter()
                .zip(&log_e)
                .map(|(p, l)| p * (l - m).exp())
                .collect();
            let s: f64 = post.iter().sum();
            if s > 0.0 && s.is_finite() {
                post.iter_mut().for_each(|p| *p /= s);
                alpha = post;
            } else {
                alpha = prior;
            }
        }
        alpha
    }

    /// Expected displacements of the next `horizon` steps, given the filtered distribution.
    fn expected_displacements(&self, mut dist: Vec<f64>, horizon: usize) -> Vec<Vec<f64>> {
        let k = self.centroids.len();
        (0..horizon)
            .map(|_| {
                dist = push_through(&self.transition, &dist);
                (0..self.dim)
                    .map(|a| (0..k).map(|j| dist[j] * self.centroids[j][a]).sum())
                    .collect()
            })
            .collect()
    }

    fn predict(&self, history: &Trajectory, horizon: usize, window: usize) -> Vec<Vec<f64>> {
        let disp = displacements(history);
        let recent = &disp[disp.len().saturating_sub(window)..];
        let steps = if recent.is_empty() {
            // no displacement observed yet: the first one is distributed as `initial`
            self.expected_from_initial(self.initial.clone(), horizon)
        } else {
            self.expected_displacements(self.filter(recent), horizon)
        };
        self.cumulate(history, steps)
    }

    fn expected_from_initial(&self, first: Vec<f64>, horizon: usize) -> Vec<Vec<f64>> {
        let mean_of = |dist: &[f64]| -> Vec<f64> {
            (0..self.dim)
                .map(|a| {
                    dist.iter()
                        .zip(&self.centroids)
                        .map(|(p, c)| p * c[a])
                        .sum()
                })
                .collect()
        };
        let mut out = vec![mean_of(&first)];
        if horizon > 1 {
            out.extend(self.expected_displacements(first, horizon - 1));
        }
        out
    }

    fn cumulate(&self, history: &Trajectory, disp: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
        let mut pos = history.last_point().to_vec();
        disp.into_iter()
            .map(|d| {
                pos.iter_mut().zip(&d).for_each(|(p, d)| *p += d);
                pos.clone()
            })
            .collect()
    }
}

impl Predictor for Hmm {
    fn name(&self) -> &str {
        "hmm"
    }

    fn fitted_summary(&self) -> Option<String> {
        self.model
            .as_ref()
            .map(|m| format!("{} motion states", m.centroids.len()))
    }

    /// `{"centroids": K x dim, "transition": K x K, "initial": K, "emission_variance"}`.
    fn fitted_params(&self) -> Result<serde_json::Value> {
        self.model
            .as_ref()
            .map(HmmModel::to_json)
            .ok_or_else(|| Error::NotFitted {
                method: "hmm".into(),
            })
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        self.model = Some(HmmModel::from_json(params)?);
        Ok(())
    }

    fn fit(&mut self, train_set: &[Trajectory]) -> Result<()> {
        let seqs: Vec<Vec<Vec<f64>>> = train_set
            .iter()
            .map(displacements)
            .filter(|s| !s.is_empty())
            .collect();
        if seqs.is_empty() {
            return Err(Error::Empty {
                what: "training displacements (every trajectory has a single point)",
            });
        }
        let dim = seqs[0][0].len();
        if let Some(bad) = seqs.iter().find(|s| s[0].len() != dim) {
            return Err(Error::DimensionMismatch {
                what: "training trajectories",
                expected: dim,
                got: bad[0].len(),
            });
        }
        let k = match self.params.states {
            Some(k) => k,
            None => choose_k(&seqs, &self.params)?,
        };
        self.model = Some(train(&seqs, k, &self.params)?);
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, 1)?;
        let model = self.model.as_ref().ok_or_else(|| Error::NotFitted {
            method: "hmm".into(),
        })?;
        if history.dim() != model.dim {
            return Err(Error::DimensionMismatch {
                what: "history vs fitted HMM",
                expected: model.dim,
                got: history.dim(),
            });
        }
        Forecast::new(
            history.dim(),
            model.predict(history, horizon, self.params.filter_window),
        )
    }
}

/// Most held-out forecast origins K is scored on (spread evenly over the held-out
/// trajectories), which bounds the cost of choosing among large K.
const CHOOSE_K_ORIGINS: usize = 4000;

/// Chooses K among the candidates by the error the forecasts are judged by: the mean position
/// error over steps 1..=`horizon` of forecasts on held-out training trajectories (every fifth
/// one; the last 20 % of every sequence when there are fewer than five), each K fitted on
/// the rest. Never the test data.
fn choose_k(seqs: &[Vec<Vec<f64>>], params: &HmmParams) -> Result<usize> {
    let (fit, held): (Vec<_>, Vec<_>) = if seqs.len() >= 5 {
        let (f, h): (Vec<_>, Vec<_>) = seqs.iter().enumerate().partition(|(i, _)| i % 5 != 4);
        (
            f.into_iter().map(|(_, s)| s.clone()).collect(),
            h.into_iter().map(|(_, s)| s.clone()).collect(),
        )
    } else {
        seqs.iter()
            .map(|s| {
                let cut = (s.len() * 4).div_ceil(5).max(1);
                (s[..cut].to_vec(), s[cut..].to_vec())
            })
            .unzip()
    };
    let h = params.horizon;
    // (sequence, displacements seen) of every held-out origin with `h` displacements after it
    let origins: Vec<(usize, usize)> = held
        .iter()
        .enumerate()
        .flat_map(|(i, s)| (1..=s.len().saturating_sub(h)).map(move |j| (i, j)))
        .collect();
    let stride = origins.len().div_ceil(CHOOSE_K_ORIGINS).max(1);
    let total_fit: usize = fit.iter().map(Vec::len).sum();
    let mut best: Option<(usize, f64)> = None;
    for &k in &params.candidates {
        if k > total_fit {
            continue;
        }
        let model = train(&fit, k, params)?;
        // each origin's step errors in parallel, then summed in the origins' order
        let chosen: Vec<(usize, usize)> = origins.iter().step_by(stride).copied().collect();
        let per_origin: Vec<Vec<f64>> = chosen
            .par_iter()
            .map(|&(i, j)| {
                let seq = &held[i];
                let recent = &seq[j.saturating_sub(params.filter_window)..j];
                let pred = model.expected_displacements(model.filter(recent), h);
                let (mut p, mut t) = (vec![0.0; model.dim], vec![0.0; model.dim]);
                pred.iter()
                    .zip(&seq[j..j + h])
                    .map(|(step, d)| {
                        for a in 0..model.dim {
                            p[a] += step[a];
                            t[a] += d[a];
                        }
                        sq_dist(&p, &t).sqrt()
                    })
                    .collect()
            })
            .collect();
        let (mut err, mut n) = (0.0, 0usize);
        for e in per_origin.iter().flatten() {
            err += e;
            n += 1;
        }
        let score = if n > 0 { err / n as f64 } else { f64::INFINITY };
        if best.is_none_or(|(_, s)| score < s) {
            best = Some((k, score));
        }
    }
    best.map(|(k, _)| k).ok_or(Error::TooShort {
        what: "training displacements for the smallest candidate K",
        needed: params.candidates.iter().copied().min().unwrap_or(1),
        got: total_fit,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pseudo-random row-stochastic matrix and distribution of `k` states (no RNG crate:
    /// a fixed sine sequence).
    fn model(k: usize) -> HmmModel {
        let v = |i: usize| ((i as f64 * 12.9898).sin() * 43758.5453).fract().abs() + 1e-3;
        let transition = (0..k)
            .map(|i| {
                let row: Vec<f64> = (0..k).map(|j| v(i * k + j)).collect();
                let s: f64 = row.iter().sum();
                row.into_iter().map(|x| x / s).collect()
            })
            .collect();
        HmmModel {
            dim: 2,
            centroids: (0..k).map(|j| vec![v(7 * j), -v(7 * j + 1)]).collect(),
            transition,
            initial: vec![1.0 / k as f64; k],
            emission_variance: 0.3,
        }
    }

    /// The blocked product equals the plain column sums bit for bit (the fit's choice of K
    /// and every forecast depend on it), at sizes around the block.
    #[test]
    fn push_through_is_the_plain_sum_bit_for_bit() {
        for k in [1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 33, 128] {
            let m = model(k);
            let dist: Vec<f64> = (0..k).map(|i| m.transition[k / 2][i]).collect();
            let want: Vec<f64> = (0..k)
                .map(|j| (0..k).map(|i| dist[i] * m.transition[i][j]).sum())
                .collect();
            let got = push_through(&m.transition, &dist);
            assert_eq!(
                got.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                want.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                "k = {k}"
            );
        }
    }

    /// The parallel, flat assignment step picks what `nearest` picks (the first of equal
    /// distances included) and reports a change exactly when one happened, across several
    /// rayon chunks.
    #[test]
    fn assign_nearest_matches_nearest() {
        let m = model(9);
        let mut cents = m.centroids.clone();
        cents.push(cents[3].clone()); // an exact tie: the first index must win
        let points: Vec<Vec<f64>> = (0..3 * ASSIGN_CHUNK + 17)
            .map(|i| vec![((i as f64) * 0.37).sin(), ((i as f64) * 0.11).cos() - 0.5])
            .collect();
        let flat: Vec<f64> = points.iter().flatten().copied().collect();
        let cflat: Vec<f64> = cents.iter().flatten().copied().collect();
        let mut assign = vec![usize::MAX; points.len()];
        assert!(assign_nearest(&flat, &cflat, 2, &mut assign));
        let want: Vec<usize> = points.iter().map(|x| nearest(&cents, x)).collect();
        assert_eq!(assign, want);
        assert!(!assign.contains(&(cents.len() - 1)));
        assert!(!assign_nearest(&flat, &cflat, 2, &mut assign));
        assign[2 * ASSIGN_CHUNK + 5] = usize::MAX;
        assert!(assign_nearest(&flat, &cflat, 2, &mut assign));
    }
}
