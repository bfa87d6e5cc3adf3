//! Small numerical helpers shared by every filter: checks of finiteness, shape and
//! definiteness, Cholesky factorisation with typed errors, symmetrisation.

use crate::error::Result;
use nalgebra::allocator::Allocator;
use nalgebra::base::storage::IsContiguous;
use nalgebra::{Const, DefaultAllocator, Dim, Matrix, OMatrix, OVector, RealField, Storage};
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;

mod congruence;
mod factor;
pub(crate) use congruence::{congruence_simd, congruence_simd_applies};
pub(crate) use factor::{Chol, Ldl, cholesky, ldl};

/// Errors with [`trajpred_core::Error::NonFinite`] if any element of `m` is NaN or infinite.
#[inline(always)]
pub(crate) fn check_finite<T, R, C, S>(m: &Matrix<T, R, C, S>, what: &'static str) -> Result<()>
where
    T: RealField + Copy,
    R: Dim,
    C: Dim,
    S: Storage<T, R, C> + IsContiguous,
{
    if all_finite(m) {
        return Ok(());
    }
    match m.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(CoreError::NonFinite { what, index }.into()),
        None => Ok(()),
    }
}

/// `v` as `f64` (NaN if it cannot be represented, which the callers reject as non-finite).
#[inline(always)]
pub(crate) fn to_f64<T: RealField + Copy>(v: T) -> f64 {
    nalgebra::try_convert::<T, f64>(v).unwrap_or(f64::NAN)
}

/// `true` when no element of `m` is NaN or infinite: one pass without early exit, so the
/// compiler vectorises it (the index of a bad value is looked up only on failure).
#[inline(always)]
#[allow(clippy::eq_op)] // `v - v` is the finiteness test, not a mistake
pub(crate) fn all_finite<T, R, C, S>(m: &Matrix<T, R, C, S>) -> bool
where
    T: RealField + Copy,
    R: Dim,
    C: Dim,
    S: Storage<T, R, C> + IsContiguous,
{
    // v - v is 0 for a finite v and NaN for an infinite or NaN one: a float comparison that
    // vectorises (is_finite compiles to integer bit tests, one element at a time); over the
    // contiguous slice, not the matrix iterator, whose two-level loop is not unrolled
    m.as_slice()
        .iter()
        .fold(true, |acc, &v| acc & (v - v == T::zero()))
}

/// `true` when the sizes `R`, `C` are both known at compile time (stack storage): the
/// small-matrix kernels below then run as unrolled loops without heap allocation.
#[inline(always)]
pub(crate) fn is_static<R: Dim, C: Dim>() -> bool {
    R::try_to_usize().is_some() && C::try_to_usize().is_some()
}

/// The product `a b`: explicit loops (column by column, `out[:, j] += a[:, l] b[l, j]`) for
/// static sizes, nalgebra's product otherwise.
#[inline(always)]
pub(crate) fn mul<T, R, K, C>(a: &OMatrix<T, R, K>, b: &OMatrix<T, K, C>) -> OMatrix<T, R, C>
where
    T: RealField + Copy,
    R: Dim,
    K: Dim,
    C: Dim,
    DefaultAllocator: Allocator<R, K> + Allocator<K, C> + Allocator<R, C>,
{
    if is_static::<R, K>() && is_static::<K, C>() && K::try_to_usize() != Some(0) {
        let (r, k) = a.shape_generic();
        let c = b.shape_generic().1;
        // column axpy order (i innermost, contiguous in column-major storage): vectorises
        let mut out = OMatrix::<T, R, C>::zeros_generic(r, c);
        for j in 0..c.value() {
            for l in 0..k.value() {
                let blj = b[(l, j)];
                for i in 0..r.value() {
                    out[(i, j)] += a[(i, l)] * blj;
                }
            }
        }
        out
    } else {
        a * b
    }
}

/// The product `a v` of a matrix and a vector (same strategy as [`mul`]).
#[inline(always)]
pub(crate) fn mul_vec<T, R, K>(a: &OMatrix<T, R, K>, v: &OVector<T, K>) -> OVector<T, R>
where
    T: RealField + Copy,
    R: Dim,
    K: Dim,
    DefaultAllocator: Allocator<R, K> + Allocator<K> + Allocator<R>,
{
    if is_static::<R, K>() && K::try_to_usize() != Some(0) {
        let (r, k) = a.shape_generic();
        let mut out = OVector::<T, R>::zeros_generic(r, Const::<1>);
        for l in 0..k.value() {
            let vl = v[l];
            for i in 0..r.value() {
                out[i] += a[(i, l)] * vl;
            }
        }
        out
    } else {
        a * v
    }
}

/// Above this many rows the symmetric products of static size ([`mul_tr_sym_plus`],
/// [`joseph`]) form whole columns and mirror the lower triangle instead of forming the
/// triangle alone: the loops then have constant trip counts. Measured with the KF step
/// benches (criterion, 2026-12-06): the dense 6-state step 257 -> 194-200 ns, while the
/// 4-state damped step went 64 -> 70 ns (so 4 keeps the triangle).
const FULL_COLUMNS_ABOVE: usize = 4;

/// `x a^T + (c + c^T) / 2` for a product `x a^T` that is symmetric in exact arithmetic
/// (`x = a b` with `b` symmetric): for static sizes only the lower triangle is formed and
/// then mirrored, so the result is exactly symmetric without a separate symmetrisation
/// pass; run-time sizes use nalgebra's product and [`symmetrise`].
#[inline(always)]
pub(crate) fn mul_tr_sym_plus<T, R, K>(
    x: &OMatrix<T, R, K>,
    a: &OMatrix<T, R, K>,
    c: &OMatrix<T, R, R>,
) -> OMatrix<T, R, R>
where
    T: RealField + Copy,
    R: Dim,
    K: Dim,
    DefaultAllocator: Allocator<R, K> + Allocator<K, R> + Allocator<R, R>,
{
    if is_static::<R, K>() && K::try_to_usize() != Some(0) {
        let (r, k) = a.shape_generic();
        let half = nalgebra::convert::<f64, T>(0.5);
        // (c + c^T) / 2 to start from, every entry (a zeroed matrix cost a call to `memset`)
        let mut out =
            OMatrix::<T, R, R>::from_fn_generic(r, r, |i, j| (c[(i, j)] + c[(j, i)]) * half);
        // the lower triangle, column by column with i innermost (contiguous), then mirrored;
        // above FULL_COLUMNS_ABOVE rows whole columns (constant trip counts: unrolled and
        // vectorised; the upper half is overwritten), each entry of the lower triangle the
        // same sum in the same order either way
        let from = |j: usize| if r.value() > FULL_COLUMNS_ABOVE { 0 } else { j };
        for j in 0..r.value() {
            for l in 0..k.value() {
                let ajl = a[(j, l)];
                for i in from(j)..r.value() {
                    out[(i, j)] += x[(i, l)] * ajl;
                }
            }
        }
        for j in 0..r.value() {
            for i in 0..j {
                out[(i, j)] = out[(j, i)];
            }
        }
        out
    } else {
        let mut out = x * a.transpose() + c;
        symmetrise(&mut out);
        out
    }
}

/// The Joseph form `(I - K H) P (I - K H)^T + K R K^T` from `HP`, the gain `K` and
/// `S = H P H^T + R` (symmetric), for any gain `K`. Expanding the product gives
/// `P - K (HP) - (HP)^T K^T + K S K^T`, which equals `P + U K^T + K U^T` with
/// `U = K S / 2 - (HP)^T` (an `n x m` matrix): for static sizes only the lower triangle of
/// that sum is formed (from the lower triangle of `P`, which is symmetric: exactly for the
/// filters' own predictions, to the input check's tolerance otherwise) and mirrored, so the
/// result is exactly symmetric; run-time sizes use nalgebra's products and [`symmetrise`].
#[inline(always)]
pub(crate) fn joseph<T, D, M>(
    p: &OMatrix<T, D, D>,
    k: &OMatrix<T, D, M>,
    hp: &OMatrix<T, M, D>,
    s: &OMatrix<T, M, M>,
) -> OMatrix<T, D, D>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    DefaultAllocator: Allocator<D, D> + Allocator<D, M> + Allocator<M, D> + Allocator<M, M>,
{
    if is_static::<D, M>() && M::try_to_usize() != Some(0) {
        let (d, m) = k.shape_generic();
        let half = nalgebra::convert::<f64, T>(0.5);
        let ks = mul(k, s);
        let u = OMatrix::<T, D, M>::from_fn_generic(d, m, |i, a| ks[(i, a)] * half - hp[(a, i)]);
        // a copy of `p` to start from (a zeroed matrix cost a call to `memset`)
        let mut out = p.clone();
        // the lower triangle (whole columns above FULL_COLUMNS_ABOVE rows, as in
        // `mul_tr_sym_plus`: the upper half, read from `p`, is overwritten), then mirrored
        let from = |j: usize| if d.value() > FULL_COLUMNS_ABOVE { 0 } else { j };
        for j in 0..d.value() {
            for a in 0..m.value() {
                let (kja, uja) = (k[(j, a)], u[(j, a)]);
                for i in from(j)..d.value() {
                    out[(i, j)] += u[(i, a)] * kja + k[(i, a)] * uja;
                }
            }
        }
        for j in 0..d.value() {
            for i in 0..j {
                out[(i, j)] = out[(j, i)];
            }
        }
        out
    } else {
        let a = k * hp;
        let mut c = k * s * k.transpose();
        c += p;
        c -= &a;
        c -= a.transpose();
        symmetrise(&mut c);
        c
    }
}

/// `F P F^T + (Q + Q^T) / 2` through the factorisation `P = L D L^T` (`L` unit lower
/// triangular), which doubles as the check that `P` is positive definite: `None` when a
/// pivot `d_j` is not strictly positive and finite (a semi-definite, indefinite or
/// non-finite `P`; the caller then takes the exact check). Otherwise `M = F L` and the lower
/// triangle of `M D M^T + Q`, mirrored: the same cost as the two products of `F P F^T`
/// alone, so the definiteness check is free. Reads the lower triangle of `P` only (the caller
/// checks symmetry). Static sizes only (the loops are meant to be unrolled).
#[inline(always)]
pub(crate) fn congruence_ldl<T, D>(
    f: &OMatrix<T, D, D>,
    p: &OMatrix<T, D, D>,
    q: &OMatrix<T, D, D>,
) -> Option<OMatrix<T, D, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    let (dd, _) = p.shape_generic();
    let n = dd.value();
    // L D L^T in place: L below the diagonal of `l`, D in `d`
    let mut l = p.clone();
    let mut d = OVector::<T, D>::zeros_generic(dd, Const::<1>);
    let mut ok = true;
    for j in 0..n {
        let mut dj = l[(j, j)];
        for k in 0..j {
            dj -= l[(j, k)] * l[(j, k)] * d[k];
        }
        ok &= dj > T::zero() && dj.is_finite();
        d[j] = dj;
        let inv = T::one() / dj;
        for i in (j + 1)..n {
            let mut s = l[(i, j)];
            for k in 0..j {
                s -= l[(i, k)] * l[(j, k)] * d[k];
            }
            l[(i, j)] = s * inv;
        }
    }
    if !ok {
        return None;
    }
    // M = F L (L unit lower triangular), then MD = M diag(d)
    let mut m = f.clone();
    for j in 0..n {
        for k in (j + 1)..n {
            let lkj = l[(k, j)];
            for i in 0..n {
                m[(i, j)] += f[(i, k)] * lkj;
            }
        }
    }
    let md = OMatrix::<T, D, D>::from_fn_generic(dd, dd, |i, k| m[(i, k)] * d[k]);
    Some(mul_tr_sym_plus(&md, &m, q))
}

/// Errors with [`trajpred_core::Error::DimensionMismatch`] unless `got == expected`.
#[inline(always)]
pub(crate) fn check_dim(what: &'static str, expected: usize, got: usize) -> Result<()> {
    if expected == got {
        Ok(())
    } else {
        Err(CoreError::DimensionMismatch {
            what,
            expected,
            got,
        }
        .into())
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
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    if is_psd(m) {
        Ok(())
    } else {
        psd_error(m, what)
    }
}

/// The verdict of [`check_psd`] without the error: finite, symmetric, non-negative diagonal
/// and `m + 64 n eps max|m| I` positive definite, in one branch-free pass over the elements
/// before the factorisation.
#[inline(always)]
pub(crate) fn is_psd<T, D>(m: &OMatrix<T, D, D>) -> bool
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    is_psd_sized(m, m.nrows())
}

/// [`is_psd`] with the shift `64 n eps max|m|` of a matrix of size `n`: the verdict on a
/// block-diagonal matrix of size `n` whose diagonal blocks are all `m` (padded with zeros).
#[inline(always)]
pub(crate) fn is_psd_sized<T, D>(m: &OMatrix<T, D, D>, n: usize) -> bool
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    if !all_finite(m) {
        return false;
    }
    let scale = amax_finite(m);
    if !is_symmetric_with_nonnegative_diagonal(m, scale) {
        return false;
    }
    if scale == T::zero() {
        return true;
    }
    let jitter = T::default_epsilon() * nalgebra::convert::<f64, T>(64.0 * n as f64) * scale;
    positive_definite_shifted(m.clone(), jitter)
}

/// `max |m_ij|` of a matrix without NaN.
#[inline(always)]
fn amax_finite<T, D>(m: &OMatrix<T, D, D>) -> T
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    m.as_slice().iter().fold(T::zero(), |s, v| {
        let a = v.abs();
        if a > s { a } else { s }
    })
}

/// `true` when the two triangles of `m` are equal element for element (NaN equals nothing):
/// the filters' own covariances are, being mirrored, and then no tolerance (and no scale for
/// it) is needed.
#[inline(always)]
pub(crate) fn exactly_symmetric<T, D>(m: &OMatrix<T, D, D>) -> bool
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let mut exact = true;
    for j in 0..m.nrows() {
        for i in 0..j {
            exact &= m[(i, j)] == m[(j, i)];
        }
    }
    exact
}

/// A non-negative diagonal.
#[inline(always)]
fn nonnegative_diagonal<T, D>(m: &OMatrix<T, D, D>) -> bool
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    (0..m.nrows()).fold(true, |ok, j| ok & (m[(j, j)] >= T::zero()))
}

/// Symmetric to [`symmetry_tolerance`] of `scale = max|m|`, with a non-negative diagonal
/// (branch-free).
#[inline(always)]
fn is_symmetric_with_nonnegative_diagonal<T, D>(m: &OMatrix<T, D, D>, scale: T) -> bool
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let tol = symmetry_tolerance(scale);
    let mut ok = true;
    for j in 0..m.nrows() {
        ok &= m[(j, j)] >= T::zero();
        for i in 0..j {
            ok &= (m[(i, j)] - m[(j, i)]).abs() <= tol;
        }
    }
    ok
}

/// The fast check of a state for the factorising predict, **to be combined with a
/// successful `L D L^T` factorisation of `P`** (which reads the lower triangle and fails on a
/// non-finite or non-positive pivot, so it already proves the lower triangle finite and
/// positive definite): a finite mean, and `P` symmetric to [`symmetry_tolerance`] of the
/// largest diagonal element (for a positive definite matrix the largest magnitude is on the
/// diagonal). A non-finite upper element fails the symmetry test (the tolerance is finite
/// whenever the factorisation succeeded), so no separate finiteness pass over `P` is needed.
/// An exactly symmetric `P` (every output of the filters, whose covariances are mirrored)
/// skips the tolerance: equal triangles need no scale, and a non-finite upper element can
/// only equal an infinite lower one (NaN equals nothing), which the factorisation rejects.
#[inline(always)]
pub(crate) fn mean_finite_and_symmetric<T, D>(state: &Gaussian<T, D>) -> bool
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let p = &state.covariance;
    if exactly_symmetric(p) {
        return all_finite(&state.mean);
    }
    let mut scale = T::zero();
    for j in 0..p.nrows() {
        let v = p[(j, j)];
        scale = if v > scale { v } else { scale };
    }
    let tol = symmetry_tolerance(scale);
    let mut ok = all_finite(&state.mean);
    for j in 0..p.nrows() {
        for i in 0..j {
            ok &= (p[(i, j)] - p[(j, i)]).abs() <= tol;
        }
    }
    ok
}

/// The error [`check_psd`] reports (the slow path, taken only when [`is_psd`] failed).
#[cold]
#[inline(never)]
fn psd_error<T, D>(m: &OMatrix<T, D, D>, what: &'static str) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    check_finite(m, what)?;
    let n = m.nrows();
    let scale = m.amax();
    let tol = symmetry_tolerance(scale);
    for j in 0..n {
        if m[(j, j)] < T::zero() {
            return Err(CoreError::NotPositiveDefinite { what }.into());
        }
        for i in 0..j {
            if (m[(i, j)] - m[(j, i)]).abs() > tol {
                return Err(CoreError::NotPositiveDefinite { what }.into());
            }
        }
    }
    if scale == T::zero() {
        return Ok(());
    }
    let jitter = T::default_epsilon() * nalgebra::convert::<f64, T>(64.0 * n as f64) * scale;
    if positive_definite_shifted(m.clone(), jitter) {
        Ok(())
    } else {
        Err(CoreError::NotPositiveDefinite { what }.into())
    }
}

/// Whether the symmetric matrix `a + shift I` (lower triangle read) is positive definite:
/// its [`Ldl`] factorisation has all pivots strictly positive and finite (cheaper than
/// [`Chol::new`]: no square roots).
#[inline(always)]
pub(crate) fn positive_definite_shifted<T, D>(a: OMatrix<T, D, D>, shift: T) -> bool
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    Ldl::factor(a, shift).1
}

/// Whether the symmetric matrix `a` (lower triangle read) is positive definite, by
/// fraction-free (Bareiss) elimination: after step `k` the trailing entries are the Schur
/// complement scaled by the leading `k + 1` minor, computed as
/// `(p_k a_ij - a_ik a_jk) / p_(k-1)` with `p_k` the `k`-th pivot. The pivots `p_k` are the
/// leading principal minors, all strictly positive (and finite) exactly for a positive
/// definite matrix (Sylvester). Each step divides by the pivot of the step before, whose
/// reciprocal is formed while that step's products run, so no division waits on the
/// critical path (the `L D L^T` loop waits for one per pivot); the rounding of each entry
/// is that of the `L D L^T` update scaled by a positive factor. The minors grow like the
/// `k`-th power of the entries: a matrix whose leading minors over- or underflow is
/// reported as not positive definite, and the caller falls back to [`is_psd`].
#[inline(always)]
pub(crate) fn positive_definite_minors<T, D>(mut a: OMatrix<T, D, D>) -> bool
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let n = a.nrows();
    let big = T::max_value().unwrap_or(T::one() / T::zero());
    // `T::min_value()` is the most negative value, not the smallest positive one
    let tiny = T::one() / big;
    let mut ok = true;
    let mut inv_prev = T::one();
    for k in 0..n {
        let p = a[(k, k)];
        ok &= (p >= tiny) & (p <= big);
        for j in (k + 1)..n {
            for i in j..n {
                a[(i, j)] = (p * a[(i, j)] - a[(i, k)] * a[(j, k)]) * inv_prev;
            }
        }
        inv_prev = T::one() / p;
    }
    ok
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
                return Err(CoreError::NotPositiveDefinite { what }.into());
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
    let p = &state.covariance;
    if all_finite(&state.mean)
        && (if full {
            is_psd(p)
        } else {
            all_finite(p)
                && ((exactly_symmetric(p) && nonnegative_diagonal(p))
                    || is_symmetric_with_nonnegative_diagonal(p, amax_finite(p)))
        })
    {
        return Ok(());
    }
    state_error(state, n, full)
}

/// The error [`check_state`] reports (the slow path, taken only when a fast check failed).
#[cold]
#[inline(never)]
fn state_error<T, D>(state: &Gaussian<T, D>, n: usize, full: bool) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    check_finite(&state.mean, "state mean")?;
    if full {
        return psd_error(&state.covariance, "P");
    }
    let p = &state.covariance;
    check_finite(p, "P")?;
    let tol = symmetry_tolerance(p.amax());
    for j in 0..n {
        if p[(j, j)] < T::zero() {
            return Err(CoreError::NotPositiveDefinite { what: "P" }.into());
        }
        for i in 0..j {
            if (p[(i, j)] - p[(j, i)]).abs() > tol {
                return Err(CoreError::NotPositiveDefinite { what: "P" }.into());
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
