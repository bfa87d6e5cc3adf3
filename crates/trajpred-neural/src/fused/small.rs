//! The two matrix products of a recurrent step, for `f32` (the training type), without
//! packing: `out += h W` (the gates' recurrent part) and `out = g W^T` (the gradient back to
//! the previous hidden state), with `W` the row-major `[hidden, 4 hidden]` recurrent weight.
//!
//! A general GEMM (matrixmultiply, through ndarray) copies both operands into packed panels
//! on every call; for a batch of 16 rows and a 64 x 256 weight that copy of the weight took
//! as long as the multiplications (about a quarter of an LSTM epoch each). These kernels
//! read the weight where it is: `h W` broadcasts one entry of `h` per row against vectors of
//! a row of `W` (4 rows x 4 vectors of accumulators), `g W^T` takes dot products of rows of
//! `g` with rows of `W` (4 x 4 accumulators, reduced at the end). With AVX2's 16 vector
//! registers the 4 x 4 blocks spilled: there both take 4 x 2 (2026-12-07, 200 calls of
//! 32 x 64 x 256 in 60 alternating rounds, medians: `g W^T` 16.8 against 24.9 µs, `h W`
//! 19.8 against 20.6 µs). Written once against
//! `pulp`'s safe SIMD types and dispatched at run time (AVX-512, AVX2 + FMA or scalar), as
//! the LAR kernels of trajpred-sparse are. Sums run in another order than matrixmultiply's:
//! the results agree to rounding (tests below, against plain loops in `f64`).

// the kernels index fixed-size accumulator arrays in lockstep
#![allow(clippy::needless_range_loop)]

use pulp::{Arch, Simd, WithSimd};

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
        // AVX-512's 32 registers hold 4 x 4 accumulators and the operands; AVX2's 16 do
        // not (the compiler spilled them): 4 x 2 there
        if S::F32_LANES >= 16 {
            mul_add_rows::<S, 4, 4>(simd, self)
        } else {
            mul_add_rows::<S, 4, 2>(simd, self)
        }
    }
}

/// [`MulAdd`] in blocks of `RB` rows (the last rows one at a time) by `CB` vectors of
/// columns (then one vector, then the last columns one at a time).
#[inline(always)]
fn mul_add_rows<S: Simd, const RB: usize, const CB: usize>(simd: S, m: MulAdd<'_>) {
    let MulAdd {
        h,
        w,
        dims: (rows, k, n),
        out,
    } = m;
    let lanes = S::F32_LANES;
    let (wide, narrow) = (n / (CB * lanes) * CB * lanes, n / lanes * lanes);
    let mut r0 = 0;
    while r0 < rows {
        let rb = if r0 + RB <= rows { RB } else { 1 };
        let mut c0 = 0;
        while c0 < wide {
            if rb == RB {
                add_tile::<S, RB, CB>(simd, h, w, (k, n), out, (r0, c0));
            } else {
                add_tile::<S, 1, CB>(simd, h, w, (k, n), out, (r0, c0));
            }
            c0 += CB * lanes;
        }
        while c0 < narrow {
            if rb == RB {
                add_tile::<S, RB, 1>(simd, h, w, (k, n), out, (r0, c0));
            } else {
                add_tile::<S, 1, 1>(simd, h, w, (k, n), out, (r0, c0));
            }
            c0 += lanes;
        }
        for r in r0..r0 + rb {
            for kk in 0..k {
                let b = h[r * k + kk];
                for c in narrow..n {
                    out[r * n + c] += b * w[kk * n + c];
                }
            }
        }
        r0 += rb;
    }
}

/// `out[r0.., c0..] += h[r0.., :] w[:, c0..]` for `RB` rows and `CB` vectors of columns.
#[inline(always)]
fn add_tile<S: Simd, const RB: usize, const CB: usize>(
    simd: S,
    h: &[f32],
    w: &[f32],
    (k, n): (usize, usize),
    out: &mut [f32],
    (r0, c0): (usize, usize),
) {
    let width = CB * S::F32_LANES;
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
        let o = S::as_mut_simd_f32s(&mut out[(r0 + r) * n + c0..(r0 + r) * n + c0 + width]).0;
        o[..CB].copy_from_slice(&acc[r]);
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
        // as in MulAdd: 4 x 4 dot products at once with 32 registers, 4 x 2 with 16
        if S::F32_LANES >= 16 {
            mul_t_rows::<S, 4, 4>(simd, self)
        } else {
            mul_t_rows::<S, 4, 2>(simd, self)
        }
    }
}

/// [`MulT`] in tiles of `RB` rows of `g` (the last rows one at a time) by `CB` rows of `w`
/// (the last ones one at a time).
#[inline(always)]
fn mul_t_rows<S: Simd, const RB: usize, const CB: usize>(simd: S, m: MulT<'_>) {
    let MulT {
        g,
        w,
        dims: (rows, n, k),
        out,
    } = m;
    let mut r0 = 0;
    while r0 < rows {
        let rb = if r0 + RB <= rows { RB } else { 1 };
        let mut k0 = 0;
        while k0 < k {
            let cb = if k0 + CB <= k { CB } else { 1 };
            match (rb == RB, cb == CB) {
                (true, true) => dot_tile::<S, RB, CB>(simd, g, w, (n, k), out, (r0, k0)),
                (true, false) => dot_tile::<S, RB, 1>(simd, g, w, (n, k), out, (r0, k0)),
                (false, true) => dot_tile::<S, 1, CB>(simd, g, w, (n, k), out, (r0, k0)),
                (false, false) => dot_tile::<S, 1, 1>(simd, g, w, (n, k), out, (r0, k0)),
            }
            k0 += cb;
        }
        r0 += rb;
    }
}

/// `out[r0 + r, k0 + c] = g[r0 + r, :] . w[k0 + c, :]` for `RB` rows and `CB` columns.
#[inline(always)]
fn dot_tile<S: Simd, const RB: usize, const CB: usize>(
    simd: S,
    g: &[f32],
    w: &[f32],
    (n, k): (usize, usize),
    out: &mut [f32],
    (r0, k0): (usize, usize),
) {
    let lanes = S::F32_LANES;
    let vn = n / lanes * lanes;
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
