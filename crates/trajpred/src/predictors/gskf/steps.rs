//! Where each axis's LAR paths stop, chosen on held-out groups: the regularisation of
//! [`Gsc`](super::Gsc) and [`Gskf`](super::Gskf) when they are fitted on several groups.

use super::{AxisFilter, CV_FOLDS, GskfParams, axis_series, errors, fit_gsc};
use crate::predictors::auto::{fold_of_trajectories, fold_split};
use std::fmt::Write as _;
use trajpred_core::{Result, Trajectory};

/// Per axis, the number of LAR steps of every horizon's fit (`None`: the full path, whose end
/// is least squares), chosen among the full path and 1 to `m - 1` steps by the mean absolute
/// error of the plain GSC pooled over [`CV_FOLDS`] folds by group: fitted on the other
/// folds, scored on the held-out one's rolling origins. The full path wins ties. Returns the
/// choice per axis and, in words, every option's held-out error.
pub(super) fn choose_steps(
    params: &GskfParams,
    train: &[Trajectory],
    groups: &[usize],
) -> Result<(Vec<Option<usize>>, String)> {
    let (fold, k) = fold_of_trajectories(groups, CV_FOLDS, 0)?;
    let dim = train.first().map_or(0, Trajectory::dim);
    let needed = params.window + params.horizons + 1;
    let options: Vec<Option<usize>> = std::iter::once(None)
        .chain((1..params.window).map(Some))
        .collect();
    // per axis, per option: absolute errors and their count (infinite: failed in a fold)
    let mut sae = vec![vec![(0.0, 0usize); options.len()]; dim];
    for f in 0..k {
        let (fit, _, held) = fold_split(train, groups, &fold, f);
        for (a, row) in sae.iter_mut().enumerate() {
            let (fit_series, held_series) =
                (axis_series(&fit, a, needed), axis_series(&held, a, needed));
            for (o, &steps) in options.iter().enumerate() {
                let filter = fit_gsc(params, &fit_series, steps).and_then(AxisFilter::plain);
                match filter {
                    Ok(filter) => {
                        let (_, e, n) = errors(&filter, &held_series)?;
                        row[o].0 += e;
                        row[o].1 += n;
                    }
                    Err(_) => row[o].0 = f64::INFINITY,
                }
            }
        }
    }
    let mut said = format!("LAR steps chosen per axis by {k}-fold cross-validation by group");
    let mut chosen = Vec::with_capacity(dim);
    for (a, row) in sae.iter().enumerate() {
        let mae = |o: usize| match row[o] {
            (e, n) if n > 0 && e.is_finite() => e / n as f64,
            _ => f64::INFINITY,
        };
        let best = (0..options.len()).fold(0, |b, o| if mae(o) < mae(b) { o } else { b });
        let _ = write!(said, "; axis {a}, held-out mean absolute error:");
        for (o, steps) in options.iter().enumerate() {
            let name = steps.map_or("full path".to_string(), |s| format!("{s} steps"));
            let _ = write!(said, " {name} {:.4e},", mae(o));
        }
        let _ = write!(
            said,
            " -> {}",
            options[best].map_or("full path".to_string(), |s| format!("{s} steps"))
        );
        chosen.push(options[best]);
    }
    Ok((chosen, said))
}
