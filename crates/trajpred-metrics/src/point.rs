//! Point-wise error measures.

use crate::error::{check_finite, first_of_pair};
use crate::{MetricsError, Result};
use serde::{Deserialize, Serialize};
use trajpred_core::Error as CoreError;

/// Checks a (predicted, actual) pair of point lists and returns the common number of axes.
fn check<P: AsRef<[f64]>, Q: AsRef<[f64]>>(predicted: &[P], actual: &[Q]) -> Result<usize> {
    let first = first_of_pair(
        predicted,
        actual,
        "actual points vs predicted points",
        "points",
    )?;
    let dim = first.as_ref().len();
    if dim == 0 {
        return Err(CoreError::Empty { what: "point 0" }.into());
    }
    for (index, (p, a)) in predicted.iter().zip(actual).enumerate() {
        let (p, a) = (p.as_ref(), a.as_ref());
        for got in [p.len(), a.len()] {
            if got != dim {
                return Err(CoreError::PointDimension {
                    index,
                    expected: dim,
                    got,
                }
                .into());
            }
        }
        check_finite(p, "predicted", index)?;
        check_finite(a, "actual", index)?;
    }
    Ok(dim)
}

fn squared_distance(p: &[f64], a: &[f64]) -> f64 {
    p.iter().zip(a).map(|(p, a)| (p - a) * (p - a)).sum()
}

/// Euclidean error `||p_i - x_i||` of every point.
///
/// ```
/// assert_eq!(trajpred_metrics::euclidean_errors(&[[3.0, 4.0]], &[[0.0, 0.0]])?, vec![5.0]);
/// # Ok::<(), trajpred_metrics::MetricsError>(())
/// ```
pub fn euclidean_errors<P: AsRef<[f64]>, Q: AsRef<[f64]>>(
    predicted: &[P],
    actual: &[Q],
) -> Result<Vec<f64>> {
    check(predicted, actual)?;
    Ok(predicted
        .iter()
        .zip(actual)
        .map(|(p, a)| squared_distance(p.as_ref(), a.as_ref()).sqrt())
        .collect())
}

/// Root mean square error of each axis: `sqrt(sum_i (p_ik - x_ik)^2 / N)` for axis `k`.
///
/// ```
/// let r = trajpred_metrics::rmse(&[[1.0, 0.0], [1.0, 2.0]], &[[0.0, 0.0], [0.0, 0.0]])?;
/// assert_eq!(r, vec![1.0, 2.0f64.sqrt()]);
/// # Ok::<(), trajpred_metrics::MetricsError>(())
/// ```
pub fn rmse<P: AsRef<[f64]>, Q: AsRef<[f64]>>(predicted: &[P], actual: &[Q]) -> Result<Vec<f64>> {
    let dim = check(predicted, actual)?;
    let mut sums = vec![0.0; dim];
    for (p, a) in predicted.iter().zip(actual) {
        for ((s, p), a) in sums.iter_mut().zip(p.as_ref()).zip(a.as_ref()) {
            *s += (p - a) * (p - a);
        }
    }
    let n = predicted.len() as f64;
    Ok(sums.into_iter().map(|s| (s / n).sqrt()).collect())
}

/// Root mean square of the Euclidean error, for points of any number of axes:
/// `sqrt(sum_i ||p_i - x_i||^2 / N)`.
pub fn rms_euclidean_error<P: AsRef<[f64]>, Q: AsRef<[f64]>>(
    predicted: &[P],
    actual: &[Q],
) -> Result<f64> {
    check(predicted, actual)?;
    let total: f64 = predicted
        .iter()
        .zip(actual)
        .map(|(p, a)| squared_distance(p.as_ref(), a.as_ref()))
        .sum();
    Ok((total / predicted.len() as f64).sqrt())
}

/// The 3-D RMSE of eq. 21 of the GSKF paper: `sqrt(sum_i (dx_i^2 + dy_i^2 + dz_i^2) / N)`.
/// Points must have exactly 3 axes (use [`rms_euclidean_error`] for other dimensions).
pub fn rmse_3d<P: AsRef<[f64]>, Q: AsRef<[f64]>>(predicted: &[P], actual: &[Q]) -> Result<f64> {
    let dim = check(predicted, actual)?;
    if dim != 3 {
        return Err(CoreError::DimensionMismatch {
            what: "point axes (rmse_3d)",
            expected: 3,
            got: dim,
        }
        .into());
    }
    rms_euclidean_error(predicted, actual)
}

/// Mean Euclidean error `sum_i ||p_i - x_i|| / N`. This is what the KF-dynamic paper
/// (definition 3) calls "RMSE"; it is a mean distance, not a root mean square.
pub fn mean_euclidean_error<P: AsRef<[f64]>, Q: AsRef<[f64]>>(
    predicted: &[P],
    actual: &[Q],
) -> Result<f64> {
    let errors = euclidean_errors(predicted, actual)?;
    Ok(errors.iter().sum::<f64>() / errors.len() as f64)
}

/// Share of predictions whose Euclidean error is strictly below `threshold` (the KF-dynamic
/// paper's accuracy at 25 m, definition 4). `threshold` must be finite and positive.
pub fn hit_rate<P: AsRef<[f64]>, Q: AsRef<[f64]>>(
    predicted: &[P],
    actual: &[Q],
    threshold: f64,
) -> Result<f64> {
    if !(threshold.is_finite() && threshold > 0.0) {
        return Err(CoreError::invalid_parameter(
            "threshold",
            format!("must be finite and positive, got {threshold}"),
        )
        .into());
    }
    let errors = euclidean_errors(predicted, actual)?;
    let hits = errors.iter().filter(|&&e| e < threshold).count();
    Ok(hits as f64 / errors.len() as f64)
}

/// Relative RMSE of the MKPF paper: `sqrt(mean over points i and axes k of ((p_ik - x_ik) / x_ik)^2)`.
/// Undefined where a true coordinate is zero: [`MetricsError::ZeroReference`] names the first.
pub fn relative_rmse<P: AsRef<[f64]>, Q: AsRef<[f64]>>(
    predicted: &[P],
    actual: &[Q],
) -> Result<f64> {
    let dim = check(predicted, actual)?;
    let mut sum = 0.0;
    for (index, (p, a)) in predicted.iter().zip(actual).enumerate() {
        for (axis, (p, a)) in p.as_ref().iter().zip(a.as_ref()).enumerate() {
            if *a == 0.0 {
                return Err(MetricsError::ZeroReference { index, axis });
            }
            let r = (p - a) / a;
            sum += r * r;
        }
    }
    Ok((sum / (predicted.len() * dim) as f64).sqrt())
}

/// Mean and variance of the per-point Euclidean errors (GSKF paper, Table 4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErrorStatistics {
    /// Number of points.
    pub count: usize,
    /// Mean of the per-point Euclidean errors.
    pub mean: f64,
    /// Population variance (divided by N) of the per-point Euclidean errors.
    pub variance: f64,
}

/// Mean and population variance of the per-point Euclidean errors.
///
/// The paper does not say whether its variance divides by N or N - 1; we divide by N (the
/// difference is below 0.5% for its 200 test points).
pub fn error_statistics<P: AsRef<[f64]>, Q: AsRef<[f64]>>(
    predicted: &[P],
    actual: &[Q],
) -> Result<ErrorStatistics> {
    let errors = euclidean_errors(predicted, actual)?;
    let n = errors.len() as f64;
    let mean = errors.iter().sum::<f64>() / n;
    let variance = errors.iter().map(|e| (e - mean) * (e - mean)).sum::<f64>() / n;
    Ok(ErrorStatistics {
        count: errors.len(),
        mean,
        variance,
    })
}

/// Errors of multi-step forecasts, step by step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PerHorizon {
    /// Number of forecasts.
    pub count: usize,
    /// Mean Euclidean error at step `k + 1`.
    pub mean_euclidean: Vec<f64>,
    /// Root mean square Euclidean error at step `k + 1`.
    pub rms_euclidean: Vec<f64>,
}

impl PerHorizon {
    /// Average displacement error: the mean Euclidean error over every step of every forecast.
    pub fn ade(&self) -> f64 {
        self.mean_euclidean.iter().sum::<f64>() / self.mean_euclidean.len() as f64
    }

    /// Final displacement error: the mean Euclidean error at the last step.
    pub fn fde(&self) -> f64 {
        self.mean_euclidean.last().copied().unwrap_or(f64::NAN)
    }
}

/// Per-step errors of `forecasts[j]` (a list of H predicted points) against `actual[j]` (the H
/// true points that followed origin j). Every forecast must have the same horizon H >= 1.
///
/// ```
/// use trajpred_metrics::per_horizon;
/// let forecasts = vec![vec![[1.0], [2.0]], vec![[0.0], [4.0]]];
/// let actual = vec![vec![[0.0], [0.0]], vec![[0.0], [0.0]]];
/// let h = per_horizon(&forecasts, &actual)?;
/// assert_eq!(h.mean_euclidean, vec![0.5, 3.0]);
/// assert_eq!((h.ade(), h.fde()), (1.75, 3.0));
/// # Ok::<(), trajpred_metrics::MetricsError>(())
/// ```
pub fn per_horizon<F, A, P, Q>(forecasts: &[F], actual: &[A]) -> Result<PerHorizon>
where
    F: AsRef<[P]>,
    A: AsRef<[Q]>,
    P: AsRef<[f64]>,
    Q: AsRef<[f64]>,
{
    let first = first_of_pair(forecasts, actual, "actual tracks vs forecasts", "forecasts")?;
    let horizon = first.as_ref().len();
    if horizon == 0 {
        return Err(CoreError::Empty { what: "forecast 0" }.into());
    }
    let mut sum = vec![0.0; horizon];
    let mut sum_sq = vec![0.0; horizon];
    let mut dim = None;
    for (index, (f, a)) in forecasts.iter().zip(actual).enumerate() {
        let (f, a) = (f.as_ref(), a.as_ref());
        for got in [f.len(), a.len()] {
            if got != horizon {
                return Err(MetricsError::ItemDimensionMismatch {
                    what: "forecast",
                    index,
                    expected: horizon,
                    got,
                });
            }
        }
        let d = check(f, a).map_err(|e| match e {
            // report the forecast index, not the step index
            MetricsError::Core(CoreError::NonFinite { what, .. }) => {
                CoreError::NonFinite { what, index }.into()
            }
            MetricsError::Core(CoreError::PointDimension { expected, got, .. }) => {
                MetricsError::ItemDimensionMismatch {
                    what: "forecast point",
                    index,
                    expected,
                    got,
                }
            }
            other => other,
        })?;
        let d0 = *dim.get_or_insert(d);
        if d != d0 {
            return Err(MetricsError::ItemDimensionMismatch {
                what: "forecast point",
                index,
                expected: d0,
                got: d,
            });
        }
        for (k, (p, x)) in f.iter().zip(a).enumerate() {
            let sq = squared_distance(p.as_ref(), x.as_ref());
            sum[k] += sq.sqrt();
            sum_sq[k] += sq;
        }
    }
    let n = forecasts.len() as f64;
    Ok(PerHorizon {
        count: forecasts.len(),
        mean_euclidean: sum.into_iter().map(|s| s / n).collect(),
        rms_euclidean: sum_sq.into_iter().map(|s| (s / n).sqrt()).collect(),
    })
}
