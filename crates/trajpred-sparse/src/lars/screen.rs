//! Screening in single precision for a wide LAR path (`p > n`, no Gram matrix).
//!
//! Without the Gram matrix every LAR step takes `a_j = x_j . u` for every inactive column, a
//! pass over `X`; on a wide design that pass is most of the time, and it is bound by how fast
//! `X` comes from memory. Only the columns whose step length may be the shortest need `a_j`
//! exactly, so the pass reads a single-precision copy of `X` (half the bytes) and bounds the
//! error of every product it gives; the columns whose step length the bounds cannot rule out
//! are taken again in double precision, with the same kernel and in the same order as the
//! unscreened pass, and the step is the minimum over them alone. The correlations `c_j` of
//! the other columns are then updated with approximate `a_j`, and their error bounds grow
//! with each step; a column whose bound could matter (for the step length or for joining the
//! active set) has its `c_j = x_j . r` taken again in double precision from the residual `r`,
//! which is kept exactly. The path is that of the unscreened code up to the rounding of the
//! correlations (the unscreened code carries every `c_j` by updates, this one recomputes
//! some from `r`): the same variables enter in the same order at the same steps whenever the
//! unscreened path's choices are not decided by rounding.

use crate::kernels::{dot, dots32, screen_bounds};

/// Unit roundoff of `f32`.
const U32: f64 = 1.0 / (1u64 << 24) as f64;

/// Relative slack on the bounds' own arithmetic (done in `f64`, a few roundings each).
const SLACK: f64 = 1e-12;

/// `f32` values in a 64-byte line.
const LINE32: usize = 16;

/// The single-precision copy of `X`, the exact residual and the correlations' error bounds.
pub(super) struct Screen {
    /// `X` in single precision, column stride `ld` (`n` rounded up to 16), the first column
    /// at `off` (on a 64-byte line).
    x32: Vec<f32>,
    off: usize,
    ld: usize,
    n: usize,
    /// `||x_j||` (double precision), and the smallest positive one.
    norms: Vec<f64>,
    min_norm: f64,
    /// A bound on `|c_j - x_j . r|` for each column (0: `c_j` was taken exactly since the
    /// last update, or updated with an exact `a_j` only).
    err: Vec<f64>,
    /// `r = y - X beta`, updated by `r -= gamma u` at every step.
    r: Vec<f64>,
    u32: Vec<f32>,
    a32: Vec<f32>,
    /// `||u||` of this step's equiangular vector.
    u_norm: f64,
    /// This step's columns taken exactly, and whether a column is among them.
    exact: Vec<usize>,
    is_exact: Vec<bool>,
    /// Scratch of [`Screen::step`], in the order of the pass: the correlations, their bounds,
    /// the bounds of the products and the smallest step lengths the bounds allow.
    cl: Vec<f64>,
    el: Vec<f64>,
    bl: Vec<f64>,
    lo: Vec<f64>,
}

impl Screen {
    /// A screen for the column-major `data` (`n` rows, column stride `ldx`, `p` columns) and
    /// the target `ys`, or `None` when a value of `X` is too large for single precision to
    /// bound its products (beyond `1e30`) or the copy would exceed `max_bytes`.
    pub(super) fn new(
        data: &[f64],
        ldx: usize,
        (n, p): (usize, usize),
        ys: &[f64],
        max_bytes: usize,
    ) -> Option<Self> {
        let ld = n.next_multiple_of(LINE32);
        if (ld * p + LINE32) * size_of::<f32>() > max_bytes || ys.len() != n {
            return None;
        }
        let mut x32 = vec![0.0f32; ld * p + LINE32 - 1];
        // (the address is only looked at, never made into a pointer again)
        let misalign = (x32.as_ptr() as usize / size_of::<f32>()) % LINE32;
        let off = (LINE32 - misalign) % LINE32;
        let mut norms = Vec::with_capacity(p);
        for j in 0..p {
            let col = &data[j * ldx..j * ldx + n];
            if !col.iter().all(|v| v.abs() <= 1e30) {
                return None;
            }
            let dst = &mut x32[off + j * ld..off + j * ld + n];
            for (d, &v) in dst.iter_mut().zip(col) {
                *d = v as f32;
            }
            norms.push(dot(col, col).sqrt());
        }
        let min_norm = norms
            .iter()
            .copied()
            .filter(|&v| v > 0.0)
            .fold(f64::INFINITY, f64::min);
        Some(Screen {
            min_norm: if min_norm.is_finite() { min_norm } else { 1.0 },
            x32,
            off,
            ld,
            n,
            norms,
            err: vec![0.0; p],
            r: ys.to_vec(),
            u32: vec![0.0; n],
            a32: Vec::with_capacity(p),
            u_norm: 0.0,
            exact: Vec::new(),
            is_exact: vec![false; p],
            cl: Vec::with_capacity(p),
            el: Vec::with_capacity(p),
            bl: Vec::with_capacity(p),
            lo: Vec::with_capacity(p),
        })
    }

    /// Approximate `a_j = x_j . u` for the columns `order` into `out` (in that order).
    pub(super) fn pass(&mut self, order: &[usize], u: &[f64], out: &mut [f64]) {
        for (d, &v) in self.u32.iter_mut().zip(u) {
            *d = v as f32;
        }
        self.u_norm = dot(u, u).sqrt();
        self.a32.resize(order.len(), 0.0);
        let data = &self.x32[self.off..];
        dots32(data, self.ld, order, &self.u32, &mut self.a32);
        for (o, &v) in out.iter_mut().zip(&self.a32) {
            *o = f64::from(v);
        }
    }

    /// A bound on `|a_j(pass) - x_j . u|` over `||x_j||`: rounding `x_j` and `u` to single
    /// precision and the single-precision sum (`(n + 1) u32 sum |x_i u_i|` for any order of summation), with
    /// `sum |x_i u_i| <= ||x_j|| ||u||`, doubled for the double-precision rounding the exact
    /// products carry and the bounds' own arithmetic; plus what `f32` underflow can lose.
    /// (The underflow term is taken relative to the smallest positive column norm; a column of
    /// norm zero never reaches the pass.)
    fn a_factor(&self) -> f64 {
        let n = self.n as f64;
        2.0 * (n + 4.0) * U32 * self.u_norm + n * 1e-37 / self.min_norm
    }

    /// Correlations that may reach `threshold` taken exactly: `c_j = x_j . r` for each column
    /// of `cols` whose bound lets `|c_j|` reach it.
    pub(super) fn refresh_near(
        &mut self,
        data: &[f64],
        ldx: usize,
        cols: &[usize],
        c: &mut [f64],
        threshold: f64,
    ) {
        for &j in cols {
            if self.err[j] > 0.0 && c[j].abs() + self.err[j] >= threshold {
                c[j] = dot(&data[j * ldx..j * ldx + self.n], &self.r);
                self.err[j] = 0.0;
            }
        }
    }

    /// The LAR step length over the columns `order` (whose approximate `a_j` are `a_listed`,
    /// in that order), `min(gamma_hat, min (C - s c_j) / (AA - s a_j))` over the quotients
    /// with both terms positive, exactly as the unscreened code takes it: the columns whose
    /// quotient the bounds cannot put above the smallest upper bound get `a_j = x_j . u` (and
    /// `c_j = x_j . r` when not exact) in double precision, written to `a` and `c`, and the
    /// minimum is over them.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step(
        &mut self,
        (data, ldx): (&[f64], usize),
        order: &[usize],
        a_listed: &[f64],
        u: &[f64],
        (c, a): (&mut [f64], &mut [f64]),
        (big_c, aa, gamma_hat): (f64, f64, f64),
    ) -> f64 {
        // per column, in the order of the pass: the correlation, its bound and the bound of
        // the product with `u`
        let kfac = self.a_factor();
        self.cl.clear();
        self.el.clear();
        self.bl.clear();
        for &j in order {
            self.cl.push(c[j]);
            self.el.push(self.err[j]);
            self.bl.push(kfac * self.norms[j]);
        }
        self.lo.resize(order.len(), 0.0);
        let listed = (&self.cl[..], a_listed, &self.el[..], &self.bl[..]);
        let hi = screen_bounds(listed, (big_c, aa, gamma_hat), &mut self.lo) * (1.0 + SLACK);
        // every column whose quotient may be at most `hi`
        for &j in &self.exact {
            self.is_exact[j] = false;
        }
        self.exact.clear();
        for (&j, &lo) in order.iter().zip(&self.lo) {
            if lo * (1.0 - SLACK) <= hi {
                self.exact.push(j);
                self.is_exact[j] = true;
            }
        }
        let mut gamma = gamma_hat;
        for &j in &self.exact {
            let col = &data[j * ldx..j * ldx + self.n];
            a[j] = dot(col, u);
            if self.err[j] > 0.0 {
                c[j] = dot(col, &self.r);
                self.err[j] = 0.0;
            }
            for side in [1.0, -1.0] {
                let (num, den) = (big_c - side * c[j], aa - side * a[j]);
                if num > 0.0 && den > 0.0 {
                    let g = num / den;
                    if g < gamma {
                        gamma = g;
                    }
                }
            }
        }
        gamma
    }

    /// After the move `c -= gamma a`: the residual follows (`r -= gamma u`) and the bounds of
    /// the columns of `order` updated with an approximate `a_j` grow by `gamma` times its bound.
    pub(super) fn moved(&mut self, order: &[usize], gamma: f64, u: &[f64]) {
        let g = gamma * self.a_factor() * (1.0 + SLACK);
        for &j in order {
            if !self.is_exact[j] {
                self.err[j] += g * self.norms[j];
            }
        }
        for (r, &v) in self.r.iter_mut().zip(u) {
            *r -= gamma * v;
        }
    }
}
