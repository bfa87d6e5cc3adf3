//! The LAR step length over the inactive columns, vectorised.

use super::arch;
use pulp::{Simd, WithSimd};

/// `min(gamma_hat, min over k and both signs of (C - s c_k) / (AA - s a_k))`, taken over
/// the quotients whose numerator and denominator are both positive (eq. 2.13 of Efron et
/// al.). Every quotient is one IEEE division and the minimum does not depend on the order:
/// the result is exactly that of [`step_min_plain`].
struct StepMin<'a> {
    c: &'a [f64],
    a: &'a [f64],
    big_c: f64,
    aa: f64,
    gamma_hat: f64,
}

impl WithSimd for StepMin<'_> {
    type Output = f64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> f64 {
        let StepMin {
            c,
            a,
            big_c,
            aa,
            gamma_hat,
        } = self;
        let n = c.len().min(a.len());
        let (ch, ct) = S::as_simd_f64s(&c[..n]);
        let (ah, at) = S::as_simd_f64s(&a[..n]);
        let zero = simd.splat_f64s(0.0);
        let vc = simd.splat_f64s(big_c);
        let va = simd.splat_f64s(aa);
        let mut best = simd.splat_f64s(gamma_hat);
        for (&cv, &av) in ch.iter().zip(ah) {
            // side +1: (C - c) / (AA - a); side -1: (C + c) / (AA + a)
            for (num, den) in [
                (simd.sub_f64s(vc, cv), simd.sub_f64s(va, av)),
                (simd.add_f64s(vc, cv), simd.add_f64s(va, av)),
            ] {
                let g = simd.div_f64s(num, den);
                let ok = simd.and_m64s(
                    simd.and_m64s(
                        simd.greater_than_f64s(num, zero),
                        simd.greater_than_f64s(den, zero),
                    ),
                    // (false for a NaN quotient, as in the plain loop)
                    simd.less_than_f64s(g, best),
                );
                best = simd.select_f64s(ok, g, best);
            }
        }
        let mut gamma = simd.reduce_min_f64s(best);
        for (&cj, &aj) in ct.iter().zip(at) {
            gamma = step_min_one(cj, aj, big_c, aa, gamma);
        }
        gamma
    }
}

#[inline(always)]
fn step_min_one(cj: f64, aj: f64, big_c: f64, aa: f64, mut gamma: f64) -> f64 {
    for (num, den) in [(big_c - cj, aa - aj), (big_c + cj, aa + aj)] {
        if num > 0.0 && den > 0.0 {
            let g = num / den;
            if g < gamma {
                gamma = g;
            }
        }
    }
    gamma
}

/// The step length `gamma` of a LAR step (no variable just dropped) from the inactive
/// columns' correlations `c` and their correlations `a` with the equiangular direction, in the
/// same order.
pub(crate) fn step_min(c: &[f64], a: &[f64], big_c: f64, aa: f64, gamma_hat: f64) -> f64 {
    arch().dispatch(StepMin {
        c,
        a,
        big_c,
        aa,
        gamma_hat,
    })
}

/// [`step_min`] as a plain loop (the reference of its test).
#[cfg(test)]
pub(crate) fn step_min_plain(c: &[f64], a: &[f64], big_c: f64, aa: f64, gamma_hat: f64) -> f64 {
    c.iter().zip(a).fold(gamma_hat, |g, (&cj, &aj)| {
        step_min_one(cj, aj, big_c, aa, g)
    })
}
