//! Small numerical helpers shared by every filter: checks of finiteness, shape and
//! definiteness, Cholesky factorisation with typed errors, symmetrisation.

use crate::error::{KalmanError, Result};
use nalgebra::allocator::Allocator;
use nalgebra::{Cholesky, DefaultAllocator, Dim, Matrix, OMatrix, RealField, Storage};
use trajpred_core::Gaussian;

/// Errors with [`KalmanError::NonFinite`] if any element of `m` is NaN or infinite.
pub(crate) fn check_finite<T, R, C, S>(m: &Matrix<T, R, C, S>, what: &'static str) -> Result<()>
where
    T: RealField + Copy,
    R: Dim,
    C: Dim,
    S: Storage<T, R, C>,
{
    match m.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(KalmanError::NonFinite { what, index }),
        None => Ok(()),
    }
}

/// Errors with [`KalmanError::DimensionMismatch`] unless `got == expected`.
pub(crate) fn check_dim(what: &'static str, expected: usize, got: usize) -> Result<()> {
    if expected == got {
        Ok(())
    } else {
        Err(KalmanError::DimensionMismatch {
            what,
            expected,
            got,
        })
    }
}

/// Checks that `m` is `n x n`.
pub(crate) fn check_square<T, R, C, S>(
    m: &Matrix<T, R, C, S>,
    n: usize,
    what: &'static str,
) -> Result<()>
where
    T: RealField + Copy,
    R: Dim,
    C: Dim,
    S: Storage<T, R, C>,
{
    check_dim(what, n, m.nrows())?;
    check_dim(what, n, m.ncols())
}

/// Cholesky factor of a symmetric positive definite matrix, or
/// [`KalmanError::NotPositiveDefinite`] naming `what`.
pub(crate) fn cholesky<T, D>(m: OMatrix<T, D, D>, what: &'static str) -> Result<Cholesky<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    Cholesky::new(m).ok_or(KalmanError::NotPositiveDefinite { what })
}

/// Symmetry tolerance: `sqrt(eps)` relative to the largest magnitude (at least 1).
fn symmetry_tolerance<T: RealField + Copy>(scale: T) -> T {
    T::default_epsilon().sqrt() * scale.max(T::one())
}

/// Checks that a square matrix is finite, symmetric (to `sqrt(eps)` relative) and positive
/// semi-definite: the Cholesky factorisation of `m + 64 n eps max|m| I` must exist, which
/// accepts rank-deficient matrices such as the discrete white-noise `Q` while rejecting any
/// eigenvalue below about `-64 n eps max|m|`.
pub(crate) fn check_psd<T, D>(m: &OMatrix<T, D, D>, what: &'static str) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    check_finite(m, what)?;
    let n = m.nrows();
    let scale = m.amax();
    let tol = symmetry_tolerance(scale);
    for j in 0..n {
        if m[(j, j)] < T::zero() {
            return Err(KalmanError::NotPositiveDefinite { what });
        }
        for i in 0..j {
            if (m[(i, j)] - m[(j, i)]).abs() > tol {
                return Err(KalmanError::NotPositiveDefinite { what });
            }
        }
    }
    if scale == T::zero() {
        return Ok(());
    }
    let jitter = T::default_epsilon() * nalgebra::convert::<f64, T>(64.0 * n as f64) * scale;
    let mut shifted = m.clone();
    for i in 0..n {
        shifted[(i, i)] += jitter;
    }
    cholesky(shifted, what).map(|_| ())
}

/// Checks that `m` is symmetric positive definite (its Cholesky factor exists).
pub(crate) fn check_pd<T, D>(m: &OMatrix<T, D, D>, what: &'static str) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    check_finite(m, what)?;
    let n = m.nrows();
    let tol = symmetry_tolerance(m.amax());
    for j in 0..n {
        for i in 0..j {
            if (m[(i, j)] - m[(j, i)]).abs() > tol {
                return Err(KalmanError::NotPositiveDefinite { what });
            }
        }
    }
    cholesky(m.clone(), what).map(|_| ())
}

/// Validates a Gaussian state of dimension `n`: shapes, finite values, and a symmetric
/// positive semi-definite covariance (see [`check_psd`]).
pub(crate) fn check_state<T, D>(state: &Gaussian<T, D>, n: usize) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    check_dim("state mean", n, state.mean.nrows())?;
    check_square(&state.covariance, n, "state covariance")?;
    check_finite(&state.mean, "state mean")?;
    check_psd(&state.covariance, "P")
}

/// Replaces `m` by its symmetric part `(m + m^T) / 2` in place.
pub(crate) fn symmetrise<T, D>(m: &mut OMatrix<T, D, D>)
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let n = m.nrows();
    let half = nalgebra::convert::<f64, T>(0.5);
    for j in 0..n {
        for i in 0..j {
            let v = (m[(i, j)] + m[(j, i)]) * half;
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
    }
}

/// `ln det A` from the Cholesky factor of `A`.
pub(crate) fn log_det<T, D>(chol: &Cholesky<T, D>) -> T
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let l = chol.l_dirty();
    let mut s = T::zero();
    for i in 0..l.nrows() {
        s += l[(i, i)].ln();
    }
    s + s
}
