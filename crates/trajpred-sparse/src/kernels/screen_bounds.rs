//! The bounds of the LAR step lengths a single-precision screen works with (`lars/screen.rs`),
//! vectorised.

use super::arch;
use pulp::{Simd, WithSimd};

/// Per column `k`, with `c_k` known to within `e_k` and `a_k` to within `b_k`, over both signs
/// `s` of the quotient `(C - s c_k) / (AA - s a_k)` (taken when both terms are positive):
/// `lo[k]`, the smallest value the quotient may take on a side where both terms may be
/// positive (infinite when neither may be), and the return value, the smallest quotient that
/// surely qualifies at its largest (at most `gamma_hat`).
#[inline(always)]
fn bounds_one(
    (cj, aj, ej, bj): (f64, f64, f64, f64),
    (big_c, aa): (f64, f64),
    hi: f64,
) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, hi);
    for (num, den) in [(big_c - cj, aa - aj), (big_c + cj, aa + aj)] {
        let (nlo, nhi, dlo, dhi) = (num - ej, num + ej, den - bj, den + bj);
        if nlo > 0.0 && dlo > 0.0 {
            hi = hi.min(nhi / dlo);
        }
        if nhi > 0.0 && dhi > 0.0 {
            lo = lo.min(nlo.max(0.0) / dhi);
        }
    }
    (lo, hi)
}

struct Bounds<'a> {
    cab: (&'a [f64], &'a [f64], &'a [f64], &'a [f64]),
    big_c: f64,
    aa: f64,
    gamma_hat: f64,
    lo: &'a mut [f64],
}

impl WithSimd for Bounds<'_> {
    type Output = f64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> f64 {
        let Bounds {
            cab: (c, a, e, b),
            big_c,
            aa,
            gamma_hat,
            lo,
        } = self;
        let n = c.len();
        let (ch, ct) = S::as_simd_f64s(c);
        let (ah, at) = S::as_simd_f64s(&a[..n]);
        let (eh, et) = S::as_simd_f64s(&e[..n]);
        let (bh, bt) = S::as_simd_f64s(&b[..n]);
        let (loh, lot) = S::as_mut_simd_f64s(&mut lo[..n]);
        let zero = simd.splat_f64s(0.0);
        let inf = simd.splat_f64s(f64::INFINITY);
        let vc = simd.splat_f64s(big_c);
        let va = simd.splat_f64s(aa);
        let mut best = simd.splat_f64s(gamma_hat);
        for i in 0..ch.len() {
            let (cv, av, ev, bv) = (ch[i], ah[i], eh[i], bh[i]);
            let mut low = inf;
            for (num, den) in [
                (simd.sub_f64s(vc, cv), simd.sub_f64s(va, av)),
                (simd.add_f64s(vc, cv), simd.add_f64s(va, av)),
            ] {
                let (nlo, nhi) = (simd.sub_f64s(num, ev), simd.add_f64s(num, ev));
                let (dlo, dhi) = (simd.sub_f64s(den, bv), simd.add_f64s(den, bv));
                let sure = simd.and_m64s(
                    simd.greater_than_f64s(nlo, zero),
                    simd.greater_than_f64s(dlo, zero),
                );
                let q = simd.div_f64s(nhi, dlo);
                best = simd.select_f64s(simd.and_m64s(sure, simd.less_than_f64s(q, best)), q, best);
                let may = simd.and_m64s(
                    simd.greater_than_f64s(nhi, zero),
                    simd.greater_than_f64s(dhi, zero),
                );
                let ql = simd.div_f64s(simd.max_f64s(nlo, zero), dhi);
                low = simd.select_f64s(simd.and_m64s(may, simd.less_than_f64s(ql, low)), ql, low);
            }
            loh[i] = low;
        }
        let mut hi = simd.reduce_min_f64s(best);
        for k in 0..ct.len() {
            let (l, h) = bounds_one((ct[k], at[k], et[k], bt[k]), (big_c, aa), hi);
            lot[k] = l;
            hi = h;
        }
        hi
    }
}

/// Fills `lo` (one per column of `c`) and returns the smallest sure upper bound, as
/// [`bounds_one`] describes, for the columns whose correlations are `c` (within `e`) and
/// whose products with the equiangular vector are `a` (within `b`), all in the same order.
pub(crate) fn screen_bounds(
    (c, a, e, b): (&[f64], &[f64], &[f64], &[f64]),
    (big_c, aa, gamma_hat): (f64, f64, f64),
    lo: &mut [f64],
) -> f64 {
    debug_assert!(a.len() == c.len() && e.len() == c.len() && b.len() == c.len());
    debug_assert_eq!(lo.len(), c.len());
    arch().dispatch(Bounds {
        cab: (c, a, e, b),
        big_c,
        aa,
        gamma_hat,
        lo,
    })
}

/// [`screen_bounds`] as a plain loop (the reference of its test).
#[cfg(test)]
pub(crate) fn screen_bounds_plain(
    (c, a, e, b): (&[f64], &[f64], &[f64], &[f64]),
    (big_c, aa, gamma_hat): (f64, f64, f64),
    lo: &mut [f64],
) -> f64 {
    let mut hi = gamma_hat;
    for k in 0..c.len() {
        let (l, h) = bounds_one((c[k], a[k], e[k], b[k]), (big_c, aa), hi);
        lo[k] = l;
        hi = h;
    }
    hi
}
