//! `F P F^T + (Q + Q^T) / 2` for `f64` matrices of 5 to 8 states (4 with AVX2), written once against
//! `pulp`'s safe SIMD types and dispatched at run time (AVX-512 or AVX2 with fused
//! multiply-adds; without either, `None` and the caller keeps its scalar loops), as the
//! kernels of trajpred-sparse and trajpred-neural are.
//!
//! The crate is built for the baseline x86-64 target (two-wide SSE2, no fused multiply-add),
//! where the two dense products of a 6-state prediction (about 430 multiply-adds) took most
//! of the step. Here a column of `P` or of the result is one or two vectors: `G = F P` as
//! `G[:, j] = sum_k F[:, k] P[k, j]` (`P` read from its lower triangle), then the lower
//! triangle of `G F^T + (Q + Q^T) / 2` as whole columns `sum_k G[:, k] F[j, k]`, mirrored so
//! that the result is exactly symmetric. The sums run in the order of the scalar loops of
//! [`mul`](super::mul) and [`mul_tr_sym_plus`](super::mul_tr_sym_plus), but with fused
//! multiply-adds: the results agree to rounding (tests below).

// the kernel indexes fixed-size arrays of vectors in lockstep
#![allow(clippy::needless_range_loop)]

use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, RealField};
use pulp::{Arch, Simd, WithSimd};
use std::any::{Any, TypeId};

/// The most vectors a column takes (8 states in vectors of at least 4 lanes).
const MAX_VECTORS: usize = 2;

/// `out = F P F^T + (Q + Q^T) / 2` (lower triangle formed, mirrored) for `N x N`
/// column-major slices.
struct Congruence<'a, const N: usize> {
    f: &'a [f64],
    p: &'a [f64],
    q: &'a [f64],
    out: &'a mut [f64],
    /// whether to run the leading-minors check first (skipped: `P` is taken as it is)
    check: bool,
}

impl<const N: usize> WithSimd for Congruence<'_, N> {
    /// `None` when not handled (vectors of fewer than 4 lanes), else whether `P` is
    /// positive definite (and then `out` is written).
    type Output = Option<bool>;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> Option<bool> {
        let Congruence {
            f,
            p,
            q,
            out,
            check,
        } = self;
        let lanes = S::F64_LANES;
        let len = N * N;
        // scalar lanes: not worth it (the caller's loops are as good)
        if !(4..=8).contains(&lanes)
            || f.len() != len
            || p.len() != len
            || q.len() != len
            || out.len() != len
        {
            return None;
        }
        let nv = N.div_ceil(lanes);
        let zero = simd.splat_f64s(0.0);
        if check && !leading_minors_positive::<S, N>(simd, p) {
            return Some(false);
        }
        let mut fc = [[zero; MAX_VECTORS]; N];
        for k in 0..N {
            for v in 0..nv {
                fc[k][v] = load(simd, f, k * N + v * lanes);
            }
        }
        // G = F P, column by column (P[k, j] from the lower triangle)
        let mut g = [[zero; MAX_VECTORS]; N];
        for j in 0..N {
            for k in 0..N {
                let pkj = simd.splat_f64s(if k >= j { p[k + j * N] } else { p[j + k * N] });
                for v in 0..nv {
                    g[j][v] = simd.mul_add_e_f64s(fc[k][v], pkj, g[j][v]);
                }
            }
        }
        // (Q + Q^T) / 2: an exactly symmetric Q (the usual case) is read as it is (with
        // `(q + q) / 2 = q`, exact below `f64::MAX / 2`); otherwise a copy with the
        // symmetrised lower triangle (the rest is overwritten by the mirror)
        let mut q_exact = true;
        for j in 0..N {
            for i in 0..j {
                q_exact &= q[i + j * N] == q[j + i * N];
            }
        }
        let qs: [f64; 64];
        let q_used = if q_exact {
            q
        } else {
            let mut c = [0.0; 64];
            for j in 0..N {
                for i in j..N {
                    c[i + j * N] = (q[i + j * N] + q[j + i * N]) * 0.5;
                }
            }
            qs = c;
            &qs[..len]
        };
        // out[:, j] = qs[:, j] + sum_k G[:, k] F[j, k], stored in increasing `j` (a store's
        // lanes past the column's end are overwritten by the next column's)
        for j in 0..N {
            let mut acc = [zero; MAX_VECTORS];
            for v in 0..nv {
                acc[v] = load(simd, q_used, j * N + v * lanes);
            }
            for k in 0..N {
                let fjk = simd.splat_f64s(f[j + k * N]);
                for v in 0..nv {
                    acc[v] = simd.mul_add_e_f64s(g[k][v], fjk, acc[v]);
                }
            }
            for v in 0..nv {
                store(simd, out, j * N + v * lanes, acc[v]);
            }
        }
        for j in 0..N {
            for i in 0..j {
                out[i + j * N] = out[j + i * N];
            }
        }
        Some(true)
    }
}

/// The leading principal minors of the lower triangle of `P` (`N x N`, column-major) all
/// within `[1 / f64::MAX, f64::MAX]`, by fraction-free elimination on whole columns: the
/// operations of `positive_definite_minors` in the same order (no fused multiply-adds), so
/// the same verdict; the lanes above the diagonal and past a column's end are never read by
/// the lanes below it.
#[inline(always)]
fn leading_minors_positive<S: Simd, const N: usize>(simd: S, p: &[f64]) -> bool {
    let lanes = S::F64_LANES;
    let nv = N.div_ceil(lanes);
    let zero = simd.splat_f64s(0.0);
    let mut a = [[zero; MAX_VECTORS]; N];
    for j in 0..N {
        for v in 0..nv {
            a[j][v] = load(simd, p, j * N + v * lanes);
        }
    }
    let big = f64::MAX;
    let tiny = 1.0 / big;
    let mut ok = true;
    let mut inv_prev = 1.0;
    let mut col = [0.0; 2 * 8];
    for k in 0..N {
        for v in 0..nv {
            S::as_mut_simd_f64s(&mut col[v * lanes..(v + 1) * lanes]).0[0] = a[k][v];
        }
        let pk = col[k];
        ok &= (pk >= tiny) & (pk <= big);
        let (pv, iv) = (simd.splat_f64s(pk), simd.splat_f64s(inv_prev));
        for j in (k + 1)..N {
            let ajk = simd.splat_f64s(col[j]);
            for v in 0..nv {
                let t = simd.sub_f64s(simd.mul_f64s(pv, a[j][v]), simd.mul_f64s(a[k][v], ajk));
                a[j][v] = simd.mul_f64s(t, iv);
            }
        }
        inv_prev = 1.0 / pk;
    }
    ok
}

/// `S::F64_LANES` (at most 8) elements of `m` from `from`, as a vector: the kernels read
/// whole vectors (the lanes past a column's end hold the next column's first rows, which no
/// stored lane depends on); a vector past the end of `m` is read through a zero-padded copy.
#[inline(always)]
pub(super) fn load<S: Simd>(_simd: S, m: &[f64], from: usize) -> S::f64s {
    let lanes = S::F64_LANES;
    if from + lanes <= m.len() {
        S::as_simd_f64s(&m[from..from + lanes]).0[0]
    } else {
        let mut t = [0.0; 8];
        t[..m.len() - from].copy_from_slice(&m[from..]);
        S::as_simd_f64s(&t[..lanes]).0[0]
    }
}

/// Stores the vector `x` at `from` in `m`, the lanes past the end of `m` dropped (the lanes
/// past a column's end are overwritten when the next column is stored).
#[inline(always)]
pub(super) fn store<S: Simd>(_simd: S, m: &mut [f64], from: usize, x: S::f64s) {
    let lanes = S::F64_LANES;
    if from + lanes <= m.len() {
        S::as_mut_simd_f64s(&mut m[from..from + lanes]).0[0] = x;
    } else {
        let mut t = [0.0; 8];
        S::as_mut_simd_f64s(&mut t[..lanes]).0[0] = x;
        let len = m.len();
        m[from..].copy_from_slice(&t[..len - from]);
    }
}

/// `f64` elements, a static size of 5 to 8 with vectors of at least 4 lanes (AVX2 or
/// AVX-512), or of 4 with vectors of exactly 4 (AVX2):
/// where the kernels apply.
#[inline(always)]
pub(super) fn is_f64_of_size<T: RealField + Copy, D: Dim>() -> bool {
    TypeId::of::<T>() == TypeId::of::<f64>()
        && D::try_to_usize().is_some_and(|n| {
            // exactly where the kernel answers (it declines vectors of fewer than 4 lanes,
            // such as NEON's 2): 4 states are one vector of AVX2, while in AVX-512's 8 lanes
            // half of each would be wasted and the scalar factorisation is as fast
            let lanes = Arch::new().dispatch(Lanes);
            match n {
                4 => lanes == 4,
                5..=8 => (4..=8).contains(&lanes),
                _ => false,
            }
        })
}

/// The `f64` lanes of the dispatched vectors.
struct Lanes;

impl WithSimd for Lanes {
    type Output = usize;
    #[inline(always)]
    fn with_simd<S: Simd>(self, _simd: S) -> usize {
        S::F64_LANES
    }
}

/// The column-major elements of `m` when `T` is `f64`.
#[inline(always)]
fn as_f64<T, D>(m: &OMatrix<T, D, D>) -> Option<&[f64]>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    (m as &dyn Any)
        .downcast_ref::<OMatrix<f64, D, D>>()
        .map(|m| m.as_slice())
}

/// Whether [`congruence_simd`] gives a result for these types on this machine: `f64`, a
/// static size of 5 to 8, vectors of at least 4 lanes (AVX2 or AVX-512), or 4 states with
/// AVX2.
#[inline(always)]
pub(crate) fn congruence_simd_applies<T: RealField + Copy, D: Dim>() -> bool {
    is_f64_of_size::<T, D>()
}

/// `F P F^T + (Q + Q^T) / 2`, exactly symmetric, from the lower triangle of `P`, through the
/// SIMD kernel, in `f64` matrices of 5 to 8 states on a machine with AVX2 or AVX-512 (and of
/// 4 with AVX2)
/// ([`congruence_simd_applies`]; `None` otherwise). With `check`, only when `P` passes the
/// leading-minors check (the verdict of
/// [`positive_definite_minors`](super::positive_definite_minors), which it reproduces
/// operation for operation; `None` when it fails); without it, `P` is taken as it is (for a
/// `P` verified by other means, or not to be verified:
/// [`InputChecks::Cheap`](crate::InputChecks::Cheap)).
#[inline(always)]
pub(crate) fn congruence_simd<T, D>(
    f: &OMatrix<T, D, D>,
    p: &OMatrix<T, D, D>,
    q: &OMatrix<T, D, D>,
    check: bool,
) -> Option<OMatrix<T, D, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    if !congruence_simd_applies::<T, D>() {
        return None;
    }
    let n = D::try_to_usize()?;
    let (dd, _) = p.shape_generic();
    let (f, p, q) = (as_f64(f)?, as_f64(p)?, as_f64(q)?);
    let mut out = OMatrix::<T, D, D>::zeros_generic(dd, dd);
    let o = (&mut out as &mut dyn Any).downcast_mut::<OMatrix<f64, D, D>>()?;
    let out_slice = o.as_mut_slice();
    let arch = Arch::new();
    let done = match n {
        4 => arch.dispatch(Congruence::<4> {
            f,
            p,
            q,
            out: out_slice,
            check,
        }),
        5 => arch.dispatch(Congruence::<5> {
            f,
            p,
            q,
            out: out_slice,
            check,
        }),
        6 => arch.dispatch(Congruence::<6> {
            f,
            p,
            q,
            out: out_slice,
            check,
        }),
        7 => arch.dispatch(Congruence::<7> {
            f,
            p,
            q,
            out: out_slice,
            check,
        }),
        _ => arch.dispatch(Congruence::<8> {
            f,
            p,
            q,
            out: out_slice,
            check,
        }),
    };
    (done == Some(true)).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::{mul, mul_tr_sym_plus, positive_definite_minors};
    use nalgebra::SMatrix;

    /// Deterministic entries in [-1, 1).
    fn entry(i: usize, seed: usize) -> f64 {
        let x = (i as u64)
            .wrapping_mul(2_654_435_761)
            .wrapping_add(seed as u64 * 40_503);
        (x % 2000) as f64 / 1000.0 - 1.0
    }

    fn check<const N: usize>() {
        let f = SMatrix::<f64, N, N>::from_fn(|i, j| entry(i + N * j, 1));
        let a = SMatrix::<f64, N, N>::from_fn(|i, j| entry(i + N * j, 2));
        // symmetric positive definite P, a Q that is not exactly symmetric
        let p = a * a.transpose() + SMatrix::<f64, N, N>::identity();
        let q = SMatrix::<f64, N, N>::from_fn(|i, j| {
            entry(i + N * j, 3) * 1e-2 + (i == j) as u8 as f64
        });
        // a Q that is not exactly symmetric, and one that is
        for q in [q, (q + q.transpose()) * 0.5] {
            let plain = mul_tr_sym_plus(&mul(&f, &p), &f, &q);
            let applies = congruence_simd_applies::<f64, nalgebra::Const<N>>();
            match congruence_simd(&f, &p, &q, true) {
                Some(fast) => {
                    for j in 0..N {
                        for i in 0..N {
                            assert_eq!(fast[(i, j)], fast[(j, i)], "not mirrored at {i}, {j}");
                            let scale = plain[(i, j)].abs().max(1.0);
                            assert!(
                                (fast[(i, j)] - plain[(i, j)]).abs() <= 1e-13 * scale,
                                "N = {N}, ({i}, {j}): {} against {}",
                                fast[(i, j)],
                                plain[(i, j)]
                            );
                        }
                    }
                }
                None => assert!(!applies, "N = {N}: no kernel result where it applies"),
            }
        }
        // the upper triangle of P is not read
        let mut p_upper_nan = p;
        for j in 0..N {
            for i in 0..j {
                p_upper_nan[(i, j)] = f64::NAN;
            }
        }
        if let Some(fast) = congruence_simd(&f, &p_upper_nan, &q, true) {
            assert!(fast.iter().all(|v| v.is_finite()));
        }
        // the verdict of the scalar minors check: indefinite, semi-definite, huge
        let mut indefinite = p;
        indefinite[(N - 1, N - 1)] = -1.0;
        let semidefinite = a.columns(0, 1) * a.columns(0, 1).transpose();
        for bad in [indefinite, semidefinite, p * 1e300] {
            assert!(!positive_definite_minors(bad));
            assert!(congruence_simd(&f, &bad, &q, true).is_none());
            // without the check, the product of whatever P is given
            let Some(fast) = congruence_simd(&f, &bad, &q, false) else {
                assert!(
                    matches!(Arch::new(), Arch::Scalar),
                    "N = {N}: no unchecked result"
                );
                continue;
            };
            let plain = mul_tr_sym_plus(&mul(&f, &bad), &f, &q);
            let top = plain.amax();
            for (x, y) in fast.iter().zip(plain.iter()) {
                assert!(
                    (x - y).abs() <= 1e-13 * top,
                    "N = {N}: unchecked {x} against {y}"
                );
            }
        }
    }

    #[test]
    fn kernel_matches_the_plain_loops() {
        check::<4>();
        check::<5>();
        check::<6>();
        check::<7>();
        check::<8>();
        // other sizes and types are left to the caller
        let f3 = SMatrix::<f64, 3, 3>::identity();
        assert!(congruence_simd(&f3, &f3, &f3, true).is_none());
        let f6 = SMatrix::<f32, 6, 6>::identity();
        assert!(congruence_simd(&f6, &f6, &f6, true).is_none());
    }
}
