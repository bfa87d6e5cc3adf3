//! Whether each axis of a [`Gskf`](super::Gskf) fitted on several groups applies its Kalman
//! correction, and with which `q`: chosen on held-out groups.

use super::{
    AxisFilter, CV_FOLDS, GskfParams, axis_series, errors, fit_axes, mean_residual_variance,
};
use crate::predictors::auto::{fold_of_trajectories, fold_split};
use std::fmt::Write as _;
use trajpred_core::{Result, Trajectory};

/// Chooses per axis between the plain GSC and each `q` of the grid on [`CV_FOLDS`] folds
/// by group: the GSC fitted on the other folds, scored on the held-out one's rolling
/// origins by the mean absolute error (the leaderboard's kind of measure). The best `q`
/// is the one with the lowest error pooled over the folds; it replaces the plain GSC only
/// when it also gains consistently: its mean gain over the folds (the GSC's held-out error
/// minus its own, fold by fold) must exceed one standard error of that mean (the
/// one-standard-error rule, with paired folds: a gain that one wild held-out group makes
/// alone is not one that new groups can expect). Returns the filters refitted on all of
/// `train` and what was chosen, in words.
pub(super) fn choose(
    params: &GskfParams,
    train: &[Trajectory],
    groups: &[usize],
    steps: &[super::steps::AxisFit],
) -> Result<(Vec<AxisFilter>, String)> {
    let (fold, k) = fold_of_trajectories(groups, CV_FOLDS, 0)?;
    let needed = params.window + params.horizons + 1;
    let grid = &params.q_grid;
    // per axis, per option (0: no correction, 1..: the grid), per fold: absolute errors
    // and count
    let mut sae: Vec<Vec<Vec<(f64, usize)>>> = Vec::new();
    // per axis, per option: why it first failed, for the summary
    let mut why: Vec<Vec<Option<String>>> = Vec::new();
    for f in 0..k {
        let (fit, _, held) = fold_split(train, groups, &fold, f);
        let Ok(coders) = fit_axes(params, &fit, steps) else {
            continue;
        };
        sae.resize(coders.len(), vec![vec![(0.0, 0); k]; grid.len() + 1]);
        why.resize(coders.len(), vec![None; grid.len() + 1]);
        for (a, gsc) in coders.into_iter().enumerate() {
            let series = axis_series(&held, a, needed);
            let scale = mean_residual_variance(&gsc);
            for (o, g) in std::iter::once(None)
                .chain(grid.iter().map(Some))
                .enumerate()
            {
                let filter = match g {
                    None => AxisFilter::plain(gsc.clone()),
                    Some(&g) => AxisFilter::new(gsc.clone(), (g * scale).max(1e-300)),
                };
                let filter = match filter {
                    Ok(filter) => filter,
                    Err(e) => {
                        sae[a][o][f].0 = f64::INFINITY;
                        why[a][o].get_or_insert_with(|| format!("fold {f}: {e}"));
                        continue;
                    }
                };
                let (_, e, n) = errors(&filter, &series)?;
                sae[a][o][f] = (e, n);
            }
        }
    }
    let coders = fit_axes(params, train, steps)?;
    let mut said = format!("chosen per axis by {k}-fold cross-validation by group");
    let mut axes = Vec::with_capacity(coders.len());
    for (a, gsc) in coders.into_iter().enumerate() {
        let scale = mean_residual_variance(&gsc);
        let folds = |o: usize| sae.get(a).map_or(&[][..], |row| &row[o][..]);
        let mae = |o: usize| pooled_mae(folds(o));
        let best_q = (1..=grid.len()).fold(None, |b: Option<usize>, o| match b {
            Some(b) if mae(b) <= mae(o) => Some(b),
            _ if mae(o).is_finite() => Some(o),
            _ => b,
        });
        let gain = best_q.and_then(|o| paired_gain(folds(0), folds(o)));
        let best = match (best_q, gain) {
            (Some(o), Some((mean, se))) if mae(o) < mae(0) && mean > se => o,
            _ => 0,
        };
        let shown = |o: usize| {
            let e = mae(o);
            match (e.is_finite(), why.get(a).and_then(|w| w[o].as_deref())) {
                (true, _) => format!("{e:.4e}"),
                (false, Some(reason)) => format!("failed ({reason})"),
                (false, None) => "failed in a fold".into(),
            }
        };
        let _ = write!(
            said,
            "; held-out mean absolute error, axis {a}: GSC alone {}",
            shown(0)
        );
        for (j, g) in grid.iter().enumerate() {
            let _ = write!(said, ", q = {:.3e}: {}", g * scale, shown(j + 1));
        }
        if let (Some(o), Some((mean, se))) = (best_q, gain) {
            let _ = write!(
                said,
                "; gain of q = {:.3e} over the GSC per fold {mean:.4e} +- {se:.4e}",
                grid[o - 1] * scale
            );
        }
        let filter = if best == 0 {
            let _ = write!(said, " -> no correction");
            AxisFilter::plain(gsc)?
        } else {
            let q = (grid[best - 1] * scale).max(1e-300);
            let _ = write!(said, " -> q = {q:.3e}");
            AxisFilter::new(gsc, q)?
        };
        axes.push(filter);
    }
    Ok((axes, said))
}

/// The mean absolute error pooled over folds of `(sum of absolute errors, count)`; infinite
/// when a fold failed or there are no errors.
fn pooled_mae(folds: &[(f64, usize)]) -> f64 {
    let (e, n) = folds
        .iter()
        .fold((0.0, 0usize), |(e, n), &(fe, fnn)| (e + fe, n + fnn));
    if n > 0 && e.is_finite() {
        e / n as f64
    } else {
        f64::INFINITY
    }
}

/// The mean over folds of `base`'s held-out mean absolute error minus `other`'s, and the
/// standard error of that mean (sample standard deviation over `sqrt(folds)`), over the folds
/// where both have errors; `None` with fewer than two such folds or a failed fold.
fn paired_gain(base: &[(f64, usize)], other: &[(f64, usize)]) -> Option<(f64, f64)> {
    let d: Vec<f64> = base
        .iter()
        .zip(other)
        .filter(|&(&(_, nb), &(_, no))| nb > 0 && no > 0)
        .map(|(&(eb, nb), &(eo, no))| eb / nb as f64 - eo / no as f64)
        .collect();
    if d.len() < 2 || d.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let k = d.len() as f64;
    let mean = d.iter().sum::<f64>() / k;
    let var = d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
    Some((mean, (var / k).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooled_error_weighs_folds_by_their_counts() {
        // (10 + 2) / (4 + 2) = 2
        assert_eq!(pooled_mae(&[(10.0, 4), (2.0, 2)]), 2.0);
        assert_eq!(pooled_mae(&[(10.0, 4), (f64::INFINITY, 0)]), f64::INFINITY);
        assert_eq!(pooled_mae(&[]), f64::INFINITY);
    }

    #[test]
    fn paired_gain_is_the_mean_fold_difference_and_its_standard_error() {
        // per-fold errors: base 3, 5, 4; other 2, 2, 4 -> differences 1, 3, 0: mean 4/3,
        // sample variance ((1 - 4/3)^2 + (3 - 4/3)^2 + (4/3)^2) / 2 = 7/3, se sqrt(7/9)
        let base = [(6.0, 2), (5.0, 1), (12.0, 3)];
        let other = [(4.0, 2), (2.0, 1), (12.0, 3)];
        let (mean, se) = paired_gain(&base, &other).unwrap();
        assert!((mean - 4.0 / 3.0).abs() < 1e-15, "{mean}");
        assert!((se - (7.0f64 / 9.0).sqrt()).abs() < 1e-15, "{se}");
        // one fold, or a failed one: no verdict
        assert_eq!(paired_gain(&base[..1], &other[..1]), None);
        assert_eq!(
            paired_gain(&base, &[(4.0, 2), (f64::INFINITY, 1), (12.0, 3)]),
            None
        );
    }
}
