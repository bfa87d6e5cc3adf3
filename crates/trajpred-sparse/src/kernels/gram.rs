//! `X^T X` (and `X^T y` in the same pass) by a register-blocked kernel over packed rows.

use super::arch;
use crate::workspace::Aligned;
use pulp::{Simd, WithSimd};

/// The Gram matrix is accumulated over chunks of `GRAM_ROWS` rows: each chunk of `X` is first
/// packed transposed, `L` features (one SIMD vector) at a time, so that the micro-kernel
/// reads `3 L` features of a row as three vectors and broadcasts the `L` features of its
/// column block: `3 L x L` accumulators (24 of AVX-512's 32 registers, 12 of AVX2's 16),
/// `3 + L` loads per `3 L` fused multiply-adds. (128, 256 and 512 rows ran equally fast on
/// 5000 x 500.)
const GRAM_ROWS: usize = 256;
/// Vectors of features per row block of the micro-kernel: three with AVX-512's 32 registers,
/// two with AVX2's 16 (three take all 16 with the accumulators, and the compiler spills).
fn gram_mv(lanes: usize) -> usize {
    if lanes >= 8 { 3 } else { 2 }
}

struct GramPacked<'a> {
    data: &'a [f64],
    n: usize,
    p: usize,
    /// a vector packed as feature `p`, so that `X^T extra` comes out as column `p`
    extra: &'a [f64],
    /// `p + 1` rounded up to whole vectors
    pl: usize,
    /// column-major `pl x pl`; the upper block triangle is accumulated
    g: &'a mut [f64],
}

/// Adds to `g` the products of feature blocks `ib..ib + M` (rows of `g`) with feature block
/// `jb` (columns) over the packed chunk `t` of `len` rows.
#[inline(always)]
fn gram_micro<S: Simd, const M: usize, const NR: usize>(
    simd: S,
    t: &[f64],
    len: usize,
    (ib, jb): (usize, usize),
    g: &mut [f64],
    (p, pl): (usize, usize),
) {
    let l = S::F64_LANES;
    let block = GRAM_ROWS * l;
    let mut arows: [&[S::f64s]; M] = [&[]; M];
    for (v, a) in arows.iter_mut().enumerate() {
        let o = (ib + v) * block;
        // exactly `len` vectors, so that the loop below needs no bounds check
        *a = &S::as_simd_f64s(&t[o..o + len * l]).0[..len];
    }
    let o = jb * block;
    let brows = &t[o..o + len * NR];
    let z = simd.splat_f64s(0.0);
    let mut acc = [[z; NR]; M];
    for r in 0..len {
        let mut av = [z; M];
        for v in 0..M {
            av[v] = arows[v][r];
        }
        for b in 0..NR {
            let bb = simd.splat_f64s(brows[r * NR + b]);
            for v in 0..M {
                acc[v][b] = simd.mul_add_e_f64s(av[v], bb, acc[v][b]);
            }
        }
    }
    for b in 0..NR {
        let j = jb * l + b;
        if j >= p {
            break;
        }
        for v in 0..M {
            let i0 = (ib + v) * l;
            let (head, _) = S::as_mut_simd_f64s(&mut g[j * pl + i0..j * pl + i0 + l]);
            head[0] = simd.add_f64s(head[0], acc[v][b]);
        }
    }
}

#[inline(always)]
fn gram_chunks<S: Simd, const NR: usize>(simd: S, job: GramPacked<'_>) {
    let GramPacked {
        data,
        n,
        p,
        extra,
        pl,
        g,
    } = job;
    // the extra vector is packed as feature p
    let pe = p + 1;
    let l = S::F64_LANES;
    let nblocks = pl / l;
    let block = GRAM_ROWS * l;
    let mut t = crate::workspace::Aligned::zeroed(nblocks * block);
    let t = t.as_mut_slice();
    let mut r0 = 0;
    while r0 < n {
        let len = GRAM_ROWS.min(n - r0);
        // pack: t[fb][r][lane] = X[r0 + r, fb l + lane]; padded features stay 0
        for fb in 0..nblocks {
            let mut cols: [&[f64]; NR] = [&[]; NR];
            let mut width = 0;
            for (lane, c) in cols.iter_mut().enumerate() {
                let j = fb * l + lane;
                if j < p {
                    *c = &data[j * n + r0..j * n + r0 + len];
                    width = lane + 1;
                } else if j == p {
                    *c = &extra[r0..r0 + len];
                    width = lane + 1;
                }
            }
            let dst = &mut t[fb * block..fb * block + len * l];
            if width == NR {
                for (r, d) in dst.chunks_exact_mut(NR).enumerate() {
                    for lane in 0..NR {
                        d[lane] = cols[lane][r];
                    }
                }
            } else {
                for (r, d) in dst.chunks_exact_mut(NR).enumerate() {
                    for lane in 0..width {
                        d[lane] = cols[lane][r];
                    }
                }
            }
        }
        let mut ib = 0;
        while ib < nblocks {
            let m = gram_mv(l).min(nblocks - ib);
            for jb in ib..nblocks {
                let (blocks, dims) = ((ib, jb), (pe, pl));
                // the upper block triangle only: column block `jb` needs the row blocks up to
                // `jb` (the first two column blocks of a group take one and two)
                match m.min(jb - ib + 1) {
                    3 => gram_micro::<S, 3, NR>(simd, t, len, blocks, g, dims),
                    2 => gram_micro::<S, 2, NR>(simd, t, len, blocks, g, dims),
                    _ => gram_micro::<S, 1, NR>(simd, t, len, blocks, g, dims),
                }
            }
            ib += m;
        }
        r0 += len;
    }
}

impl WithSimd for GramPacked<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        match S::F64_LANES {
            8 => gram_chunks::<S, 8>(simd, self),
            4 => gram_chunks::<S, 4>(simd, self),
            2 => gram_chunks::<S, 2>(simd, self),
            _ => gram_chunks::<S, 1>(simd, self),
        }
    }
}

/// `X^T X` (p x p, symmetric) of the column-major `data` (`n` rows, `p` columns), stored
/// column-major with column stride `ld >= p` (entry `(i, j)` at `j * ld + i`), and `X^T extra`
/// (`extra.len() == n`) from the same pass over `X`: the upper block triangle of
/// `[X extra]^T [X extra]` by a register-blocked kernel over packed chunks of rows (see
/// [`GRAM_ROWS`]), then mirrored in place. Every entry is one chain of fused multiply-adds over
/// the rows in order, whichever block computed it. Returns `(G, ld, X^T extra)`.
pub(crate) fn gram(data: &[f64], n: usize, p: usize, extra: &[f64]) -> (Aligned, usize, Vec<f64>) {
    debug_assert_eq!(extra.len(), n);
    let l = lanes();
    let pl = (p + 1).div_ceil(l) * l;
    let mut buf = Aligned::zeroed(pl * pl);
    let gp = buf.as_mut_slice();
    if n > 0 && p > 0 {
        arch().dispatch(GramPacked {
            data,
            n,
            p,
            extra,
            pl,
            g: gp,
        });
    }
    let xty = gp[p * pl..p * pl + p].to_vec();
    // the lower triangle from the upper one, by tiles (both sides stay in cache)
    const TILE: usize = 32;
    for j0 in (0..p).step_by(TILE) {
        for i0 in (0..=j0).step_by(TILE) {
            for j in j0..(j0 + TILE).min(p) {
                for i in i0..(i0 + TILE).min(j) {
                    gp[i * pl + j] = gp[j * pl + i];
                }
            }
        }
    }
    (buf, pl, xty)
}

struct Lanes;

impl WithSimd for Lanes {
    type Output = usize;
    #[inline(always)]
    fn with_simd<S: Simd>(self, _simd: S) -> usize {
        S::F64_LANES
    }
}

/// Width in `f64` of the vectors the dispatched kernels use.
fn lanes() -> usize {
    arch().dispatch(Lanes)
}
