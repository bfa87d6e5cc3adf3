//! Gaussian helpers: a square-root factor of a positive semi-definite matrix (for sampling
//! with a singular `Q`), Gaussian log-densities through a Cholesky factor, standard normal
//! draws in any scalar type, conversions to `f64` for log-weights.

use crate::error::Result;
use nalgebra::allocator::Allocator;
use nalgebra::{Cholesky, DefaultAllocator, Dim, OMatrix, OVector, RealField, U1};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use trajpred_core::Error as CoreError;

/// `v` as `f64` (NaN if it cannot be represented, which the callers reject as non-finite).
pub(crate) fn to_f64<T: RealField + Copy>(v: T) -> f64 {
    nalgebra::try_convert::<T, f64>(v).unwrap_or(f64::NAN)
}

/// A lower-triangular `L` with `L L^T = m` for a symmetric positive **semi**-definite `m`:
/// the Cholesky algorithm where a pivot below `n eps max|m|` (a zero eigen-direction, as in
/// the discrete white-noise `Q`) gives a zero column instead of a failure. A pivot below
/// minus that tolerance, an asymmetric or a non-finite matrix is
/// [`trajpred_core::Error::NotPositiveDefinite`].
pub(crate) fn psd_factor<T, D>(m: &OMatrix<T, D, D>, what: &'static str) -> Result<OMatrix<T, D, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let n = m.nrows();
    if m.ncols() != n {
        return Err(CoreError::DimensionMismatch {
            what,
            expected: n,
            got: m.ncols(),
        }
        .into());
    }
    if m.iter().any(|v| !v.is_finite()) {
        return Err(CoreError::NotPositiveDefinite { what }.into());
    }
    let scale = m.amax();
    let sym_tol = T::default_epsilon().sqrt() * scale.max(T::one());
    for j in 0..n {
        for i in 0..j {
            if (m[(i, j)] - m[(j, i)]).abs() > sym_tol {
                return Err(CoreError::NotPositiveDefinite { what }.into());
            }
        }
    }
    let tol = T::default_epsilon() * nalgebra::convert::<f64, T>(64.0 * n as f64) * scale;
    let mut l = m.clone_owned();
    l.fill(T::zero());
    for j in 0..n {
        let mut d = m[(j, j)];
        for k in 0..j {
            d -= l[(j, k)] * l[(j, k)];
        }
        if d < -tol {
            return Err(CoreError::NotPositiveDefinite { what }.into());
        }
        if d <= tol {
            continue; // zero column
        }
        let ljj = d.sqrt();
        l[(j, j)] = ljj;
        for i in (j + 1)..n {
            let mut s = m[(i, j)];
            for k in 0..j {
                s -= l[(i, k)] * l[(j, k)];
            }
            l[(i, j)] = s / ljj;
        }
    }
    Ok(l)
}

/// A zero-mean Gaussian `N(0, S)` for evaluating log-densities of residuals.
#[derive(Debug, Clone)]
pub(crate) struct Density<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D, D>,
{
    chol: Cholesky<T, D>,
    log_norm: f64,
}

impl<T: RealField + Copy, D: Dim> Density<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// `S` must be symmetric positive definite.
    pub(crate) fn new(s: &OMatrix<T, D, D>, what: &'static str) -> Result<Self> {
        if s.iter().any(|v| !v.is_finite()) {
            return Err(CoreError::NotPositiveDefinite { what }.into());
        }
        let chol = Cholesky::new(s.clone_owned()).ok_or(CoreError::NotPositiveDefinite { what })?;
        // a singular matrix can pass the factorisation with a rounding-size pivot: require
        // every pivot L_ii^2 above n eps max|S|
        let floor = to_f64(s.amax()) * f64::EPSILON * 64.0 * s.nrows() as f64;
        let l = chol.l_dirty();
        if (0..s.nrows()).any(|i| {
            let d = to_f64(l[(i, i)]);
            d.is_nan() || d * d <= floor
        }) {
            return Err(CoreError::NotPositiveDefinite { what }.into());
        }
        let log_norm =
            -0.5 * (s.nrows() as f64 * (2.0 * std::f64::consts::PI).ln()) - log_det_half(&chol);
        if !log_norm.is_finite() {
            return Err(CoreError::NotPositiveDefinite { what }.into());
        }
        Ok(Density { chol, log_norm })
    }

    /// `ln N(r; 0, S)`; `-inf` for a non-finite residual.
    pub(crate) fn log_density(&self, r: &OVector<T, D>) -> f64 {
        if r.iter().any(|v| !v.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let mut y = r.clone_owned();
        self.chol
            .l_dirty()
            .solve_lower_triangular_unchecked_mut(&mut y);
        let q = to_f64(y.norm_squared());
        if q.is_finite() {
            self.log_norm - 0.5 * q
        } else {
            f64::NEG_INFINITY
        }
    }
}

/// `ln sqrt(det S) = sum_i ln L_ii` from the Cholesky factor.
pub(crate) fn log_det_half<T, D>(chol: &Cholesky<T, D>) -> f64
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let l = chol.l_dirty();
    (0..l.nrows()).map(|i| to_f64(l[(i, i)]).ln()).sum()
}

/// Appends `count` standard normal variates converted to `T`.
pub(crate) fn push_normals<T: RealField + Copy, R: Rng + ?Sized>(
    rng: &mut R,
    count: usize,
    out: &mut Vec<T>,
) {
    out.reserve(count);
    for _ in 0..count {
        let e: f64 = StandardNormal.sample(rng);
        out.push(nalgebra::convert(e));
    }
}

/// The vector `mean + L e` for a slice of standard normals `e` (length `n`).
pub(crate) fn shifted<T, D>(mean: &OVector<T, D>, l: &OMatrix<T, D, D>, e: &[T]) -> OVector<T, D>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let d = mean.shape_generic().0;
    let ev = OVector::<T, D>::from_iterator_generic(d, U1, e.iter().copied());
    mean + l * ev
}

/// Index of the first non-finite element, if any.
pub(crate) fn first_non_finite<T: RealField + Copy, D: Dim>(v: &OVector<T, D>) -> Option<usize>
where
    DefaultAllocator: Allocator<D>,
{
    v.iter().position(|x| !x.is_finite())
}
