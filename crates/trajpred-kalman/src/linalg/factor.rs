//! The factorisations of the filters: the in-place Cholesky factor of small matrices and
//! the `L D L^T` factorisation, with typed errors.

use crate::error::{KalmanError, Result};
use nalgebra::allocator::Allocator;
use nalgebra::{Const, DefaultAllocator, Dim, OMatrix, OVector, RealField};
use trajpred_core::Error as CoreError;

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
        // one verdict without branches, as in `positive_definite_shifted`
        let big = T::max_value().unwrap_or(T::one() / T::zero());
        let mut ok = true;
        cholesky_in_place::<T, D, false>(&mut a, |d| {
            ok &= (d > T::zero()) & (d <= big);
            d.sqrt()
        });
        ok.then_some(Chol { l: a })
    }

    /// The factor `L` with `L L^T = a` of a symmetric positive **semi**-definite `a`: a
    /// pivot up to `tol` (a zero eigen-direction, up to rounding) gives a zero column instead
    /// of a failure; `None` if a pivot is below `-tol` (or not finite).
    #[inline(always)]
    pub(crate) fn semidefinite(mut a: OMatrix<T, D, D>, tol: T) -> Option<Self> {
        let mut ok = true;
        cholesky_in_place::<T, D, true>(&mut a, |d| {
            ok &= (d >= -tol) & d.is_finite();
            if d > tol { d.sqrt() } else { T::zero() }
        });
        ok.then_some(Chol { l: a })
    }

    /// The factor `L`, by value.
    pub(crate) fn unpack(self) -> OMatrix<T, D, D> {
        self.l
    }
}

/// The Cholesky-Banachiewicz loop in place on the lower triangle of `a` (the upper triangle
/// set to zero): column `j`'s diagonal is `root(d_j)` of its pivot
/// `d_j = a_jj - sum_(k<j) L_jk^2`, the entries below it are divided by that diagonal, or,
/// with `ZERO_COLUMNS`, set to zero when it is zero (a zero column; without it the loop has no
/// branch, as the filters' factorisations want).
#[inline(always)]
fn cholesky_in_place<T, D, const ZERO_COLUMNS: bool>(
    a: &mut OMatrix<T, D, D>,
    mut root: impl FnMut(T) -> T,
) where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let n = a.nrows();
    for j in 0..n {
        let mut d = a[(j, j)];
        for k in 0..j {
            d -= a[(j, k)] * a[(j, k)];
        }
        let ljj = root(d);
        a[(j, j)] = ljj;
        if ZERO_COLUMNS && ljj == T::zero() {
            for i in (j + 1)..n {
                a[(i, j)] = T::zero();
            }
        } else {
            for i in (j + 1)..n {
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= a[(i, k)] * a[(j, k)];
                }
                a[(i, j)] = s / ljj;
            }
        }
        for i in 0..j {
            a[(i, j)] = T::zero();
        }
    }
}

/// The factorisation `A = L D L^T` of a symmetric positive definite matrix (`L` unit lower
/// triangular, `D` diagonal and positive), for solves and log-determinants: no square roots,
/// and one division per pivot (the reciprocals are kept, so solves only multiply). Reads
/// only the lower triangle.
#[derive(Debug, Clone)]
pub(crate) struct Ldl<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    /// `L` below the diagonal (the diagonal and upper triangle are scratch).
    l: OMatrix<T, D, D>,
    d: OVector<T, D>,
    inv_d: OVector<T, D>,
}

impl<T: RealField + Copy, D: Dim> Ldl<T, D>
where
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    /// Factorises `a + shift I` and returns the factors with the verdict: every pivot
    /// `d_j` strictly positive and finite. One verdict accumulated without branches (after
    /// a bad pivot the remaining arithmetic is harmless and the factors are meaningless).
    #[inline(always)]
    pub(crate) fn factor(mut a: OMatrix<T, D, D>, shift: T) -> (Self, bool) {
        let (dd, _) = a.shape_generic();
        let n = dd.value();
        let big = T::max_value().unwrap_or(T::one() / T::zero());
        let mut d = OVector::<T, D>::zeros_generic(dd, Const::<1>);
        let mut inv_d = OVector::<T, D>::zeros_generic(dd, Const::<1>);
        if n == 2 {
            // the 2 x 2 case in closed form: `d_1 = det / a_00` with `det = a_00 a_11 - a_10^2`,
            // so the two divisions (by `a_00` and by `det`) run side by side instead of the
            // second waiting for the first. Taken when `det` is a normal number and every
            // factor is finite; otherwise (a product under- or overflowed, or the matrix is
            // not positive definite) the loop below decides.
            let (a00, a10, a11) = (a[(0, 0)] + shift, a[(1, 0)], a[(1, 1)] + shift);
            let det = a00 * a11 - a10 * a10;
            let (inv0, inv_det) = (T::one() / a00, T::one() / det);
            let (d1, inv1) = (det * inv0, a00 * inv_det);
            // 4 / max is the smallest normal number (max = (2 - 2^-p) 2^e_max)
            let min_normal = nalgebra::convert::<f64, T>(4.0) / big;
            // (then 1 / a_00 is finite too)
            let normal = |v: T| (v >= min_normal) & (v <= big);
            if normal(a00) & normal(det) & (d1 > T::zero()) & (d1 <= big) & (inv1 <= big) {
                d[0] = a00;
                d[1] = d1;
                inv_d[0] = inv0;
                inv_d[1] = inv1;
                a[(0, 1)] = a10;
                a[(1, 0)] = a10 * inv0;
                return (Ldl { l: a, d, inv_d }, true);
            }
        }
        let mut ok = true;
        for j in 0..n {
            // row j of L is in a[(j, k)], k < j; w_k = L_jk d_k goes to the unused a[(k, j)]
            let mut dj = a[(j, j)] + shift;
            for k in 0..j {
                let w = a[(j, k)] * d[k];
                a[(k, j)] = w;
                dj -= a[(j, k)] * w;
            }
            ok &= (dj > T::zero()) & (dj <= big);
            d[j] = dj;
            let inv = T::one() / dj;
            inv_d[j] = inv;
            for i in (j + 1)..n {
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= a[(i, k)] * a[(k, j)];
                }
                a[(i, j)] = s * inv;
            }
        }
        (Ldl { l: a, d, inv_d }, ok)
    }

    /// Solves `L w = b` in place, column by column (`L` unit lower triangular).
    #[inline(always)]
    fn solve_unit_lower_mut<C: Dim>(&self, b: &mut OMatrix<T, D, C>)
    where
        DefaultAllocator: Allocator<D, C>,
    {
        let n = self.l.nrows();
        for c in 0..b.ncols() {
            for i in 1..n {
                let mut s = b[(i, c)];
                for k in 0..i {
                    s -= self.l[(i, k)] * b[(k, c)];
                }
                b[(i, c)] = s;
            }
        }
    }

    /// Solves `A x = b` in place: `L w = b`, `D v = w`, `L^T x = v`.
    #[inline(always)]
    pub(crate) fn solve_mut<C: Dim>(&self, b: &mut OMatrix<T, D, C>)
    where
        DefaultAllocator: Allocator<D, C>,
    {
        self.solve_unit_lower_mut(b);
        let n = self.l.nrows();
        for c in 0..b.ncols() {
            for i in (0..n).rev() {
                let mut s = b[(i, c)] * self.inv_d[i];
                for k in (i + 1)..n {
                    s -= self.l[(k, i)] * b[(k, c)];
                }
                b[(i, c)] = s;
            }
        }
    }

    /// `det A = prod d_i` (0 or infinite when the product under- or overflows).
    #[inline(always)]
    pub(crate) fn det(&self) -> T {
        self.d.iter().fold(T::one(), |p, &di| p * di)
    }

    /// `ln det A = ln prod d_i` (one logarithm of the product when it is representable:
    /// finite and not below `1 / max`, so it keeps all but at most two bits of precision).
    #[inline(always)]
    pub(crate) fn log_det(&self) -> T {
        let prod = self.det();
        let big = T::max_value().unwrap_or(T::one() / T::zero());
        if prod >= T::one() / big && prod <= big {
            prod.ln()
        } else {
            self.d.iter().fold(T::zero(), |s, &di| s + di.ln())
        }
    }

    /// The quadratic form `y^T A^-1 y = sum_i w_i^2 / d_i` with `L w = y`.
    #[inline(always)]
    pub(crate) fn quadratic_form(&self, y: &OVector<T, D>) -> T {
        let mut w = y.clone();
        self.solve_unit_lower_mut(&mut w);
        w.iter()
            .zip(self.inv_d.iter())
            .fold(T::zero(), |s, (&wi, &inv)| s + wi * wi * inv)
    }
}

/// The `L D L^T` factorisation of a symmetric positive definite matrix, or
/// [`trajpred_core::Error::NotPositiveDefinite`] naming `what`.
#[inline(always)]
pub(crate) fn ldl<T, D>(m: OMatrix<T, D, D>, what: &'static str) -> Result<Ldl<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    match Ldl::factor(m, T::zero()) {
        (f, true) => Ok(f),
        _ => Err(CoreError::NotPositiveDefinite { what }.into()),
    }
}

/// Cholesky factor of a symmetric positive definite matrix, or
/// [`trajpred_core::Error::NotPositiveDefinite`] naming `what`.
#[inline(always)]
pub(crate) fn cholesky<T, D>(m: OMatrix<T, D, D>, what: &'static str) -> Result<Chol<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    Chol::new(m).ok_or(KalmanError::Core(CoreError::NotPositiveDefinite { what }))
}
