//! Where each axis's LAR paths stop, chosen on held-out groups: the regularisation of
//! [`Gsc`](super::Gsc) and [`Gskf`](super::Gskf) when they are fitted on several groups.

use super::{AxisFilter, CV_FOLDS, GskfParams, axis_series, errors, fit_gsc};
use crate::predictors::auto::{fold_of_trajectories, fold_split};
use std::fmt::Write as _;
use trajpred_core::{Result, Trajectory};

/// How one axis's GSC is fitted: in which frame
/// ([`GscParams::relative`](trajpred_sparse::GscParams::relative)) and where every horizon's
/// LAR path stops (`None`: the full path, whose end is least squares).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct AxisFit {
    pub(super) relative: bool,
    pub(super) steps: Option<usize>,
}

impl AxisFit {
    fn name(self) -> String {
        let steps = self
            .steps
            .map_or("full path".to_string(), |s| format!("{s} steps"));
        if self.relative {
            format!("relative {steps}")
        } else {
            steps
        }
    }
}

/// Per axis, the number of LAR steps of every horizon's fit (`None`: the full path), chosen
/// among the full path and 1 to `m - 1` steps (in both frames with
/// [`GskfParams::choose_frame`], else in `params.relative`'s) by the mean absolute error of
/// the plain GSC pooled over [`CV_FOLDS`] folds by group: fitted on the other folds, scored
/// on the held-out one's rolling origins. The first option wins ties: the full path, in
/// absolute values when both frames are tried. Returns the choice per axis and, in words,
/// every option's held-out error.
pub(super) fn choose_steps(
    params: &GskfParams,
    train: &[Trajectory],
    groups: &[usize],
) -> Result<(Vec<AxisFit>, String)> {
    let (fold, k) = fold_of_trajectories(groups, CV_FOLDS, 0)?;
    let dim = train.first().map_or(0, Trajectory::dim);
    let needed = params.window + params.horizons + 1;
    let frames: &[bool] = if params.choose_frame {
        &[false, true]
    } else if params.relative {
        &[true]
    } else {
        &[false]
    };
    let options: Vec<AxisFit> = frames
        .iter()
        .flat_map(|&relative| {
            std::iter::once(None)
                .chain((1..params.window).map(Some))
                .map(move |steps| AxisFit { relative, steps })
        })
        .collect();
    // per axis, per option: absolute errors and their count (infinite: failed in a fold)
    let mut sae = vec![vec![(0.0, 0usize); options.len()]; dim];
    for f in 0..k {
        let (fit, _, held) = fold_split(train, groups, &fold, f);
        for (a, row) in sae.iter_mut().enumerate() {
            let (fit_series, held_series) =
                (axis_series(&fit, a, needed), axis_series(&held, a, needed));
            for (o, &option) in options.iter().enumerate() {
                let filter = fit_gsc(params, &fit_series, option).and_then(AxisFilter::plain);
                match filter {
                    Ok(filter) => {
                        let (_, e, n) = errors(&filter, &held_series, 0)?;
                        row[o].0 += e;
                        row[o].1 += n;
                    }
                    Err(_) => row[o].0 = f64::INFINITY,
                }
            }
        }
    }
    let what = if params.choose_frame {
        "frame and LAR steps"
    } else {
        "LAR steps"
    };
    let mut said = format!("{what} chosen per axis by {k}-fold cross-validation by group");
    let mut chosen = Vec::with_capacity(dim);
    for (a, row) in sae.iter().enumerate() {
        let mae = |o: usize| match row[o] {
            (e, n) if n > 0 && e.is_finite() => e / n as f64,
            _ => f64::INFINITY,
        };
        let best = (0..options.len()).fold(0, |b, o| if mae(o) < mae(b) { o } else { b });
        let _ = write!(said, "; axis {a}, held-out mean absolute error:");
        for (o, option) in options.iter().enumerate() {
            let _ = write!(said, " {} {:.4e},", option.name(), mae(o));
        }
        let _ = write!(said, " -> {}", options[best].name());
        chosen.push(options[best]);
    }
    Ok((chosen, said))
}
