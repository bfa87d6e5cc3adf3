//! `X_S^T v` in single precision, for screening: a wide LAR path reads a single-precision
//! copy of `X` (half the bytes of a pass) to find the few columns whose step length may be
//! the shortest, and takes those columns' products again in double precision
//! (`lars/screen.rs`).

use super::{GROUP, arch};
use pulp::{Simd, WithSimd};

/// `K` columns' products with `v`, two accumulator chains per column.
#[inline(always)]
fn dots32_with<S: Simd, const K: usize>(simd: S, c: [&[f32]; K], v: &[f32]) -> [f32; K] {
    let n = v.len();
    let (vh, vt) = S::as_simd_f32s(v);
    let heads: [&[S::f32s]; K] = std::array::from_fn(|k| S::as_simd_f32s(&c[k][..n]).0);
    let z = simd.splat_f32s(0.0);
    let (mut a0, mut a1) = ([z; K], [z; K]);
    let pairs = vh.len() / 2;
    for i in 0..pairs {
        let (v0, v1) = (vh[2 * i], vh[2 * i + 1]);
        for k in 0..K {
            a0[k] = simd.mul_add_e_f32s(heads[k][2 * i], v0, a0[k]);
            a1[k] = simd.mul_add_e_f32s(heads[k][2 * i + 1], v1, a1[k]);
        }
    }
    if vh.len() % 2 == 1 {
        let i = vh.len() - 1;
        for k in 0..K {
            a0[k] = simd.mul_add_e_f32s(heads[k][i], vh[i], a0[k]);
        }
    }
    let done = vh.len() * S::F32_LANES;
    let mut out = [0.0; K];
    for k in 0..K {
        let mut r = simd.reduce_sum_f32s(simd.add_f32s(a0[k], a1[k]));
        for (x, y) in c[k][done..n].iter().zip(vt) {
            r += x * y;
        }
        out[k] = r;
    }
    out
}

struct Dots32<'a> {
    data: &'a [f32],
    ld: usize,
    cols: &'a [usize],
    v: &'a [f32],
    out: &'a mut [f32],
}

impl WithSimd for Dots32<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Dots32 {
            data,
            ld,
            cols,
            v,
            out,
        } = self;
        let n = v.len();
        let col = |j: usize| &data[j * ld..j * ld + n];
        let mut groups = cols.chunks_exact(GROUP);
        let mut outs = out.chunks_exact_mut(GROUP);
        for (g, o) in (&mut groups).zip(&mut outs) {
            let c: [&[f32]; GROUP] = [col(g[0]), col(g[1]), col(g[2]), col(g[3])];
            o.copy_from_slice(&dots32_with(simd, c, v));
        }
        for (&j, o) in groups.remainder().iter().zip(outs.into_remainder()) {
            *o = dots32_with(simd, [col(j)], v)[0];
        }
    }
}

/// `out[k] = x_{cols[k]}[..n] . v` in single precision (`n = v.len() <= ld`, column stride
/// `ld`). Each result is within `(n + 1) u32 sum_i |x_i v_i|` of the exact product of the
/// single-precision operands (`u32 = 2^-24`; recursive summation bound, any order).
pub(crate) fn dots32(data: &[f32], ld: usize, cols: &[usize], v: &[f32], out: &mut [f32]) {
    debug_assert!(v.len() <= ld);
    debug_assert_eq!(out.len(), cols.len());
    arch().dispatch(Dots32 {
        data,
        ld,
        cols,
        v,
        out,
    });
}
