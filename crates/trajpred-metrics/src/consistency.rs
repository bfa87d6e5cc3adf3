//! Filter consistency: NEES, NIS and their chi-square bounds.

use crate::error::{check_finite, first_of_pair};
use crate::{MetricsError, Result};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use trajpred_core::Error as CoreError;

/// Normalised squared errors `e_i^T P_i^-1 e_i`, solved through Cholesky (no inverse).
fn normalised_squares(errors: &[DVector<f64>], covariances: &[DMatrix<f64>]) -> Result<Vec<f64>> {
    let dim = first_of_pair(
        errors,
        covariances,
        "covariances vs error vectors",
        "errors",
    )?
    .len();
    errors
        .iter()
        .zip(covariances)
        .enumerate()
        .map(|(index, (e, p))| {
            if e.len() != dim {
                return Err(MetricsError::ItemDimensionMismatch {
                    what: "error vector",
                    index,
                    expected: dim,
                    got: e.len(),
                });
            }
            if p.nrows() != dim || p.ncols() != dim {
                return Err(MetricsError::ItemDimensionMismatch {
                    what: "covariance",
                    index,
                    expected: dim,
                    got: if p.nrows() != dim {
                        p.nrows()
                    } else {
                        p.ncols()
                    },
                });
            }
            check_finite(e, "error vector", index)?;
            check_finite(p, "covariance", index)?;
            let chol = p
                .clone()
                .cholesky()
                .ok_or(MetricsError::CovarianceNotPositiveDefinite { index })?;
            Ok(e.dot(&chol.solve(e)))
        })
        .collect()
}

/// Normalised estimation error squared of each step: `(x_i - x_hat_i)^T P_i^-1 (x_i - x_hat_i)`,
/// with `errors[i] = x_i - x_hat_i` and `covariances[i] = P_i`. For a consistent filter each is
/// chi-square distributed with `dim` degrees of freedom.
///
/// ```
/// use nalgebra::{dmatrix, dvector};
/// let v = trajpred_metrics::nees(&[dvector![2.0, 0.0]], &[dmatrix![4.0, 0.0; 0.0, 1.0]])?;
/// assert!((v[0] - 1.0).abs() < 1e-12);
/// # Ok::<(), trajpred_metrics::MetricsError>(())
/// ```
pub fn nees(errors: &[DVector<f64>], covariances: &[DMatrix<f64>]) -> Result<Vec<f64>> {
    normalised_squares(errors, covariances)
}

/// Normalised innovation squared of each update: `nu_i^T S_i^-1 nu_i`, with innovations `nu_i`
/// and their covariances `S_i`. Chi-square with `dim(z)` degrees of freedom when consistent.
pub fn nis(innovations: &[DVector<f64>], covariances: &[DMatrix<f64>]) -> Result<Vec<f64>> {
    normalised_squares(innovations, covariances)
}

/// Two-sided `confidence` bounds for the AVERAGE of `samples` independent chi-square values
/// with `dof` degrees of freedom each: `N * average ~ chi2(N * dof)`, so the bounds are
/// `chi2_inv((1 -+ confidence) / 2; N dof) / N`.
///
/// ```
/// // chi2(2) is exponential with mean 2: its quantile q is -2 ln(1 - q)
/// let (lo, hi) = trajpred_metrics::chi_square_bounds(2, 1, 0.95)?;
/// assert!((lo - (-2.0 * 0.975f64.ln())).abs() < 1e-9);
/// assert!((hi - (-2.0 * 0.025f64.ln())).abs() < 1e-9);
/// # Ok::<(), trajpred_metrics::MetricsError>(())
/// ```
pub fn chi_square_bounds(dof: usize, samples: usize, confidence: f64) -> Result<(f64, f64)> {
    if dof == 0 {
        return Err(CoreError::invalid_parameter(
            "degrees of freedom",
            "must be at least 1, got 0",
        )
        .into());
    }
    if samples == 0 {
        return Err(CoreError::Empty { what: "samples" }.into());
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(CoreError::invalid_parameter(
            "confidence",
            format!("must lie in (0, 1), got {confidence}"),
        )
        .into());
    }
    let k = (dof * samples) as f64;
    let chi = ChiSquared::new(k).map_err(|e| {
        CoreError::invalid_parameter(
            "degrees of freedom",
            format!("{dof} x {samples} samples = {k} gives no chi-square distribution: {e}"),
        )
    })?;
    let n = samples as f64;
    let tail = (1.0 - confidence) / 2.0;
    Ok((chi.inverse_cdf(tail) / n, chi.inverse_cdf(1.0 - tail) / n))
}

/// The outcome of a chi-square consistency test on NEES or NIS values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Consistency {
    /// Average of the values.
    pub mean: f64,
    /// Lower bound for the average.
    pub lower: f64,
    /// Upper bound for the average.
    pub upper: f64,
    /// Whether `lower <= mean <= upper`.
    pub consistent: bool,
}

/// Tests whether the average of NEES (or NIS) `values`, each with `dof` degrees of freedom,
/// lies inside the two-sided `confidence` chi-square interval of [`chi_square_bounds`].
pub fn consistency(values: &[f64], dof: usize, confidence: f64) -> Result<Consistency> {
    if let Some(index) = values.iter().position(|v| !v.is_finite() || *v < 0.0) {
        return Err(CoreError::NonFinite {
            what: "values (or a negative value)",
            index,
        }
        .into());
    }
    let (lower, upper) = chi_square_bounds(dof, values.len(), confidence)?;
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    Ok(Consistency {
        mean,
        lower,
        upper,
        consistent: (lower..=upper).contains(&mean),
    })
}
