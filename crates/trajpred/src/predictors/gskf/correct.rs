//! Whether each axis of a [`Gskf`](super::Gskf) fitted on several groups applies its Kalman
//! correction, and with which gain (the IKF's for a `q`, or one fitted to the training series
//! with some residual lags): chosen on held-out groups.

use super::gain::{self, Part};
use super::{
    AxisFilter, CV_FOLDS, GskfParams, axis_series, errors, fit_axes, mean_residual_variance,
};
use crate::predictors::auto::{fold_of_trajectories, fold_split};
use std::fmt::Write as _;
use trajpred_core::{Result, Trajectory};

/// Chooses per axis between the plain GSC, each `q` of the grid and a gain fitted with each
/// of `params.gain_lags` on [`CV_FOLDS`] folds by group: the GSC (and a fitted gain) fitted on
/// the other folds, scored on the held-out one's rolling origins (the same origins for every
/// option: from the first at which the longest lag has its residuals) by the mean absolute
/// error (the leaderboard's kind of measure). The best correction is the one with the
/// lowest error pooled over the folds; it replaces the plain GSC only
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
    let lags = &params.gain_lags;
    let longest = lags.iter().copied().max().unwrap_or(0);
    let options = 1 + grid.len() + lags.len();
    // per axis, per option (0: no correction, 1..: the grid, then the fitted gains), per
    // fold: absolute errors and count
    let mut sae: Vec<Vec<Vec<(f64, usize)>>> = Vec::new();
    // per axis, per option: why it first failed, for the summary
    let mut why: Vec<Vec<Option<String>>> = Vec::new();
    for f in 0..k {
        let (fit, _, held) = fold_split(train, groups, &fold, f);
        let Ok(coders) = fit_axes(params, &fit, steps) else {
            continue;
        };
        sae.resize(coders.len(), vec![vec![(0.0, 0); k]; options]);
        why.resize(coders.len(), vec![None; options]);
        for (a, gsc) in coders.into_iter().enumerate() {
            let series = axis_series(&held, a, needed);
            let fit_series = axis_series(&fit, a, needed);
            let scale = mean_residual_variance(&gsc);
            for o in 0..options {
                let filter = option_filter(&gsc, o, params, scale, &fit_series);
                let filter = match filter {
                    Ok(filter) => filter,
                    Err(e) => {
                        sae[a][o][f].0 = f64::INFINITY;
                        why[a][o].get_or_insert_with(|| format!("fold {f}: {e}"));
                        continue;
                    }
                };
                let (_, e, n) = errors(&filter, &series, longest)?;
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
        let best_q = (1..options).fold(None, |b: Option<usize>, o| match b {
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
        for o in 1..options {
            let _ = write!(said, ", {}: {}", option_name(o, params, scale), shown(o));
        }
        if let (Some(o), Some((mean, se))) = (best_q, gain) {
            let _ = write!(
                said,
                "; gain of {} over the GSC per fold {mean:.4e} +- {se:.4e}",
                option_name(o, params, scale)
            );
        }
        let _ = write!(said, " -> {}", option_name(best, params, scale));
        let all = axis_series(train, a, needed);
        axes.push(option_filter(&gsc, best, params, scale, &all)?);
    }
    Ok((axes, said))
}

/// Option `o` of [`choose`] for a GSC: 0 the GSC alone, `1..=grid` the IKF with that `q`
/// (`scale` is the unit of the grid), then a gain with each of `params.gain_lags` fitted on
/// all the origins of `fit_series`.
fn option_filter(
    gsc: &trajpred_sparse::GroupSparseCoder,
    o: usize,
    params: &GskfParams,
    scale: f64,
    fit_series: &[&[f64]],
) -> Result<AxisFilter> {
    let g = params.q_grid.len();
    if o == 0 {
        AxisFilter::plain(gsc.clone())
    } else if o <= g {
        AxisFilter::new(gsc.clone(), (params.q_grid[o - 1] * scale).max(1e-300))
    } else {
        let lags = params.gain_lags[o - 1 - g];
        let fitted = gain::fit(gsc, fit_series, lags, 0, Part::All)?;
        AxisFilter::fitted(gsc.clone(), fitted)
    }
}

/// Option `o` of [`choose`] in words.
fn option_name(o: usize, params: &GskfParams, scale: f64) -> String {
    let g = params.q_grid.len();
    if o == 0 {
        "no correction".into()
    } else if o <= g {
        format!("q = {:.3e}", (params.q_grid[o - 1] * scale).max(1e-300))
    } else {
        format!("fitted gain with {} lags", params.gain_lags[o - 1 - g])
    }
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
