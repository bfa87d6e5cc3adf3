//! Small numerical helpers shared by every filter: checks of finiteness, shape and
//! definiteness, Cholesky factorisation with typed errors, symmetrisation.

use crate::error::{KalmanError, Result};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, Matrix, OMatrix, RealField, Storage};
use trajpred_core::Gaussian;

/// Errors with [`KalmanError::NonFinite`] if any element of `m` is NaN or infinite.
#[inline(always)]
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
#[inline(always)]
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
#[inline(always)]
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

/// The lower Cholesky factor `L` (`A = L L^T`) of a symmetric positive definite matrix,
/// computed in place by a plain Cholesky-Banachiewicz loop (faster than the general
/// factorisation for the 2x2 to 6x6 matrices of tracking filters; reads only the lower
/// triangle).
#[derive(Debug, Clone)]
pub(crate) struct Chol<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D, D>,
{
    l: OMatrix<T, D, D>,
}

impl<T: RealField + Copy, D: Dim> Chol<T, D>
where
    DefaultAllocator: Allocator<D, D>,
{
    /// Factorises `a`, or `None` if a pivot is not strictly positive (or not finite).
    #[inline(always)]
    pub(crate) fn new(mut a: OMatrix<T, D, D>) -> Option<Self> {
        let n = a.nrows();
        for j in 0..n {
            let mut d = a[(j, j)];
            for k in 0..j {
                d -= a[(j, k)] * a[(j, k)];
            }
            if d <= T::zero() || !d.is_finite() {
                return None;
            }
            let ljj = d.sqrt();
            a[(j, j)] = ljj;
            for i in (j + 1)..n {
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= a[(i, k)] * a[(j, k)];
                }
                a[(i, j)] = s / ljj;
            }
            for i in 0..j {
                a[(i, j)] = T::zero();
            }
        }
        Some(Chol { l: a })
    }

    /// The factor `L`, by value.
    pub(crate) fn unpack(self) -> OMatrix<T, D, D> {
        self.l
    }

    /// Solves `L w = b` in place, column by column.
    #[inline(always)]
    pub(crate) fn solve_lower_mut<C: Dim>(&self, b: &mut OMatrix<T, D, C>)
    where
        DefaultAllocator: Allocator<D, C>,
    {
        let n = self.l.nrows();
        for c in 0..b.ncols() {
            for i in 0..n {
                let mut s = b[(i, c)];
                for k in 0..i {
                    s -= self.l[(i, k)] * b[(k, c)];
                }
                b[(i, c)] = s / self.l[(i, i)];
            }
        }
    }

    /// Solves `A x = b` (`A = L L^T`) in place.
    #[inline(always)]
    pub(crate) fn solve_mut<C: Dim>(&self, b: &mut OMatrix<T, D, C>)
    where
        DefaultAllocator: Allocator<D, C>,
    {
        self.solve_lower_mut(b);
        let n = self.l.nrows();
        for c in 0..b.ncols() {
            for i in (0..n).rev() {
                let mut s = b[(i, c)];
                for k in (i + 1)..n {
                    s -= self.l[(k, i)] * b[(k, c)];
                }
                b[(i, c)] = s / self.l[(i, i)];
            }
        }
    }

    /// `ln det A = 2 sum ln L_ii` (one logarithm of the product when it is representable).
    #[inline(always)]
    pub(crate) fn log_det(&self) -> T {
        let n = self.l.nrows();
        let mut prod = T::one();
        for i in 0..n {
            prod *= self.l[(i, i)];
        }
        let two = T::one() + T::one();
        if prod > T::zero() && prod.is_finite() && prod > T::min_value().unwrap_or(T::zero()) {
            two * prod.ln()
        } else {
            let mut s = T::zero();
            for i in 0..n {
                s += self.l[(i, i)].ln();
            }
            two * s
        }
    }
}

/// Cholesky factor of a symmetric positive definite matrix, or
/// [`KalmanError::NotPositiveDefinite`] naming `what`.
#[inline(always)]
pub(crate) fn cholesky<T, D>(m: OMatrix<T, D, D>, what: &'static str) -> Result<Chol<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    Chol::new(m).ok_or(KalmanError::NotPositiveDefinite { what })
}

/// Symmetry tolerance: `sqrt(eps)` relative to the largest magnitude (at least 1).
fn symmetry_tolerance<T: RealField + Copy>(scale: T) -> T {
    T::default_epsilon().sqrt() * scale.max(T::one())
}

/// Checks that a square matrix is finite, symmetric (to `sqrt(eps)` relative) and positive
/// semi-definite: the Cholesky factorisation of `m + 64 n eps max|m| I` must exist, which
/// accepts rank-deficient matrices such as the discrete white-noise `Q` while rejecting any
/// eigenvalue below about `-64 n eps max|m|`.
#[inline(always)]
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
#[inline(always)]
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
/// positive semi-definite covariance (see [`check_psd`]); with `full = false` only shapes,
/// finite values, symmetry and a non-negative diagonal (no factorisation).
#[inline(always)]
pub(crate) fn check_state<T, D>(state: &Gaussian<T, D>, n: usize, full: bool) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    check_dim("state mean", n, state.mean.nrows())?;
    check_square(&state.covariance, n, "state covariance")?;
    check_finite(&state.mean, "state mean")?;
    if full {
        return check_psd(&state.covariance, "P");
    }
    let p = &state.covariance;
    check_finite(p, "P")?;
    let tol = symmetry_tolerance(p.amax());
    for j in 0..n {
        if p[(j, j)] < T::zero() {
            return Err(KalmanError::NotPositiveDefinite { what: "P" });
        }
        for i in 0..j {
            if (p[(i, j)] - p[(j, i)]).abs() > tol {
                return Err(KalmanError::NotPositiveDefinite { what: "P" });
            }
        }
    }
    Ok(())
}

/// Replaces `m` by its symmetric part `(m + m^T) / 2` in place.
#[inline(always)]
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
