//! N-point polynomial extrapolation (`docs/papers.md` B.2): the KF-dynamic paper's "N-point linear
//! approximation" (degree 1) and "N-point quadratic fitting" (degree 2).

use super::{invalid, step_interval};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use trajpred_core::{Error, Forecast, Predictor, Result, Trajectory, check_forecast_args};

/// Parameters of [`PolyFit`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PolyFitParams {
    /// Polynomial degree: 1 (linear) or 2 (quadratic).
    pub degree: usize,
    /// Number of most recent points fitted (the paper: N = 5). At least `degree + 1`.
    pub points: usize,
}

impl Default for PolyFitParams {
    fn default() -> Self {
        PolyFitParams {
            degree: 1,
            points: 5,
        }
    }
}

/// Least-squares fit of each coordinate as a polynomial in time over the last N points,
/// extrapolated to the next steps.
///
/// Time is measured from the last point, so the fit is well conditioned whatever the epoch;
/// step `k` is predicted at `t_last + k dt`, with `dt` the mean sampling interval of the fitted
/// points (see `docs/evaluation.md`).
///
/// ```
/// use trajpred::predictors::{PolyFit, PolyFitParams};
/// use trajpred_core::{Predictor, Trajectory};
/// let tr = Trajectory::uniform(0.0, 1.0, vec![vec![0.0, 1.0, 4.0, 9.0, 16.0]])?; // x = t^2
/// let p = PolyFit::new(PolyFitParams { degree: 2, points: 5 })?;
/// let f = p.forecast(&tr, 2)?;
/// assert!((f.step(1)[0] - 25.0).abs() < 1e-9 && (f.step(2)[0] - 36.0).abs() < 1e-9);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PolyFit {
    params: PolyFitParams,
    name: String,
}

impl PolyFit {
    /// A validated predictor: degree 1 or 2, and at least `degree + 1` points.
    pub fn new(params: PolyFitParams) -> Result<Self> {
        if !(1..=2).contains(&params.degree) {
            return Err(invalid(
                "degree",
                format!("must be 1 or 2, got {}", params.degree),
            ));
        }
        if params.points < params.degree + 1 {
            return Err(invalid(
                "points",
                format!(
                    "a degree-{} fit needs at least {} points, got {}",
                    params.degree,
                    params.degree + 1,
                    params.points
                ),
            ));
        }
        Ok(PolyFit {
            name: format!("poly{}", params.degree),
            params,
        })
    }

    /// The parameters.
    pub fn params(&self) -> PolyFitParams {
        self.params
    }
}

impl Predictor for PolyFit {
    fn name(&self) -> &str {
        &self.name
    }

    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }

    fn fitted_params(&self) -> Result<serde_json::Value> {
        Ok(serde_json::Value::Null)
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        trajpred_core::load_nothing(self.name(), params)
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let n = self.params.points;
        let start = history.len() - n;
        let times = &history.times()[start..];
        let t_last = times[n - 1];
        let cols = self.params.degree + 1;
        // Vandermonde design in (t - t_last), scaled by dt for conditioning
        let dt = step_interval(history, n);
        let design = DMatrix::from_fn(n, cols, |i, j| ((times[i] - t_last) / dt).powi(j as i32));
        let svd = design.svd(true, true);
        let mut steps = vec![vec![0.0; history.dim()]; horizon];
        for (axis, values) in history.axes().enumerate() {
            let y = DVector::from_column_slice(&values[start..]);
            let coef = svd
                .solve(&y, 1e-12)
                .map_err(|reason| Error::InvalidParameter {
                    name: "points",
                    reason: format!("least-squares fit failed: {reason}"),
                })?;
            for (k, step) in steps.iter_mut().enumerate() {
                let s = (k + 1) as f64;
                step[axis] = (0..cols).map(|j| coef[j] * s.powi(j as i32)).sum();
            }
        }
        Forecast::new(history.dim(), steps)
    }

    fn min_history(&self) -> usize {
        self.params.points
    }
}
