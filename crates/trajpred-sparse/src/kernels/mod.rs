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
const COMBINE_GROUP: usize = 8;

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

/// `rows[k][..m] . b` for `K` rows at once (`m = b.len()`): `b` is loaded once per vector for
/// all the rows, one chain per row (`K` independent chains), so that each row is summed in the
/// same order whatever `K` (the rows of a triangular solve, and one of them alone).
#[inline(always)]
fn row_dots_with<S: Simd, const K: usize>(simd: S, rows: [&[f64]; K], b: &[f64]) -> [f64; K] {
    let m = b.len();
    let (bh, bt) = S::as_simd_f64s(b);
    let heads: [&[S::f64s]; K] = std::array::from_fn(|k| S::as_simd_f64s(&rows[k][..m]).0);
    let z = simd.splat_f64s(0.0);
    let mut acc = [z; K];
    for (i, bv) in bh.iter().enumerate() {
        for k in 0..K {
            acc[k] = simd.mul_add_e_f64s(heads[k][i], *bv, acc[k]);
        }
    }
    let done = bh.len() * S::F64_LANES;
    let mut out = [0.0; K];
    for k in 0..K {
        let mut r = simd.reduce_sum_f64s(acc[k]);
        for (x, y) in rows[k][done..m].iter().zip(bt) {
            r += x * y;
        }
        out[k] = r;
    }
    out
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

/// Which kernel [`OverColumns`] runs over all the rows.
#[derive(Clone, Copy)]
enum ColumnKernel<'a> {
    /// [`dots_into`]: `out[k] = x_{cols[k]} . v`.
    Dots,
    /// [`combine_into`]: `out = sum_k v[k] x_{cols[k]}`.
    Combine,
    /// [`residual_dots_into`]: `out = X_S^T (y - X_S v)`.
    ResidualDots {
        /// The target `y`.
        y: &'a [f64],
    },
}

/// A kernel over the columns `cols` of the column-major `data` (`n` rows) with one operand
/// vector `v`, dispatched to the CPU's SIMD: the frame [`dots`], [`combine`] and
/// [`residual_dots`] share.
struct OverColumns<'a> {
    kernel: ColumnKernel<'a>,
    data: &'a [f64],
    n: usize,
    cols: &'a [usize],
    v: &'a [f64],
    out: &'a mut [f64],
}

impl WithSimd for OverColumns<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let OverColumns {
            kernel,
            data,
            n,
            cols,
            v,
            out,
        } = self;
        match kernel {
            ColumnKernel::Dots => dots_into(simd, (data, n), cols, (0, v.len()), v, out),
            ColumnKernel::Combine => combine_into(simd, (data, n), cols, (0, out.len()), v, out),
            ColumnKernel::ResidualDots { y } => {
                residual_dots_into(simd, (data, n), cols, v, y, out)
            }
        }
    }
}

/// `out[k] = x_{cols[k]}[..v.len()] . v` for the columns of the column-major `data` (column
/// stride `n`): the whole columns when `v.len() == n`, their leading parts when shorter;
/// `out.len() == cols.len()`.
pub(crate) fn dots(data: &[f64], n: usize, cols: &[usize], v: &[f64], out: &mut [f64]) {
    debug_assert!(v.len() <= n);
    debug_assert_eq!(out.len(), cols.len());
    arch().dispatch(OverColumns {
        kernel: ColumnKernel::Dots,
        data,
        n,
        cols,
        v,
        out,
    });
}

// ---------------------------------------------------------------------------------------
// X_S w

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

// ---------------------------------------------------------------------------------------
// X_S^T (y - X_S b) in one pass over X_S

/// Rows per block of [`residual_dots`]: a block of up to 500 columns (1 MiB) stays in a 2 MiB
/// L2 cache between its two uses.
const RESIDUAL_ROWS: usize = 256;

/// `out = X_S^T (y - X_S b)` by blocks of [`RESIDUAL_ROWS`] rows.
#[inline(always)]
fn residual_dots_into<S: Simd>(
    simd: S,
    (data, n): (&[f64], usize),
    cols: &[usize],
    b: &[f64],
    y: &[f64],
    out: &mut [f64],
) {
    out.fill(0.0);
    let rows = y.len();
    let mut r = vec![0.0; RESIDUAL_ROWS.min(rows)];
    let mut part = vec![0.0; cols.len()];
    let mut r0 = 0;
    while r0 < rows {
        let r1 = (r0 + RESIDUAL_ROWS).min(rows);
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

/// `out = X_S^T (y - X_S b)` for the columns `S = cols` of the column-major `data` (column
/// stride `n`, `y.len() <= n` rows), by blocks of rows, so that `X_S` is read from memory once.
pub(crate) fn residual_dots(
    data: &[f64],
    n: usize,
    cols: &[usize],
    b: &[f64],
    y: &[f64],
    out: &mut [f64],
) {
    debug_assert!(y.len() <= n);
    debug_assert_eq!(b.len(), cols.len());
    debug_assert_eq!(out.len(), cols.len());
    arch().dispatch(OverColumns {
        kernel: ColumnKernel::ResidualDots { y },
        data,
        n,
        cols,
        v: b,
        out,
    });
}

/// `out = sum_k w[k] x_{cols[k]}` for the columns of the column-major `data` (column stride
/// `n`, `out.len() <= n` rows), `w.len() == cols.len()`.
pub(crate) fn combine(data: &[f64], n: usize, cols: &[usize], w: &[f64], out: &mut [f64]) {
    debug_assert!(out.len() <= n);
    debug_assert_eq!(w.len(), cols.len());
    arch().dispatch(OverColumns {
        kernel: ColumnKernel::Combine,
        data,
        n,
        cols,
        v: w,
        out,
    });
}

// ---------------------------------------------------------------------------------------
// triangular solves with a row-stored lower-triangular factor

/// A lower-triangular factor stored by rows, each row starting on a whole number of 8-value
/// lines from the start of `data` (row `i`, `L[i][0..=i]`, at [`tri_offset`]`(i)`): a
/// 64-byte aligned `data` makes every row's vector loads aligned.
#[derive(Clone, Copy)]
pub(crate) struct Tri<'a> {
    pub(crate) data: &'a [f64],
    pub(crate) len: usize,
}

/// Where row `i` of a [`Tri`] starts: rows `0..i` take `ceil((r + 1) / 8)` lines of 8 each.
pub(crate) const fn tri_offset(i: usize) -> usize {
    let (a, b) = (i / 8, i % 8);
    8 * (a + 1) * (4 * a + b)
}

impl<'a> Tri<'a> {
    #[inline(always)]
    fn row(&self, i: usize) -> &'a [f64] {
        let o = tri_offset(i);
        &self.data[o..o + i + 1]
    }
}

/// Rows per block of the forward solve: the dot products of a block's rows with the part of
/// the solution solved before the block are independent, so they overlap in the pipeline
/// instead of waiting for each other's reductions.
const SOLVE_BLOCK: usize = 8;

/// `row[..i] . b[..i]` as the forward solve takes it: the part before `i`'s block by a
/// vector dot product, the rest in order.
#[inline(always)]
fn forward_dot_with<S: Simd>(simd: S, row: &[f64], b: &[f64], i: usize) -> f64 {
    let i0 = i / SOLVE_BLOCK * SOLVE_BLOCK;
    let [mut s] = row_dots_with(simd, [&row[..i0]], &b[..i0]);
    for (r, x) in row[i0..i].iter().zip(&b[i0..i]) {
        s += r * x;
    }
    s
}

struct Forward<'a> {
    rows: Tri<'a>,
    b: &'a mut [f64],
}

impl WithSimd for Forward<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Forward { rows, b } = self;
        let mut i0 = 0;
        while i0 < rows.len {
            let i1 = (i0 + SOLVE_BLOCK).min(rows.len);
            // the block's dot products with b[..i0] first, all at once (a short last block
            // repeats its last row) ...
            let heads: [&[f64]; SOLVE_BLOCK] =
                std::array::from_fn(|k| &rows.row((i0 + k).min(i1 - 1))[..i0]);
            let head = row_dots_with(simd, heads, &b[..i0]);
            // ... then the triangle inside the block, in order (= forward_dot_with)
            for i in i0..i1 {
                let row = rows.row(i);
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

/// Solves `L z = b` in place (one dispatch for the whole solve).
pub(crate) fn forward(rows: Tri<'_>, b: &mut [f64]) {
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

/// Rows per group of the backward solve.
const BACK_GROUP: usize = 4;

struct Backward<'a> {
    rows: Tri<'a>,
    z: &'a mut [f64],
}

impl WithSimd for Backward<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Backward { rows, z } = self;
        // groups of BACK_GROUP rows from the bottom of the factor: the triangle inside a group
        // in order, then the group's rows leave the entries above it in one pass over `z`
        // (each entry takes the rows' products in the same order as row by row)
        let mut i1 = rows.len;
        while i1 > 0 {
            let g0 = i1.saturating_sub(BACK_GROUP);
            for i in (g0..i1).rev() {
                let row = rows.row(i);
                let xi = z[i] / row[i];
                z[i] = xi;
                for (zj, rj) in z[g0..i].iter_mut().zip(&row[g0..i]) {
                    *zj -= rj * xi;
                }
            }
            if g0 > 0 {
                // a full group (only the top rows of the factor make a short one, at g0 = 0)
                let rs: [&[f64]; BACK_GROUP] = std::array::from_fn(|k| &rows.row(i1 - 1 - k)[..g0]);
                let xs: [f64; BACK_GROUP] = std::array::from_fn(|k| z[i1 - 1 - k]);
                let mut nx = [simd.splat_f64s(0.0); BACK_GROUP];
                for k in 0..BACK_GROUP {
                    nx[k] = simd.splat_f64s(-xs[k]);
                }
                let rh: [&[S::f64s]; BACK_GROUP] =
                    std::array::from_fn(|k| S::as_simd_f64s(rs[k]).0);
                let (zh, zt) = S::as_mut_simd_f64s(&mut z[..g0]);
                let done = zh.len() * S::F64_LANES;
                for (r, zv) in zh.iter_mut().enumerate() {
                    let mut acc = *zv;
                    for k in 0..BACK_GROUP {
                        acc = simd.mul_add_e_f64s(nx[k], rh[k][r], acc);
                    }
                    *zv = acc;
                }
                for (j, zv) in zt.iter_mut().enumerate() {
                    for k in 0..BACK_GROUP {
                        *zv -= rs[k][done + j] * xs[k];
                    }
                }
            }
            i1 = g0;
        }
    }
}

/// Solves `L^T x = z` in place.
pub(crate) fn backward(rows: Tri<'_>, z: &mut [f64]) {
    arch().dispatch(Backward { rows, z });
}

mod dots2;
mod dots32;
mod gram;
mod screen_bounds;
pub(crate) mod step;
pub(crate) use dots2::dots2;
pub(crate) use dots32::dots32;
pub(crate) use gram::gram;
pub(crate) use screen_bounds::screen_bounds;
#[cfg(test)]
pub(crate) use screen_bounds::screen_bounds_plain;
pub(crate) use step::step_min;

#[cfg(test)]
mod tests;
