//! Dense kernels of the path: dot products, `X_S^T v` and `X_S w` over a subset `S` of the
//! columns of a column-major matrix, triangular solves, and the Gram matrix `X^T X`.
//!
//! They are written once against `pulp`'s safe SIMD abstraction and dispatched at run time
//! to AVX-512, AVX2 + FMA or plain scalar code, whichever the CPU has (the crate is built for
//! the baseline x86-64 target, where the compiler alone would use SSE2 only). Each kernel
//! keeps several independent accumulators and processes four columns per pass, so that a
//! vector of `X^T v` loads `v` once per four columns. Sums are therefore taken in a different
//! order than a plain loop (and differently on machines with different vector widths): the
//! results agree to rounding.

// the kernels index several fixed-size arrays (accumulators, operands) in lockstep
#![allow(clippy::needless_range_loop)]

use pulp::{Arch, Simd, WithSimd};

/// Columns per pass in [`dots`] and [`combine`].
const GROUP: usize = 4;
/// Columns per pass in [`combine`]: each pass reads and writes `out` once.
const COMBINE_GROUP: usize = 4;

#[inline]
fn arch() -> Arch {
    Arch::new()
}

// ---------------------------------------------------------------------------------------
// dot

/// `a . b` in exactly the order [`dots_with`] uses for each of its columns (so that a
/// column's products do not depend on which kernel computed them: exact duplicate columns
/// keep exactly equal correlations).
#[inline(always)]
fn dot_with<S: Simd>(simd: S, a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    dots_with::<S, 1>(simd, [&a[..n]], &b[..n])[0]
}

/// `a . b` with four chains (the latency-bound rows of a triangular solve).
#[inline(always)]
fn dot4_with<S: Simd>(simd: S, a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (ah, at) = S::as_simd_f64s(&a[..n]);
    let (bh, bt) = S::as_simd_f64s(&b[..n]);
    let z = simd.splat_f64s(0.0);
    let mut acc = [z; 4];
    let mut ac = ah.chunks_exact(4);
    let mut bc = bh.chunks_exact(4);
    for (x, y) in (&mut ac).zip(&mut bc) {
        for u in 0..4 {
            acc[u] = simd.mul_add_e_f64s(x[u], y[u], acc[u]);
        }
    }
    for (x, y) in ac.remainder().iter().zip(bc.remainder()) {
        acc[0] = simd.mul_add_e_f64s(*x, *y, acc[0]);
    }
    let s = simd.add_f64s(simd.add_f64s(acc[0], acc[1]), simd.add_f64s(acc[2], acc[3]));
    let mut r = simd.reduce_sum_f64s(s);
    for (x, y) in at.iter().zip(bt) {
        r += x * y;
    }
    r
}

struct Dot<'a>(&'a [f64], &'a [f64]);

impl WithSimd for Dot<'_> {
    type Output = f64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> f64 {
        dot_with(simd, self.0, self.1)
    }
}

/// `a . b` over the common length.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    arch().dispatch(Dot(a, b))
}

// ---------------------------------------------------------------------------------------
// X_S^T v

/// `K` dot products with the same `v`, two vectors of each per iteration (`2 K` chains);
/// each column is summed in the same order whatever `K`.
#[inline(always)]
fn dots_with<S: Simd, const K: usize>(simd: S, c: [&[f64]; K], v: &[f64]) -> [f64; K] {
    let n = v.len();
    let (vh, vt) = S::as_simd_f64s(v);
    let heads: [&[S::f64s]; K] = std::array::from_fn(|k| S::as_simd_f64s(&c[k][..n]).0);
    let z = simd.splat_f64s(0.0);
    let mut acc0 = [z; K];
    let mut acc1 = [z; K];
    let pairs = vh.len() / 2;
    for i in 0..pairs {
        let (v0, v1) = (vh[2 * i], vh[2 * i + 1]);
        for k in 0..K {
            acc0[k] = simd.mul_add_e_f64s(heads[k][2 * i], v0, acc0[k]);
            acc1[k] = simd.mul_add_e_f64s(heads[k][2 * i + 1], v1, acc1[k]);
        }
    }
    if vh.len() % 2 == 1 {
        let i = vh.len() - 1;
        for k in 0..K {
            acc0[k] = simd.mul_add_e_f64s(heads[k][i], vh[i], acc0[k]);
        }
    }
    let done = vh.len() * S::F64_LANES;
    // (no closures around SIMD operations: a closure is compiled without the target
    // features and would call the intrinsics out of line)
    let mut out = [0.0; K];
    for k in 0..K {
        let mut r = simd.reduce_sum_f64s(simd.add_f64s(acc0[k], acc1[k]));
        for (x, y) in c[k][done..n].iter().zip(vt) {
            r += x * y;
        }
        out[k] = r;
    }
    out
}

/// `out[k] = x_{cols[k]}[rows] . v` (`v.len()` = the number of rows).
#[inline(always)]
fn dots_into<S: Simd>(
    simd: S,
    (data, n): (&[f64], usize),
    cols: &[usize],
    (r0, r1): (usize, usize),
    v: &[f64],
    out: &mut [f64],
) {
    let sub = |j: usize| &data[j * n + r0..j * n + r1];
    let mut groups = cols.chunks_exact(GROUP);
    let mut outs = out.chunks_exact_mut(GROUP);
    for (g, o) in (&mut groups).zip(&mut outs) {
        let c: [&[f64]; GROUP] = [sub(g[0]), sub(g[1]), sub(g[2]), sub(g[3])];
        o.copy_from_slice(&dots_with(simd, c, v));
    }
    for (&j, o) in groups.remainder().iter().zip(outs.into_remainder()) {
        *o = dot_with(simd, sub(j), v);
    }
}

struct Dots<'a> {
    data: &'a [f64],
    n: usize,
    cols: &'a [usize],
    v: &'a [f64],
    out: &'a mut [f64],
}

impl WithSimd for Dots<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Dots {
            data,
            n,
            cols,
            v,
            out,
        } = self;
        dots_into(simd, (data, n), cols, (0, n), v, out);
    }
}

/// `out[k] = x_{cols[k]} . v` for the columns of the column-major `data` (`n` rows);
/// `v.len() == n`, `out.len() == cols.len()`.
pub(crate) fn dots(data: &[f64], n: usize, cols: &[usize], v: &[f64], out: &mut [f64]) {
    debug_assert_eq!(v.len(), n);
    debug_assert_eq!(out.len(), cols.len());
    arch().dispatch(Dots {
        data,
        n,
        cols,
        v,
        out,
    });
}

// ---------------------------------------------------------------------------------------
// X_S w

struct Combine<'a> {
    data: &'a [f64],
    n: usize,
    cols: &'a [usize],
    w: &'a [f64],
    out: &'a mut [f64],
}

/// `out = sum_k w[k] x_{cols[k]}[rows]` (`out.len()` = the number of rows).
#[inline(always)]
fn combine_into<S: Simd>(
    simd: S,
    (data, n): (&[f64], usize),
    cols: &[usize],
    (r0, r1): (usize, usize),
    w: &[f64],
    out: &mut [f64],
) {
    let sub = |j: usize| &data[j * n + r0..j * n + r1];
    out.fill(0.0);
    let mut k = 0;
    while k < cols.len() {
        let m = COMBINE_GROUP.min(cols.len() - k);
        // a short group repeats its first column with weight 0
        let c: [&[f64]; COMBINE_GROUP] =
            std::array::from_fn(|i| sub(cols[k + if i < m { i } else { 0 }]));
        let wk: [f64; COMBINE_GROUP] = std::array::from_fn(|i| if i < m { w[k + i] } else { 0.0 });
        let mut ws = [simd.splat_f64s(0.0); COMBINE_GROUP];
        for i in 0..COMBINE_GROUP {
            ws[i] = simd.splat_f64s(wk[i]);
        }
        let heads: [&[S::f64s]; COMBINE_GROUP] = std::array::from_fn(|i| S::as_simd_f64s(c[i]).0);
        let (oh, ot) = S::as_mut_simd_f64s(&mut *out);
        let done = oh.len() * S::F64_LANES;
        for (r, o) in oh.iter_mut().enumerate() {
            let mut acc = *o;
            for i in 0..COMBINE_GROUP {
                acc = simd.mul_add_e_f64s(ws[i], heads[i][r], acc);
            }
            *o = acc;
        }
        for (r, o) in ot.iter_mut().enumerate() {
            for i in 0..COMBINE_GROUP {
                *o += wk[i] * c[i][done + r];
            }
        }
        k += m;
    }
}

impl WithSimd for Combine<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Combine {
            data,
            n,
            cols,
            w,
            out,
        } = self;
        combine_into(simd, (data, n), cols, (0, n), w, out);
    }
}

// ---------------------------------------------------------------------------------------
// X_S^T (y - X_S b) in one pass over X_S

/// Rows per block of [`residual_dots`]: a block of up to 500 columns stays in L2 between
/// its two uses.
const RESIDUAL_ROWS: usize = 512;

struct ResidualDots<'a> {
    data: &'a [f64],
    n: usize,
    cols: &'a [usize],
    b: &'a [f64],
    y: &'a [f64],
    out: &'a mut [f64],
}

impl WithSimd for ResidualDots<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let ResidualDots {
            data,
            n,
            cols,
            b,
            y,
            out,
        } = self;
        out.fill(0.0);
        let mut r = vec![0.0; RESIDUAL_ROWS.min(n)];
        let mut part = vec![0.0; cols.len()];
        let mut r0 = 0;
        while r0 < n {
            let r1 = (r0 + RESIDUAL_ROWS).min(n);
            let rb = &mut r[..r1 - r0];
            combine_into(simd, (data, n), cols, (r0, r1), b, rb);
            for (ri, yi) in rb.iter_mut().zip(&y[r0..r1]) {
                *ri = yi - *ri;
            }
            dots_into(simd, (data, n), cols, (r0, r1), rb, &mut part);
            for (o, q) in out.iter_mut().zip(&part) {
                *o += q;
            }
            r0 = r1;
        }
    }
}

/// `out = X_S^T (y - X_S b)` for the columns `S = cols` of the column-major `data` (`n`
/// rows), by blocks of rows, so that `X_S` is read from memory once.
pub(crate) fn residual_dots(
    data: &[f64],
    n: usize,
    cols: &[usize],
    b: &[f64],
    y: &[f64],
    out: &mut [f64],
) {
    debug_assert_eq!(y.len(), n);
    debug_assert_eq!(b.len(), cols.len());
    debug_assert_eq!(out.len(), cols.len());
    arch().dispatch(ResidualDots {
        data,
        n,
        cols,
        b,
        y,
        out,
    });
}

/// `out = sum_k w[k] x_{cols[k]}` for the columns of the column-major `data` (`n` rows);
/// `out.len() == n`, `w.len() == cols.len()`.
pub(crate) fn combine(data: &[f64], n: usize, cols: &[usize], w: &[f64], out: &mut [f64]) {
    debug_assert_eq!(out.len(), n);
    debug_assert_eq!(w.len(), cols.len());
    arch().dispatch(Combine {
        data,
        n,
        cols,
        w,
        out,
    });
}

// ---------------------------------------------------------------------------------------
// triangular solves with a row-stored lower-triangular factor

/// Rows per block of the forward solve: the dot products of a block's rows with the part of
/// the solution solved before the block are independent, so they overlap in the pipeline
/// instead of waiting for each other's reductions.
const SOLVE_BLOCK: usize = 8;

/// `row[..i] . b[..i]` as the forward solve takes it: the part before `i`'s block by a
/// vector dot product, the rest in order.
#[inline(always)]
fn forward_dot_with<S: Simd>(simd: S, row: &[f64], b: &[f64], i: usize) -> f64 {
    let i0 = i / SOLVE_BLOCK * SOLVE_BLOCK;
    let mut s = dot4_with(simd, &row[..i0], &b[..i0]);
    for (r, x) in row[i0..i].iter().zip(&b[i0..i]) {
        s += r * x;
    }
    s
}

struct Forward<'a> {
    rows: &'a [Vec<f64>],
    b: &'a mut [f64],
}

impl WithSimd for Forward<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Forward { rows, b } = self;
        let mut i0 = 0;
        while i0 < rows.len() {
            let i1 = (i0 + SOLVE_BLOCK).min(rows.len());
            // the block's dot products with b[..i0] first (independent of each other) ...
            let mut head = [0.0; SOLVE_BLOCK];
            for (h, row) in head.iter_mut().zip(&rows[i0..i1]) {
                *h = dot4_with(simd, &row[..i0], &b[..i0]);
            }
            // ... then the triangle inside the block, in order (= forward_dot_with)
            for (i, row) in rows.iter().enumerate().take(i1).skip(i0) {
                let mut s = head[i - i0];
                for (r, x) in row[i0..i].iter().zip(&b[i0..i]) {
                    s += r * x;
                }
                b[i] = (b[i] - s) / row[i];
            }
            i0 = i1;
        }
    }
}

/// Solves `L z = b` in place, `rows[i]` holding `L[i][0..=i]` (one dispatch for the whole
/// solve).
pub(crate) fn forward(rows: &[Vec<f64>], b: &mut [f64]) {
    arch().dispatch(Forward { rows, b });
}

struct ForwardDot<'a>(&'a [f64], &'a [f64], usize);

impl WithSimd for ForwardDot<'_> {
    type Output = f64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> f64 {
        forward_dot_with(simd, self.0, self.1, self.2)
    }
}

/// `row[..i] . b[..i]` bit for bit as [`forward`] computes it for row `i`.
pub(crate) fn forward_dot(row: &[f64], b: &[f64], i: usize) -> f64 {
    arch().dispatch(ForwardDot(row, b, i))
}

struct Backward<'a> {
    rows: &'a [Vec<f64>],
    z: &'a mut [f64],
}

impl WithSimd for Backward<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Backward { rows, z } = self;
        for i in (0..rows.len()).rev() {
            let row = &rows[i];
            let xi = z[i] / row[i];
            z[i] = xi;
            let (zh, zt) = S::as_mut_simd_f64s(&mut z[..i]);
            let (rh, rt) = S::as_simd_f64s(&row[..i]);
            let nx = simd.splat_f64s(-xi);
            for (zv, rv) in zh.iter_mut().zip(rh) {
                *zv = simd.mul_add_e_f64s(nx, *rv, *zv);
            }
            for (zv, rv) in zt.iter_mut().zip(rt) {
                *zv -= rv * xi;
            }
        }
    }
}

/// Solves `L^T x = z` in place, `rows[i]` holding `L[i][0..=i]`.
pub(crate) fn backward(rows: &[Vec<f64>], z: &mut [f64]) {
    arch().dispatch(Backward { rows, z });
}

// ---------------------------------------------------------------------------------------
// X^T X

/// The Gram matrix is accumulated over chunks of `GRAM_ROWS` rows: each chunk of `X` is first
/// packed transposed, `L` features (one SIMD vector) at a time, so that the micro-kernel
/// reads `3 L` features of a row as three vectors and broadcasts the `L` features of its
/// column block: `3 L x L` accumulators (24 of AVX-512's 32 registers, 12 of AVX2's 16),
/// `3 + L` loads per `3 L` fused multiply-adds. (128, 256 and 512 rows ran equally fast on
/// 5000 x 500.)
const GRAM_ROWS: usize = 256;
/// Vectors of features per row block of the micro-kernel.
const GRAM_MV: usize = 3;

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
        *a = S::as_simd_f64s(&t[o..o + len * l]).0;
    }
    let o = jb * block;
    let brows = &t[o..o + len * l];
    let z = simd.splat_f64s(0.0);
    let mut acc = [[z; NR]; M];
    for (r, bchunk) in brows.chunks_exact(NR).enumerate() {
        let mut av = [z; M];
        for v in 0..M {
            av[v] = arows[v][r];
        }
        for b in 0..NR {
            let bb = simd.splat_f64s(bchunk[b]);
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
    let mut t = vec![0.0; nblocks * block];
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
            let m = GRAM_MV.min(nblocks - ib);
            for jb in ib..nblocks {
                let (blocks, dims) = ((ib, jb), (pe, pl));
                match m {
                    3 => gram_micro::<S, 3, NR>(simd, &t, len, blocks, g, dims),
                    2 => gram_micro::<S, 2, NR>(simd, &t, len, blocks, g, dims),
                    _ => gram_micro::<S, 1, NR>(simd, &t, len, blocks, g, dims),
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

/// `X^T X` (p x p, column-major, symmetric) of the column-major `data` (`n` rows, `p`
/// columns), and `X^T extra` (`extra.len() == n`) from the same pass over `X`: the upper block
/// triangle of `[X extra]^T [X extra]` by a register-blocked kernel over packed chunks of rows
/// (see [`GRAM_ROWS`]), then mirrored. Every entry is one chain of fused multiply-adds over
/// the rows in order, whichever block computed it.
pub(crate) fn gram(data: &[f64], n: usize, p: usize, extra: &[f64]) -> (Vec<f64>, Vec<f64>) {
    debug_assert_eq!(extra.len(), n);
    let l = lanes();
    let pl = (p + 1).div_ceil(l) * l;
    let mut gp = vec![0.0; pl * pl];
    if n > 0 && p > 0 {
        arch().dispatch(GramPacked {
            data,
            n,
            p,
            extra,
            pl,
            g: &mut gp,
        });
    }
    let mut g = vec![0.0; p * p];
    for j in 0..p {
        for i in 0..=j {
            let v = gp[j * pl + i];
            g[j * p + i] = v;
            g[i * p + j] = v;
        }
    }
    let xty = gp[p * pl..p * pl + p].to_vec();
    (g, xty)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn matrix(n: usize, p: usize) -> Vec<f64> {
        (0..n * p)
            .map(|k| ((k * 7919 % 1013) as f64 - 506.0) / 97.0)
            .collect()
    }

    fn naive_dot(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn kernels_agree_with_plain_loops_on_awkward_sizes() {
        // sizes around the vector widths, the four-column groups and the row panels
        for &(n, p) in &[
            (1, 1),
            (3, 2),
            (17, 5),
            (31, 9),
            (64, 4),
            (515, 7),
            (1030, 13),
        ] {
            let x = matrix(n, p);
            let v: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let cols: Vec<usize> = (0..p).rev().collect();
            let mut out = vec![0.0; p];
            dots(&x, n, &cols, &v, &mut out);
            for (k, &j) in cols.iter().enumerate() {
                let want = naive_dot(&x[j * n..(j + 1) * n], &v);
                assert!(close(out[k], want), "dots {n}x{p} col {j}");
                assert!(close(dot(&x[j * n..(j + 1) * n], &v), want), "dot {n}x{p}");
            }
            let w: Vec<f64> = (0..p).map(|k| 1.0 - 0.3 * k as f64).collect();
            let mut u = vec![f64::NAN; n];
            combine(&x, n, &cols, &w, &mut u);
            for i in 0..n {
                let want: f64 = cols.iter().zip(&w).map(|(&j, wk)| wk * x[j * n + i]).sum();
                assert!(close(u[i], want), "combine {n}x{p} row {i}");
            }
            let b: Vec<f64> = (0..p).map(|k| 0.25 * k as f64 - 0.5).collect();
            let mut rd = vec![f64::NAN; p];
            residual_dots(&x, n, &cols, &b, &v, &mut rd);
            let resid: Vec<f64> = (0..n)
                .map(|i| {
                    v[i] - cols
                        .iter()
                        .zip(&b)
                        .map(|(&j, bk)| bk * x[j * n + i])
                        .sum::<f64>()
                })
                .collect();
            for (k, &j) in cols.iter().enumerate() {
                let want = naive_dot(&x[j * n..(j + 1) * n], &resid);
                assert!(
                    (rd[k] - want).abs() <= 1e-10 * (1.0 + want.abs()),
                    "residual_dots {n}x{p} col {j}: {} vs {want}",
                    rd[k]
                );
            }
            let (g, xtv) = gram(&x, n, p, &v);
            for j in 0..p {
                let want = naive_dot(&x[j * n..(j + 1) * n], &v);
                assert!(close(xtv[j], want), "gram X^T v {n}x{p} col {j}");
            }
            for i in 0..p {
                for j in 0..p {
                    let want = naive_dot(&x[i * n..(i + 1) * n], &x[j * n..(j + 1) * n]);
                    assert!(close(g[j * p + i], want), "gram {n}x{p} ({i}, {j})");
                }
            }
        }
    }
}
