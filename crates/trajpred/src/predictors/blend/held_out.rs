//! The held-out forecasts a [`Blend`](super::Blend) chooses its weights on, the greedy
//! selection, and the speed regimes.

use trajpred_core::Trajectory;

/// `weights[r][k][c]`: candidate `c`'s weight in regime `r` at step `k`.
pub(super) type Weights = Vec<Vec<Vec<f64>>>;

/// The speed between the fixes at `o - 1` and `o` of `tr` (0 for the first fix or a zero
/// time step): what a blend's regime is read from, the same for a held-out origin and for
/// the last fix of a history.
pub(super) fn speed_at(tr: &Trajectory, o: usize) -> f64 {
    if o == 0 || o >= tr.len() {
        return 0.0;
    }
    let dt = tr.times()[o] - tr.times()[o - 1];
    let (a, b) = (tr.point(o), tr.point(o - 1));
    let dist = a
        .as_ref()
        .iter()
        .zip(b.as_ref())
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt();
    if dt > 0.0 && dist.is_finite() {
        dist / dt
    } else {
        0.0
    }
}

/// The regime of `speed`: how many of the (increasing) `edges` it exceeds.
pub(super) fn regime_of(edges: &[f64], speed: f64) -> usize {
    edges.iter().filter(|&&e| speed > e).count()
}

/// Edges splitting `speeds` into at most `regimes` groups of about equal size: the largest
/// value of each group but the last (a speed above an edge is in a later group), repeated
/// values dropped (so the groups may be fewer).
pub(super) fn quantile_edges(mut speeds: Vec<f64>, regimes: usize) -> Vec<f64> {
    speeds.sort_by(f64::total_cmp);
    let mut edges: Vec<f64> = Vec::new();
    if speeds.is_empty() {
        return edges;
    }
    for j in 1..regimes {
        let Some(i) = ((j * speeds.len()) / regimes).checked_sub(1) else {
            continue;
        };
        let e = speeds[i];
        if edges.last().is_none_or(|&l| e > l) && e < speeds[speeds.len() - 1] {
            edges.push(e);
        }
    }
    edges
}

/// The held-out forecasts of every candidate on the same origins, and the truth.
pub(super) struct HeldOut {
    pub(super) horizon: usize,
    pub(super) dim: usize,
    /// `truth[(i * horizon + k) * dim + a]`
    pub(super) truth: Vec<f64>,
    /// One per usable candidate: its index among the candidates and its forecasts, laid out
    /// like `truth`.
    pub(super) forecasts: Vec<(usize, Vec<f64>)>,
    /// Per origin: the last observed speed ([`speed_at`]).
    pub(super) speed: Vec<f64>,
    /// Per origin: the fold it was held out in.
    pub(super) fold: Vec<usize>,
}

impl HeldOut {
    pub(super) fn origins(&self) -> usize {
        self.truth.len() / (self.horizon * self.dim)
    }

    /// Mean error at step `k` over the origins `idx` of the forecast `sum / m` (`sum[j]` is
    /// the summed forecast of origin `idx[j]`, `dim` values each).
    pub(super) fn error(&self, k: usize, idx: &[usize], sum: &[f64], m: f64) -> f64 {
        let (h, d) = (self.horizon, self.dim);
        let mut total = 0.0;
        for (j, &i) in idx.iter().enumerate() {
            let t = &self.truth[(i * h + k) * d..][..d];
            let s = &sum[j * d..][..d];
            total += t
                .iter()
                .zip(s)
                .map(|(t, s)| (s / m - t).powi(2))
                .sum::<f64>()
                .sqrt();
        }
        total / idx.len().max(1) as f64
    }

    /// Greedy selection with replacement at step `k` on the origins `idx` (Caruana et al.,
    /// 2004): each round adds the candidate whose copy lowers the held-out mean error most;
    /// the counts of the best round are kept. Returns the counts per usable candidate, the
    /// rounds they sum to and the error (no round and an infinite error for no origin).
    pub(super) fn select(
        &self,
        k: usize,
        rounds: usize,
        idx: &[usize],
    ) -> (Vec<usize>, usize, f64) {
        let (h, d, n) = (self.horizon, self.dim, idx.len());
        let mut sum = vec![0.0; n * d];
        let mut counts = vec![0usize; self.forecasts.len()];
        let mut best = (counts.clone(), 0usize, f64::INFINITY);
        if n == 0 {
            return best;
        }
        let mut trial = vec![0.0; n * d];
        for round in 1..=rounds {
            let mut pick = None::<(usize, f64)>;
            for (c, (_, f)) in self.forecasts.iter().enumerate() {
                for (j, &i) in idx.iter().enumerate() {
                    let p = &f[(i * h + k) * d..][..d];
                    for a in 0..d {
                        trial[j * d + a] = sum[j * d + a] + p[a];
                    }
                }
                let e = self.error(k, idx, &trial, round as f64);
                if pick.is_none_or(|(_, b)| e < b) {
                    pick = Some((c, e));
                }
            }
            let Some((c, e)) = pick else { break };
            counts[c] += 1;
            for (j, &i) in idx.iter().enumerate() {
                let p = &self.forecasts[c].1[(i * h + k) * d..][..d];
                for a in 0..d {
                    sum[j * d + a] += p[a];
                }
            }
            if e < best.2 {
                best = (counts.clone(), round, e);
            }
        }
        best
    }

    /// The weights chosen on the origins `idx`, regime by regime (`edges` split them by
    /// speed); a regime none of `idx` falls in takes the weights chosen on all of `idx`.
    pub(super) fn fit_weights(&self, idx: &[usize], edges: &[f64], rounds: usize) -> Weights {
        let as_weights = |(counts, used, _): (Vec<usize>, usize, f64)| -> Vec<f64> {
            counts
                .iter()
                .map(|&n| n as f64 / used.max(1) as f64)
                .collect()
        };
        let all: Vec<Vec<f64>> = (0..self.horizon)
            .map(|k| as_weights(self.select(k, rounds, idx)))
            .collect();
        if edges.is_empty() {
            return vec![all];
        }
        (0..=edges.len())
            .map(|r| {
                let sub: Vec<usize> = idx
                    .iter()
                    .copied()
                    .filter(|&i| regime_of(edges, self.speed[i]) == r)
                    .collect();
                if sub.is_empty() {
                    return all.clone();
                }
                (0..self.horizon)
                    .map(|k| as_weights(self.select(k, rounds, &sub)))
                    .collect()
            })
            .collect()
    }

    /// The mean error (over origins and steps) of the weights `w` with regimes `edges` on
    /// the origins `idx`.
    fn blend_error(&self, w: &Weights, edges: &[f64], idx: &[usize]) -> f64 {
        let (h, d) = (self.horizon, self.dim);
        let mut total = 0.0;
        let mut p = vec![0.0; d];
        for &i in idx {
            let wr = &w[regime_of(edges, self.speed[i])];
            for (k, wk) in wr.iter().enumerate() {
                p.iter_mut().for_each(|x| *x = 0.0);
                for ((_, f), &wc) in self.forecasts.iter().zip(wk) {
                    for (a, x) in p.iter_mut().enumerate() {
                        *x += wc * f[(i * h + k) * d + a];
                    }
                }
                let t = &self.truth[(i * h + k) * d..][..d];
                total += t
                    .iter()
                    .zip(&p)
                    .map(|(t, x)| (x - t).powi(2))
                    .sum::<f64>()
                    .sqrt();
            }
        }
        total / (idx.len() * h).max(1) as f64
    }

    /// Cross-validation over the held-out folds of a blend with up to `regimes` speed
    /// regimes: for each fold, edges and weights chosen on the other folds' origins, scored
    /// on this fold's. The mean error over every origin and step.
    pub(super) fn cv_error(&self, regimes: usize, rounds: usize, folds: usize) -> f64 {
        let (mut total, mut count) = (0.0, 0usize);
        for f in 0..folds {
            let (train, test): (Vec<usize>, Vec<usize>) =
                (0..self.origins()).partition(|&i| self.fold[i] != f);
            if train.is_empty() || test.is_empty() {
                continue;
            }
            let edges = quantile_edges(train.iter().map(|&i| self.speed[i]).collect(), regimes);
            let w = self.fit_weights(&train, &edges, rounds);
            total += self.blend_error(&w, &edges, &test) * test.len() as f64;
            count += test.len();
        }
        if count == 0 {
            f64::INFINITY
        } else {
            total / count as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{HeldOut, quantile_edges, regime_of};

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
            speed: vec![0.0; 2],
            fold: vec![0; 2],
        };
        assert_eq!(held.select(0, 1, &[0, 1]), (vec![1, 0], 1, 2.0));
        assert_eq!(held.select(0, 5, &[0, 1]), (vec![1, 1], 2, 0.0));
        // a third candidate at 0 everywhere wins alone at round 1
        let held = HeldOut {
            forecasts: vec![
                (0, vec![1.0, 3.0]),
                (1, vec![-1.0, -3.0]),
                (2, vec![0.0, 0.0]),
            ],
            ..held
        };
        assert_eq!(held.select(0, 5, &[0, 1]), (vec![0, 0, 1], 1, 0.0));
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
            speed: vec![0.0; 2],
            fold: vec![0; 2],
        };
        assert_eq!(held.select(0, 3, &[0, 1]), (vec![1, 0], 1, 0.0));
        assert_eq!(held.select(1, 3, &[0, 1]), (vec![0, 1], 1, 0.0));
    }

    /// Quantile edges, worked by hand: 8 speeds into 4 groups of 2 cut after the 2nd, 4th
    /// and 6th smallest values; repeated values give fewer edges, and no edge at the largest
    /// value (nothing could exceed it).
    #[test]
    fn quantile_edges_and_regimes_match_the_hand_worked_cases() {
        let v = vec![7.0, 0.0, 1.0, 6.0, 2.0, 5.0, 3.0, 4.0];
        assert_eq!(quantile_edges(v, 4), vec![1.0, 3.0, 5.0]);
        assert_eq!(
            quantile_edges(vec![0.0, 0.0, 0.0, 0.0, 0.0, 9.0], 3),
            vec![0.0]
        );
        assert_eq!(quantile_edges(vec![3.0; 5], 4), Vec::<f64>::new());
        assert_eq!(quantile_edges(vec![1.0, 2.0], 1), Vec::<f64>::new());
        let edges = [2.0, 4.0, 6.0];
        assert_eq!(regime_of(&edges, 0.0), 0);
        assert_eq!(regime_of(&edges, 2.0), 0);
        assert_eq!(regime_of(&edges, 2.5), 1);
        assert_eq!(regime_of(&edges, 100.0), 3);
    }

    /// Two regimes that want different candidates, worked by hand: slow origins (speed 0)
    /// are exact for A, fast ones (speed 10) for B. With one regime every mix of A and B has
    /// error 1, so the first round's A alone is kept; two regimes give each its own
    /// candidate (error 0), and the cross-validation over folds sees it.
    #[test]
    fn each_speed_regime_gets_its_own_weights() {
        // 8 origins, 1 step, 1 axis; truth 0 at slow origins, 2 at fast ones
        let slow = |i: usize| i.is_multiple_of(2);
        let held = HeldOut {
            horizon: 1,
            dim: 1,
            truth: (0..8).map(|i| if slow(i) { 0.0 } else { 2.0 }).collect(),
            forecasts: vec![(0, vec![0.0; 8]), (1, vec![2.0; 8])],
            speed: (0..8).map(|i| if slow(i) { 0.0 } else { 10.0 }).collect(),
            fold: (0..8).map(|i| i / 2 % 2).collect(),
        };
        let all: Vec<usize> = (0..8).collect();
        let one = held.fit_weights(&all, &[], 4);
        assert_eq!(one, vec![vec![vec![1.0, 0.0]]]);
        assert!((held.blend_error(&one, &[], &all) - 1.0).abs() < 1e-12);
        let edges = quantile_edges(held.speed.clone(), 2);
        assert_eq!(edges, vec![0.0]);
        let two = held.fit_weights(&all, &edges, 4);
        assert_eq!(two, vec![vec![vec![1.0, 0.0]], vec![vec![0.0, 1.0]]]);
        assert_eq!(held.blend_error(&two, &edges, &all), 0.0);
        assert!((held.cv_error(1, 4, 2) - 1.0).abs() < 1e-12);
        assert_eq!(held.cv_error(2, 4, 2), 0.0);
    }
}
