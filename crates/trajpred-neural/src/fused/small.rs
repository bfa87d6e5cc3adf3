//! The two matrix products of a recurrent step, for `f32` (the training type), without
//! packing: `out += h W` (the gates' recurrent part) and `out = g W^T` (the gradient back to
//! the previous hidden state), with `W` the row-major `[hidden, 4 hidden]` recurrent weight.
//!
//! A general GEMM (matrixmultiply, through ndarray) copies both operands into packed panels
//! on every call; for a batch of 16 rows and a 64 x 256 weight that copy of the weight took
//! as long as the multiplications (about a quarter of an LSTM epoch each). These kernels
//! read the weight where it is: `h W` broadcasts one entry of `h` per row against vectors of
//! a row of `W` (4 rows x 4 vectors of accumulators), `g W^T` takes dot products of rows of
//! `g` with rows of `W` (4 x 4 accumulators, reduced at the end). Written once against
//! `pulp`'s safe SIMD types and dispatched at run time (AVX-512, AVX2 + FMA or scalar), as
//! the LAR kernels of trajpred-sparse are. Sums run in another order than matrixmultiply's:
//! the results agree to rounding (tests below, against plain loops in `f64`).

// the kernels index fixed-size accumulator arrays in lockstep
#![allow(clippy::needless_range_loop)]

use pulp::{Arch, Simd, WithSimd};

/// Rows of the left operand per block.
const RB: usize = 4;
/// Vectors of columns (`h W`) or rows of `W` (`g W^T`) per block.
const CB: usize = 4;

/// `out[rows, n] += h[rows, k] w[k, n]`, all row-major.
struct MulAdd<'a> {
    h: &'a [f32],
    w: &'a [f32],
    dims: (usize, usize, usize),
    out: &'a mut [f32],
}

impl WithSimd for MulAdd<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let MulAdd {
            h,
            w,
            dims: (rows, k, n),
            out,
        } = self;
        let lanes = S::F32_LANES;
        let width = CB * lanes;
        let full = n / width * width;
        let mut r0 = 0;
        while r0 + RB <= rows {
            let mut c0 = 0;
            while c0 < full {
                let mut acc = [[simd.splat_f32s(0.0); CB]; RB];
                for r in 0..RB {
                    let o = S::as_simd_f32s(&out[(r0 + r) * n + c0..(r0 + r) * n + c0 + width]).0;
                    acc[r].copy_from_slice(&o[..CB]);
                }
                for kk in 0..k {
                    let wv = S::as_simd_f32s(&w[kk * n + c0..kk * n + c0 + width]).0;
                    for r in 0..RB {
                        let b = simd.splat_f32s(h[(r0 + r) * k + kk]);
                        for c in 0..CB {
                            acc[r][c] = simd.mul_add_e_f32s(b, wv[c], acc[r][c]);
                        }
                    }
                }
                for r in 0..RB {
                    let o =
                        S::as_mut_simd_f32s(&mut out[(r0 + r) * n + c0..(r0 + r) * n + c0 + width])
                            .0;
                    o[..CB].copy_from_slice(&acc[r]);
                }
                c0 += width;
            }
            r0 += RB;
        }
        // what the blocks left: the last rows, the last columns
        for r in 0..rows {
            let from = if r < r0 { full } else { 0 };
            for kk in 0..k {
                let b = h[r * k + kk];
                for c in from..n {
                    out[r * n + c] += b * w[kk * n + c];
                }
            }
        }
    }
}

/// `out[rows, k] = g[rows, n] w[k, n]^T`, all row-major.
struct MulT<'a> {
    g: &'a [f32],
    w: &'a [f32],
    dims: (usize, usize, usize),
    out: &'a mut [f32],
}

impl WithSimd for MulT<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let MulT {
            g,
            w,
            dims: (rows, n, k),
            out,
        } = self;
        let lanes = S::F32_LANES;
        let vn = n / lanes * lanes;
        let mut r0 = 0;
        while r0 + RB <= rows {
            let mut k0 = 0;
            while k0 + CB <= k {
                let mut acc = [[simd.splat_f32s(0.0); CB]; RB];
                let gr: [&[S::f32s]; RB] =
                    std::array::from_fn(|r| S::as_simd_f32s(&g[(r0 + r) * n..(r0 + r) * n + vn]).0);
                let wr: [&[S::f32s]; CB] =
                    std::array::from_fn(|c| S::as_simd_f32s(&w[(k0 + c) * n..(k0 + c) * n + vn]).0);
                for v in 0..vn / lanes {
                    for r in 0..RB {
                        for c in 0..CB {
                            acc[r][c] = simd.mul_add_e_f32s(gr[r][v], wr[c][v], acc[r][c]);
                        }
                    }
                }
                for r in 0..RB {
                    for c in 0..CB {
                        let mut s = simd.reduce_sum_f32s(acc[r][c]);
                        for j in vn..n {
                            s += g[(r0 + r) * n + j] * w[(k0 + c) * n + j];
                        }
                        out[(r0 + r) * k + k0 + c] = s;
                    }
                }
                k0 += CB;
            }
            for kk in k0..k {
                for r in r0..r0 + RB {
                    out[r * k + kk] = dot(&g[r * n..(r + 1) * n], &w[kk * n..(kk + 1) * n]);
                }
            }
            r0 += RB;
        }
        for r in r0..rows {
            for kk in 0..k {
                out[r * k + kk] = dot(&g[r * n..(r + 1) * n], &w[kk * n..(kk + 1) * n]);
            }
        }
    }
}

/// A plain dot product (the blocks' leftovers).
fn dot(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `out += h w` for row-major `h` (`rows x k`), `w` (`k x n`) and `out` (`rows x n`).
pub(crate) fn mul_add(h: &[f32], w: &[f32], (rows, k, n): (usize, usize, usize), out: &mut [f32]) {
    debug_assert!(h.len() >= rows * k && w.len() >= k * n && out.len() >= rows * n);
    Arch::new().dispatch(MulAdd {
        h,
        w,
        dims: (rows, k, n),
        out,
    });
}

/// `out = g w^T` for row-major `g` (`rows x n`), `w` (`k x n`) and `out` (`rows x k`).
pub(crate) fn mul_t(g: &[f32], w: &[f32], (rows, n, k): (usize, usize, usize), out: &mut [f32]) {
    debug_assert!(g.len() >= rows * n && w.len() >= k * n && out.len() >= rows * k);
    Arch::new().dispatch(MulT {
        g,
        w,
        dims: (rows, n, k),
        out,
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic entries in [-1, 1).
    fn entries(len: usize, seed: u32) -> Vec<f32> {
        (0..len)
            .map(|i| {
                let x = (i as u32)
                    .wrapping_mul(2_654_435_761)
                    .wrapping_add(seed * 40_503);
                (x % 2000) as f32 / 1000.0 - 1.0
            })
            .collect()
    }

    #[test]
    fn products_match_plain_loops_in_f64_for_every_leftover_shape() {
        // sizes that fill the 4 x 4 blocks, and sizes that leave rows, columns and vector
        // tails over (whatever the machine's vector width)
        for &(rows, k, n) in &[
            (16, 64, 256),
            (5, 7, 13),
            (3, 1, 70),
            (9, 33, 129),
            (1, 2, 3),
        ] {
            let h = entries(rows * k, 1);
            let w = entries(k * n, 2);
            let start = entries(rows * n, 3);
            let mut out = start.clone();
            mul_add(&h, &w, (rows, k, n), &mut out);
            for r in 0..rows {
                for c in 0..n {
                    let want = start[r * n + c] as f64
                        + (0..k)
                            .map(|j| h[r * k + j] as f64 * w[j * n + c] as f64)
                            .sum::<f64>();
                    let got = out[r * n + c] as f64;
                    assert!(
                        (got - want).abs() <= 1e-5 * (1.0 + want.abs()) * (k as f64).sqrt(),
                        "h w, {rows}x{k}x{n} at ({r}, {c}): {got} vs {want}"
                    );
                }
            }
            // g (rows x n) times w^T, w here k x n
            let g = entries(rows * n, 4);
            let mut out_t = vec![f32::NAN; rows * k];
            mul_t(&g, &w, (rows, n, k), &mut out_t);
            for r in 0..rows {
                for j in 0..k {
                    let want: f64 = (0..n)
                        .map(|c| g[r * n + c] as f64 * w[j * n + c] as f64)
                        .sum();
                    let got = out_t[r * k + j] as f64;
                    assert!(
                        (got - want).abs() <= 1e-5 * (1.0 + want.abs()) * (n as f64).sqrt(),
                        "g w^T, {rows}x{n}x{k} at ({r}, {j}): {got} vs {want}"
                    );
                }
            }
        }
    }
}
