//! `X_S^T v` and `X_S^T v2` in one pass over `X_S`.

use super::{GROUP, arch};
use pulp::{Simd, WithSimd};

/// [`super::dots_with`] for two vectors at once: each column's sum with each vector is taken
/// in exactly the order `dots_with` takes it (two chains over the even and the odd vectors,
/// added, reduced, then the tail), so the results are bit for bit those of two separate
/// passes, from one read of the columns.
#[inline(always)]
fn dots2_with<S: Simd, const K: usize>(
    simd: S,
    c: [&[f64]; K],
    v: &[f64],
    v2: &[f64],
) -> ([f64; K], [f64; K]) {
    let n = v.len();
    let (vh, vt) = S::as_simd_f64s(v);
    let (wh, wt) = S::as_simd_f64s(&v2[..n]);
    let heads: [&[S::f64s]; K] = std::array::from_fn(|k| S::as_simd_f64s(&c[k][..n]).0);
    let z = simd.splat_f64s(0.0);
    let (mut a0, mut a1, mut b0, mut b1) = ([z; K], [z; K], [z; K], [z; K]);
    let pairs = vh.len() / 2;
    for i in 0..pairs {
        let (v0, v1) = (vh[2 * i], vh[2 * i + 1]);
        let (w0, w1) = (wh[2 * i], wh[2 * i + 1]);
        for k in 0..K {
            let (x0, x1) = (heads[k][2 * i], heads[k][2 * i + 1]);
            a0[k] = simd.mul_add_e_f64s(x0, v0, a0[k]);
            a1[k] = simd.mul_add_e_f64s(x1, v1, a1[k]);
            b0[k] = simd.mul_add_e_f64s(x0, w0, b0[k]);
            b1[k] = simd.mul_add_e_f64s(x1, w1, b1[k]);
        }
    }
    if vh.len() % 2 == 1 {
        let i = vh.len() - 1;
        for k in 0..K {
            a0[k] = simd.mul_add_e_f64s(heads[k][i], vh[i], a0[k]);
            b0[k] = simd.mul_add_e_f64s(heads[k][i], wh[i], b0[k]);
        }
    }
    let done = vh.len() * S::F64_LANES;
    let (mut out, mut out2) = ([0.0; K], [0.0; K]);
    for k in 0..K {
        let mut r = simd.reduce_sum_f64s(simd.add_f64s(a0[k], a1[k]));
        let mut r2 = simd.reduce_sum_f64s(simd.add_f64s(b0[k], b1[k]));
        for ((x, y), y2) in c[k][done..n].iter().zip(vt).zip(wt) {
            r += x * y;
            r2 += x * y2;
        }
        out[k] = r;
        out2[k] = r2;
    }
    (out, out2)
}

struct Dots2<'a> {
    data: &'a [f64],
    ld: usize,
    cols: &'a [usize],
    v: &'a [f64],
    v2: &'a [f64],
    out: &'a mut [f64],
    out2: &'a mut [f64],
}

impl WithSimd for Dots2<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Dots2 {
            data,
            ld,
            cols,
            v,
            v2,
            out,
            out2,
        } = self;
        let n = v.len();
        let col = |j: usize| &data[j * ld..j * ld + n];
        let mut groups = cols.chunks_exact(GROUP);
        let mut outs = out.chunks_exact_mut(GROUP);
        let mut outs2 = out2.chunks_exact_mut(GROUP);
        for ((g, o), o2) in (&mut groups).zip(&mut outs).zip(&mut outs2) {
            let c: [&[f64]; GROUP] = [col(g[0]), col(g[1]), col(g[2]), col(g[3])];
            let (r, r2) = dots2_with(simd, c, v, v2);
            o.copy_from_slice(&r);
            o2.copy_from_slice(&r2);
        }
        let rest = groups.remainder();
        for ((&j, o), o2) in rest
            .iter()
            .zip(outs.into_remainder())
            .zip(outs2.into_remainder())
        {
            let (r, r2) = dots2_with(simd, [col(j)], v, v2);
            *o = r[0];
            *o2 = r2[0];
        }
    }
}

/// `out[k] = x_{cols[k]}[..n] . v` and `out2[k] = x_{cols[k]}[..n] . v2` (`n = v.len() =
/// v2.len()`, column stride `ld >= n`) from one pass over the columns, bit for bit what
/// [`super::dots`] gives for each vector.
pub(crate) fn dots2(
    data: &[f64],
    ld: usize,
    cols: &[usize],
    (v, v2): (&[f64], &[f64]),
    out: &mut [f64],
    out2: &mut [f64],
) {
    debug_assert!(v.len() <= ld && v2.len() == v.len());
    debug_assert!(out.len() == cols.len() && out2.len() == cols.len());
    arch().dispatch(Dots2 {
        data,
        ld,
        cols,
        v,
        v2,
        out,
        out2,
    });
}
