//! The fixed-interval Rauch-Tung-Striebel smoother over time-varying steps: one filter per
//! step (built for that step's interval), so that states at irregular times — as frames
//! around a gap in the reports — are smoothed with the right transition for each interval.
//! [`Smoother`] smooths with one filter for every step; [`smooth_steps`] takes a filter per
//! step, and [`filter_smooth_steps`] runs the forward filter and then the backward pass.
//!
//! The recursion is [`Smoother`]'s, with the filter of step `k` (state `k` to state `k+1`):
//! for `k = N-2 .. 0`, `G(k) = C(k) P(k+1|k)^-1`,
//! `x_s(k) = x(k|k) + G(k) (x_s(k+1) - x(k+1|k))`,
//! `P_s(k) = P(k|k) + G(k) (P_s(k+1) - P(k+1|k)) G(k)^T`, with `C(k) = P(k|k) F(k)^T` for the
//! linear KF (`F(k)` the transition of step `k`), the Jacobian's for the EKF and the
//! sigma-point cross-covariance for the UKF. `P(k+1|k)` is factorised (`L D L^T`), never
//! inverted.

use crate::alloc::FilterAllocator;
use crate::error::Result;
use crate::filter::{RtsSmoothed, Smoother, Step, rts_backward};
use nalgebra::{DefaultAllocator, Dim, OVector, RealField};
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;

/// The forward pass and the backward pass of [`filter_smooth_steps`].
#[derive(Debug, Clone, PartialEq)]
pub struct ForwardBackward<T: RealField, D: Dim, M: Dim>
where
    DefaultAllocator: FilterAllocator<D, M>,
{
    /// The forward filter's steps, one per filter (time points `1 .. N-1`).
    pub steps: Vec<Step<T, D, M>>,
    /// The filtered states at every time point `0 .. N-1` (the first is the initial state).
    pub filtered: Vec<Gaussian<T, D>>,
    /// The smoothed states at every time point and the gains `G(0) .. G(N-2)`.
    pub smoothed: RtsSmoothed<T, D>,
}

/// Smooths `filtered` (the filtered states at time points `0 .. N-1`, in time order) where
/// `filters[k]` is the filter of the step from time point `k` to `k+1` (so there is one
/// filter fewer than states). Returns the smoothed states (the last one is the last filtered
/// state) and the gains `G(k)`, `k = 0 .. N-2`.
///
/// Errors: [`trajpred_core::Error::Empty`] for no states,
/// [`trajpred_core::Error::LengthMismatch`] when `filters.len() != filtered.len() - 1`,
/// [`trajpred_core::Error::NotPositiveDefinite`] (`"P(k+1|k)"`) when a prediction's covariance
/// cannot be factorised, [`trajpred_core::Error::NonFinite`] for an overflowing result, and the
/// filters' own prediction errors.
pub fn smooth_steps<T, D, M, F>(
    filters: &[F],
    filtered: &[Gaussian<T, D>],
) -> Result<RtsSmoothed<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    F: Smoother<T, D, M>,
    DefaultAllocator: FilterAllocator<D, M>,
{
    if filtered.is_empty() {
        return Err(CoreError::Empty {
            what: "filtered states",
        }
        .into());
    }
    if filters.len() + 1 != filtered.len() {
        return Err(CoreError::LengthMismatch {
            what: "filters (one per step between filtered states)",
            expected: filtered.len() - 1,
            got: filters.len(),
        }
        .into());
    }
    rts_backward(filtered, |k| &filters[k])
}

/// Filters forward from `initial` (the state at time point 0) with `filters[k]` over the step
/// to time point `k+1`, updating by `observations[k]` when present (a `None` is a time point
/// with no observation, e.g. a frame inside a gap), then smooths backward with the same filters
/// ([`smooth_steps`]).
///
/// Errors: [`trajpred_core::Error::LengthMismatch`] when `observations` and `filters` differ in
/// length, and the errors of the filters' steps and of [`smooth_steps`].
///
/// A constant-velocity target observed at 0, 1 and 2 s and then after a 30 s gap: the
/// smoother estimates the position inside the gap from both sides.
///
/// ```
/// use nalgebra::{Matrix1, Matrix1x2, Matrix2, Vector1, Vector2};
/// use trajpred_core::Gaussian;
/// use trajpred_kalman::smoother::filter_smooth_steps;
/// use trajpred_kalman::{Kf, LinearObservation, LinearTransition};
/// let cv = |dt: f64| {
///     let q = 0.01 * Matrix2::new(dt.powi(3) / 3.0, dt * dt / 2.0, dt * dt / 2.0, dt);
///     let tr = LinearTransition::new(Matrix2::new(1.0, dt, 0.0, 1.0), q)?;
///     Kf::new(tr, LinearObservation::new(Matrix1x2::new(1.0, 0.0), Matrix1::new(1.0))?)
/// };
/// // time points 0, 1, 2, 17 (inside the gap, no observation), 32
/// let filters = [cv(1.0)?, cv(1.0)?, cv(15.0)?, cv(15.0)?];
/// let z = |x: f64| Some(Vector1::new(x));
/// let observations = [z(10.0), z(20.0), None, z(320.0)];
/// let x0 = Gaussian { mean: Vector2::new(0.0, 0.0), covariance: Matrix2::new(1.0, 0.0, 0.0, 100.0) };
/// let fb = filter_smooth_steps(&filters, &x0, &observations)?;
/// let (forward, smoothed) = (fb.filtered[3].mean[0], fb.smoothed.states[3].mean[0]);
/// // the truth at 17 s is 170 m: the forecast from 2 s misses, the smoother nearly hits it
/// assert!((smoothed - 170.0).abs() < 5.0);
/// assert!((smoothed - 170.0).abs() < (forward - 170.0).abs());
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
pub fn filter_smooth_steps<T, D, M, F>(
    filters: &[F],
    initial: &Gaussian<T, D>,
    observations: &[Option<OVector<T, M>>],
) -> Result<ForwardBackward<T, D, M>>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    F: Smoother<T, D, M>,
    DefaultAllocator: FilterAllocator<D, M>,
{
    if observations.len() != filters.len() {
        return Err(CoreError::LengthMismatch {
            what: "observations (one per filter)",
            expected: filters.len(),
            got: observations.len(),
        }
        .into());
    }
    let mut steps: Vec<Step<T, D, M>> = Vec::with_capacity(filters.len());
    let mut filtered = Vec::with_capacity(filters.len() + 1);
    filtered.push(initial.clone());
    for (filter, z) in filters.iter().zip(observations) {
        let prev = filtered.last().unwrap_or(initial);
        let step = filter.step(prev, z.as_ref())?;
        filtered.push(step.posterior().clone());
        steps.push(step);
    }
    let smoothed = smooth_steps(filters, &filtered)?;
    Ok(ForwardBackward {
        steps,
        filtered,
        smoothed,
    })
}
