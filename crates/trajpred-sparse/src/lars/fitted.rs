//! The fitted path ([`Lars`]): knots, events, the final model, predictions.

use super::{Exclusion, LarsParams, PathEvent, StopReason};
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use trajpred_core::Error as CoreError;

/// A fitted LARS path: every knot, the events that changed the active set, and the final
/// model on the original scale.
///
/// Knot `k` (0-based) holds `alphas()[k]` and row `k` of [`Lars::coef_path`]; knot 0 is the
/// all-zero model (the intercept alone) at the largest alpha. Between knots the coefficients
/// are linear in alpha.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Lars {
    pub(super) params: LarsParams,
    pub(super) n_features: usize,
    pub(super) alphas: Vec<f64>,
    pub(super) std_path: DMatrix<f64>,
    /// `None` when it equals `std_path` (no column scaling)
    pub(super) coef_path: Option<DMatrix<f64>>,
    pub(super) intercepts: Vec<f64>,
    pub(super) events: Vec<PathEvent>,
    pub(super) active: Vec<usize>,
    pub(super) excluded: Vec<Exclusion>,
    pub(super) stop: StopReason,
    pub(super) x_mean: Vec<f64>,
    pub(super) x_scale: Vec<f64>,
    pub(super) y_mean: f64,
}

impl Lars {
    /// A builder with the defaults of [`LarsParams`].
    pub fn params() -> LarsParams {
        LarsParams::default()
    }

    /// The parameters the path was computed with.
    pub fn parameters(&self) -> &LarsParams {
        &self.params
    }

    /// Number of columns of the design.
    pub fn n_features(&self) -> usize {
        self.n_features
    }

    /// Number of knots (at least 1).
    pub fn n_knots(&self) -> usize {
        self.alphas.len()
    }

    /// Alpha at every knot, non-increasing: `max_j |x_j^T r| / n` in the standardised
    /// problem (scikit-learn's convention), `r` the residual at that knot.
    pub fn alphas(&self) -> &[f64] {
        &self.alphas
    }

    /// Coefficients at every knot on the original scale: row `k` is knot `k`, `knots x p`.
    pub fn coef_path(&self) -> &DMatrix<f64> {
        self.coef_path.as_ref().unwrap_or(&self.std_path)
    }

    /// Coefficients at every knot in the standardised problem (centred and/or unit-norm
    /// columns), the coordinates in which LAR moves; `knots x p`.
    pub fn standardized_coef_path(&self) -> &DMatrix<f64> {
        &self.std_path
    }

    /// The intercept at every knot (all zero without `fit_intercept`).
    pub fn intercepts(&self) -> &[f64] {
        &self.intercepts
    }

    /// Final coefficients (last knot), original scale.
    pub fn coef(&self) -> DVector<f64> {
        let last = self.alphas.len() - 1;
        self.coef_path().row(last).transpose()
    }

    /// Final intercept (last knot).
    pub fn intercept(&self) -> f64 {
        self.intercepts[self.intercepts.len() - 1]
    }

    /// Changes of the active set in order: additions and (lasso) drops.
    pub fn events(&self) -> &[PathEvent] {
        &self.events
    }

    /// The active set at the end of the path, in order of entry (scikit-learn's `active`).
    pub fn active(&self) -> &[usize] {
        &self.active
    }

    /// Columns kept out of the path (zero variance or collinear), sorted by column.
    pub fn excluded(&self) -> &[Exclusion] {
        &self.excluded
    }

    /// Why the path ended.
    pub fn stop_reason(&self) -> StopReason {
        self.stop
    }

    /// Column means subtracted before the path (zeros without an intercept).
    pub fn x_mean(&self) -> &[f64] {
        &self.x_mean
    }

    /// Column scales divided out before the path (ones without normalisation).
    pub fn x_scale(&self) -> &[f64] {
        &self.x_scale
    }

    /// Target mean subtracted before the path (zero without an intercept).
    pub fn y_mean(&self) -> f64 {
        self.y_mean
    }

    /// Prediction of the final model for one sample `row` (length p), original scale.
    pub fn predict_row(&self, row: &[f64]) -> Result<f64> {
        self.predict_row_at(self.alphas.len() - 1, row)
    }

    /// Prediction of the model at knot `knot` for one sample.
    pub fn predict_row_at(&self, knot: usize, row: &[f64]) -> Result<f64> {
        if knot >= self.alphas.len() {
            return Err(CoreError::InvalidParameter {
                name: "knot",
                reason: format!("path has {} knots, got {knot}", self.alphas.len()),
            }
            .into());
        }
        if row.len() != self.n_features {
            return Err(CoreError::DimensionMismatch {
                what: "sample length vs features",
                expected: self.n_features,
                got: row.len(),
            }
            .into());
        }
        if let Some(i) = row.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite {
                what: "sample",
                index: i,
            }
            .into());
        }
        let b = self.coef_path().row(knot);
        Ok(self.intercepts[knot] + b.iter().zip(row).map(|(b, x)| b * x).sum::<f64>())
    }

    /// Predictions of the final model for every row of `x` (n x p), original scale.
    pub fn predict(&self, x: &DMatrix<f64>) -> Result<DVector<f64>> {
        if x.ncols() != self.n_features {
            return Err(CoreError::DimensionMismatch {
                what: "design columns vs features",
                expected: self.n_features,
                got: x.ncols(),
            }
            .into());
        }
        for j in 0..x.ncols() {
            if let Some(row) = x.column(j).iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFiniteEntry {
                    what: "design",
                    row,
                    col: j,
                });
            }
        }
        let mut out = x * self.coef();
        out.add_scalar_mut(self.intercept());
        Ok(out)
    }
}
