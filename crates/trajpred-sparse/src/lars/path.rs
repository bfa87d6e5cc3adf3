//! The path itself, on the standardised problem: the LAR / lasso steps with an incrementally
//! updated Cholesky factor, with or without the Gram matrix, and the final refinement.

use super::knots::Knots;
use super::screen::Screen;
use super::{Exclusion, ExclusionReason, LarsParams, Method, PathEvent, StopReason};
use crate::cholesky::{Append, CholeskyFactor};
use crate::kernels::{self, dot};
use crate::workspace::Aligned;
use nalgebra::DMatrix;

/// A refinement correction at most this many `eps` of the largest active coefficient is
/// rounding: no further sweep (see [`Core::refine`]). The end point of a 5000 x 500 Gaussian
/// design moves by ~10 eps in its first sweep and ~2 eps in a second.
const REFINE_NEGLIGIBLE: f64 = 32.0;

pub(super) struct Path {
    pub(super) alphas: Vec<f64>,
    /// knot after knot, `p` coefficients each
    pub(super) coefs: Knots,
    pub(super) events: Vec<PathEvent>,
    pub(super) active: Vec<usize>,
    pub(super) stop: StopReason,
    pub(super) chol: CholeskyFactor,
}

pub(super) struct Core<'a> {
    xs: &'a DMatrix<f64>,
    /// Without the Gram matrix, when `X` is read at every step: a copy of `X` whose columns
    /// start on 64-byte lines (column stride `ldx`, `n` rounded up to 8), unless `X` is
    /// already laid out so or too large to copy (see [`design`]).
    xcopy: Option<Aligned>,
    ldx: usize,
    n: usize,
    p: usize,
    /// `X^T X` (column-major p x p, column stride `ld`), when precomputed.
    gram: Option<Aligned>,
    ld: usize,
    /// `X^T y`, computed with the Gram matrix.
    xty: Option<Vec<f64>>,
    /// `||x_j||^2`.
    sq_norms: Vec<f64>,
    /// Scratch without the Gram matrix: the equiangular vector `u = X_A w` (length n).
    u: Vec<f64>,
    /// The eligible inactive columns, in increasing order (kept up to date by `run`), and
    /// their `a_j`.
    inactive: Vec<usize>,
    a_inactive: Vec<f64>,
    /// With the Gram matrix, its rows are kept permuted so that the active set's come first,
    /// in its order: column `j` (stored contiguously) then holds `G[perm[c], j]` at offset
    /// `c`, and, `G` being symmetric, its first `k` entries are `G[j, A]`: each inactive
    /// column's correlation with the equiangular direction is one contiguous dot product. A
    /// variable entering swaps one pair of rows (sklearn's `lars_path` swaps its Gram matrix
    /// the same way); a drop moves the positions after it. `pos_of` is the inverse of `perm`.
    perm: Vec<usize>,
    pos_of: Vec<usize>,
    /// Without the Gram matrix: the inactive columns in the order of this step's pass over
    /// `X`, and whether it runs from the last column.
    order: Vec<usize>,
    backwards: bool,
    /// Without the Gram matrix, on a LAR path: `x_a . x_j` saved for the active variables
    /// `a` and the columns `j` still inactive (see [`Saved`]).
    saved: Saved,
    /// Without the Gram matrix, on a wide LAR path: the single-precision screen of the pass
    /// over `X` (see [`Screen`]).
    screen: Option<Screen>,
}

/// The products of each active variable with the columns inactive when it entered, taken in
/// the pass over `X` of the step it entered (one pass for `X_I^T u` and `X_I^T x_a`), so that
/// a variable entering later finds its products with the active set here instead of in
/// another pass over `X_A`. Bit for bit the same products (`x_a . x_j` and `x_j . x_a` are
/// the same chains of the same products). Row `j` of `g` (`cap` values) holds `x_a . x_j` for
/// the active positions `0..have`; off after a step where several variables entered, and on
/// a lasso path (its drops reorder the active set).
struct Saved {
    on: bool,
    g: Vec<f64>,
    cap: usize,
    have: usize,
    new: Vec<f64>,
}

impl Drop for Saved {
    fn drop(&mut self) {
        crate::workspace::recycle(std::mem::take(&mut self.g));
    }
}

/// Largest table of [`Saved`] products (bytes).
const SAVED_BYTES: usize = 16 << 20;

impl<'a> Core<'a> {
    /// With `use_gram`, `X^T X` and `X^T ys` are computed here, in one pass over `X`.
    pub(super) fn new(xs: &'a DMatrix<f64>, ys: &[f64], use_gram: bool) -> Self {
        let (n, p) = xs.shape();
        let (gram, ld, xty) = if use_gram {
            let (g, ld, xty) = kernels::gram(xs.as_slice(), n, p, ys);
            (Some(g), ld, Some(xty))
        } else {
            (None, p, None)
        };
        let sq_norms = match &gram {
            Some(g) => (0..p).map(|j| g.as_slice()[j * ld + j]).collect(),
            None => (0..p)
                .map(|j| {
                    let c = &xs.as_slice()[j * n..(j + 1) * n];
                    dot(c, c)
                })
                .collect(),
        };
        let (xcopy, ldx) = if use_gram {
            (None, n)
        } else {
            aligned_copy(xs)
        };
        Core {
            xs,
            xcopy,
            ldx,
            n,
            p,
            gram,
            ld,
            xty,
            sq_norms,
            u: vec![0.0; if use_gram { 0 } else { n }],
            inactive: Vec::with_capacity(p),
            a_inactive: Vec::with_capacity(p),
            perm: (0..p).collect(),
            pos_of: (0..p).collect(),
            order: Vec::with_capacity(if use_gram { 0 } else { p }),
            backwards: false,
            saved: Saved {
                on: false,
                g: Vec::new(),
                cap: 0,
                have: 0,
                new: Vec::new(),
            },
            screen: None,
        }
    }

    /// `||x_j||^2` (from the Gram matrix's diagonal when it is computed).
    pub(super) fn sq_norm(&self, j: usize) -> f64 {
        self.sq_norms[j]
    }

    fn col(&self, j: usize) -> &[f64] {
        &design(self.xs, &self.xcopy)[j * self.ldx..j * self.ldx + self.n]
    }

    /// `G[A, j]` in the order of `active`.
    fn gram_with_active(&self, active: &[usize], j: usize, out: &mut Vec<f64>) {
        out.clear();
        match &self.gram {
            Some(g) => {
                let g = g.as_slice();
                out.extend(active.iter().map(|&a| g[j * self.ld + self.pos_of[a]]));
            }
            None if self.saved.on && self.saved.have == active.len() => {
                let o = j * self.saved.cap;
                out.extend_from_slice(&self.saved.g[o..o + active.len()]);
            }
            None => {
                out.resize(active.len(), 0.0);
                let data = design(self.xs, &self.xcopy);
                kernels::dots(data, self.ldx, active, self.col(j), out);
            }
        }
    }

    /// `a = X^T X_A w` for the eligible inactive columns (`self.inactive`; from the Gram
    /// matrix's rows of those columns, or from `u = X_A w`), and `a_j = aa s_j` (eq. 2.6) on
    /// the active set.
    #[allow(clippy::too_many_arguments)]
    fn equiangular_correlations(
        &mut self,
        active: &[usize],
        w: &[f64],
        signs: &[f64],
        aa: f64,
        a: &mut [f64],
    ) {
        match self.gram.as_mut() {
            Some(g) => {
                let g = g.as_mut_slice();
                let ld = self.ld;
                for (pos, &f) in active.iter().enumerate() {
                    if self.perm[pos] != f {
                        let c = self.pos_of[f];
                        for col in g.chunks_exact_mut(ld).take(self.p) {
                            col.swap(pos, c);
                        }
                        let other = self.perm[pos];
                        self.perm.swap(pos, c);
                        self.pos_of[f] = pos;
                        self.pos_of[other] = c;
                    }
                }
                self.a_inactive.resize(self.inactive.len(), 0.0);
                kernels::dots(g, ld, &self.inactive, w, &mut self.a_inactive);
                a.fill(0.0);
                for (&j, &v) in self.inactive.iter().zip(&self.a_inactive) {
                    a[j] = v;
                }
            }
            None => {
                let data = design(self.xs, &self.xcopy);
                kernels::combine(data, self.ldx, active, w, &mut self.u);
                self.a_inactive.resize(self.inactive.len(), 0.0);
                // every other step the columns are taken from the last: the pass then starts
                // on the columns the previous one ended with, which are still in cache when
                // `X` is larger than it (each column's sum is the same in either order)
                self.backwards = !self.backwards;
                self.order.clear();
                if self.backwards {
                    self.order.extend(self.inactive.iter().rev());
                } else {
                    self.order.extend_from_slice(&self.inactive);
                }
                let k = active.len();
                if let Some(screen) = self.screen.as_mut() {
                    // approximate products; the step length takes the ones that matter again
                    screen.pass(&self.order, &self.u, &mut self.a_inactive);
                } else if self.saved.on
                    && k == self.saved.have + 1
                    && self.saved.have < self.saved.cap
                {
                    // the variable that entered last: its products with the inactive columns
                    // from the same pass, for when one of them enters
                    let f = active[self.saved.have];
                    let xf = &data[f * self.ldx..f * self.ldx + self.n];
                    self.saved.new.resize(self.order.len(), 0.0);
                    kernels::dots2(
                        data,
                        self.ldx,
                        &self.order,
                        (&self.u, xf),
                        &mut self.a_inactive,
                        &mut self.saved.new,
                    );
                    let (cap, have) = (self.saved.cap, self.saved.have);
                    for (&j, &v) in self.order.iter().zip(&self.saved.new) {
                        self.saved.g[j * cap + have] = v;
                    }
                    self.saved.have += 1;
                } else {
                    // (several variables entered together, or no room: not saved from here)
                    self.saved.on &= k == self.saved.have;
                    kernels::dots(data, self.ldx, &self.order, &self.u, &mut self.a_inactive);
                }
                a.fill(0.0);
                for (&j, &v) in self.order.iter().zip(&self.a_inactive) {
                    a[j] = v;
                }
            }
        }
        for (&j, &s) in active.iter().zip(signs) {
            a[j] = aa * s;
        }
    }

    /// Iterative refinement of the least-squares fit on the active set at the end of a full
    /// path: `beta_A += G_AA^{-1} X_A^T (y - X_A beta_A)`, with the residual recomputed from
    /// `X` each time. The path's incremental updates work on the normal equations, whose
    /// rounding grows with cond(X)^2; two refinement sweeps bring the end point to the
    /// accuracy of a least-squares solve (cond(X) * eps for a small residual). A first
    /// correction of at most [`REFINE_NEGLIGIBLE`] `eps max|beta_A|` shows that the path's end
    /// point was already within rounding of the fixed point (the error left after a sweep is
    /// a fraction of its correction whenever the sweeps converge), and the second sweep, a
    /// pass over `X_A`, is skipped.
    pub(super) fn refine(
        &self,
        active: &[usize],
        chol: &CholeskyFactor,
        ys: &[f64],
        beta: &mut [f64],
    ) {
        if active.is_empty() || chol.len() != active.len() {
            return;
        }
        let data = design(self.xs, &self.xcopy);
        let mut delta = vec![0.0; active.len()];
        let mut b = vec![0.0; active.len()];
        for _ in 0..2 {
            for (bk, &k) in b.iter_mut().zip(active) {
                *bk = beta[k];
            }
            kernels::residual_dots(data, self.ldx, active, &b, ys, &mut delta);
            chol.solve_in_place(&mut delta);
            if delta.iter().any(|d| !d.is_finite()) {
                return;
            }
            for (&k, d) in active.iter().zip(&delta) {
                beta[k] += d;
            }
            let scale = active.iter().map(|&k| beta[k].abs()).fold(0.0, f64::max);
            let moved = delta.iter().map(|d| d.abs()).fold(0.0, f64::max);
            if moved <= REFINE_NEGLIGIBLE * f64::EPSILON * scale {
                break;
            }
        }
    }

    pub(super) fn run(
        &mut self,
        params: &LarsParams,
        ys: &[f64],
        mut eligible: Vec<bool>,
        excluded: &mut Vec<Exclusion>,
    ) -> Path {
        let p = self.p;
        let nf = self.n as f64;
        let mut c = vec![0.0; p];
        if let Some(xty) = &self.xty {
            for j in (0..p).filter(|&j| eligible[j]) {
                c[j] = xty[j];
            }
        } else {
            let cols: Vec<usize> = (0..p).filter(|&j| eligible[j]).collect();
            let mut cc = vec![0.0; cols.len()];
            let data = design(self.xs, &self.xcopy);
            kernels::dots(data, self.ldx, &cols, ys, &mut cc);
            for (&j, v) in cols.iter().zip(cc) {
                c[j] = v;
            }
        }
        self.inactive.clear();
        self.inactive.extend((0..p).filter(|&j| eligible[j]));
        let cap = self.n.min(p);
        if self.gram.is_none() && params.method == Method::Lar && p > self.n && params.screen {
            let data = design(self.xs, &self.xcopy);
            self.screen = Screen::new(data, self.ldx, (self.n, p), ys, SCREEN_BYTES);
        }
        if self.gram.is_none()
            && self.screen.is_none()
            && params.method == Method::Lar
            && p * cap * size_of::<f64>() <= SAVED_BYTES
        {
            // (never read before written: no need for zeros, but the pool gives them)
            self.saved.g = crate::workspace::zeroed(p * cap);
            self.saved.cap = cap;
            self.saved.have = 0;
            self.saved.on = true;
        }
        let c0 = self
            .inactive
            .iter()
            .map(|&j| c[j].abs())
            .fold(0.0, f64::max);

        let mut beta = vec![0.0; p];
        let mut alphas = vec![c0 / nf];
        // room for the knots of a full LAR path (the lasso may need more), within reason
        let knots_guess = self.n.min(p).min(params.max_steps.unwrap_or(usize::MAX)) + 2;
        let mut coefs = Knots::with_capacity(p, knots_guess.min((1 << 24) / p.max(1)));
        coefs.push(&beta);
        let mut events = Vec::new();
        let mut active: Vec<usize> = Vec::new();
        let mut signs: Vec<f64> = Vec::new();
        let mut chol = CholeskyFactor::with_capacity(self.n.min(p));
        // z = L^{-1} s, extended on each entry, recomputed after drops (the downdate changes L)
        let mut z: Vec<f64> = Vec::new();
        let mut z_stale = false;
        let mut just_dropped: Vec<usize> = Vec::new();
        let mut big_c = c0;
        let mut step = 0usize;
        let mut scratch = Vec::new();
        let mut candidates: Vec<usize> = Vec::new();
        let mut w: Vec<f64> = Vec::new();
        let mut drops: Vec<usize> = Vec::new(); // positions in `active`
        let mut a = vec![0.0; p];
        let mut c_listed: Vec<f64> = Vec::with_capacity(p);

        let finish = |alphas, coefs, events, active, stop, chol| Path {
            alphas,
            coefs,
            events,
            active,
            stop,
            chol,
        };

        if c0.is_nan() || c0 <= 0.0 {
            alphas[0] = 0.0;
            return finish(
                alphas,
                coefs,
                events,
                active,
                StopReason::CorrelationVanished,
                chol,
            );
        }
        if c0 / nf <= params.alpha_min {
            alphas[0] = params.alpha_min;
            return finish(alphas, coefs, events, active, StopReason::AlphaMin, chol);
        }

        loop {
            if big_c <= params.vanish_tolerance * c0 {
                return finish(
                    alphas,
                    coefs,
                    events,
                    active,
                    StopReason::CorrelationVanished,
                    chol,
                );
            }
            if params.max_steps.is_some_and(|m| step >= m) {
                return finish(alphas, coefs, events, active, StopReason::MaxSteps, chol);
            }
            step += 1;

            // --- variables that tie for the largest correlation enter -------------------------
            let threshold = big_c * (1.0 - params.tie_tolerance);
            if let Some(screen) = self.screen.as_mut() {
                let data = design(self.xs, &self.xcopy);
                screen.refresh_near(data, self.ldx, &self.inactive, &mut c, threshold);
            }
            candidates.clear();
            candidates.extend(
                self.inactive
                    .iter()
                    .copied()
                    .filter(|&j| c[j].abs() >= threshold && !just_dropped.contains(&j)),
            );
            candidates.sort_by(|&i, &j| c[j].abs().total_cmp(&c[i].abs()).then(i.cmp(&j)));
            if z_stale {
                z.clone_from(&signs);
                chol.forward_in_place(&mut z);
                z_stale = false;
            }
            for &j in &candidates {
                self.gram_with_active(&active, j, &mut scratch);
                match chol.append(&scratch, self.sq_norms[j], params.collinearity_tolerance) {
                    Append::Appended => {
                        remove_sorted(&mut self.inactive, j);
                        active.push(j);
                        let sj = if c[j] >= 0.0 { 1.0 } else { -1.0 };
                        signs.push(sj);
                        // the factor grew by one row: z = L^{-1} s grows by one entry, the
                        // same value a full forward solve would give
                        chol.forward_extend(&mut z, sj);
                        events.push(PathEvent::Added { feature: j, step });
                    }
                    Append::Collinear => {
                        remove_sorted(&mut self.inactive, j);
                        eligible[j] = false;
                        excluded.push(Exclusion {
                            feature: j,
                            reason: ExclusionReason::Collinear,
                            step,
                        });
                        log::debug!("LARS step {step}: column {j} is collinear, excluded");
                    }
                }
            }
            if active.is_empty() {
                return finish(
                    alphas,
                    coefs,
                    events,
                    active,
                    StopReason::CorrelationVanished,
                    chol,
                );
            }

            // --- equiangular direction: w = AA G_AA^{-1} s ---------------------------------
            w.clone_from(&z);
            chol.backward_in_place(&mut w);
            let q: f64 = w.iter().zip(&signs).map(|(wi, si)| wi * si).sum();
            if !(q.is_finite() && q > 0.0) {
                return finish(
                    alphas,
                    coefs,
                    events,
                    active,
                    StopReason::NumericalBreakdown,
                    chol,
                );
            }
            let aa = 1.0 / q.sqrt();
            w.iter_mut().for_each(|v| *v *= aa);
            self.equiangular_correlations(&active, &w, &signs, aa, &mut a);

            // --- step length --------------------------------------------------------------
            let gamma_hat = big_c / aa;
            let mut gamma = gamma_hat;
            // `self.inactive`: the eligible inactive columns, listed for the correlations
            let any_inactive = !self.inactive.is_empty();
            // the same minimum by a vector kernel over the correlations as they were listed
            // (with `c` gathered in that order), unless a variable was just dropped
            let listed: &[usize] = if just_dropped.is_empty() {
                if self.gram.is_some() {
                    &self.inactive
                } else {
                    &self.order
                }
            } else {
                &[]
            };
            if let (Some(screen), false) = (self.screen.as_mut(), listed.is_empty()) {
                let data = design(self.xs, &self.xcopy);
                gamma = screen.step(
                    (data, self.ldx),
                    listed,
                    &self.a_inactive,
                    &self.u,
                    (&mut c, &mut a),
                    (big_c, aa, gamma_hat),
                );
            } else if !listed.is_empty() {
                c_listed.clear();
                c_listed.extend(listed.iter().map(|&j| c[j]));
                gamma = kernels::step_min(&c_listed, &self.a_inactive, big_c, aa, gamma_hat);
            }
            let scalar: &[usize] = if listed.is_empty() {
                &self.inactive
            } else {
                &[]
            };
            for &j in scalar {
                let dropped_now = just_dropped.contains(&j);
                for side in [1.0, -1.0] {
                    // a just-dropped variable sits exactly at |c_j| = C on its own side
                    if dropped_now && side * c[j] > 0.0 {
                        continue;
                    }
                    let num = big_c - side * c[j];
                    let den = aa - side * a[j];
                    // the division only when it may shorten the step: num / den < gamma
                    // implies num < gamma den (1 + 4 eps) whatever the rounding (`&`, not
                    // `&&`: one rarely taken branch instead of three unpredictable ones)
                    if (num > 0.0) & (den > 0.0) & (num < gamma * den * (1.0 + 4.0 * f64::EPSILON))
                    {
                        let g = num / den;
                        if g < gamma {
                            gamma = g;
                        }
                    }
                }
            }
            // lasso: the first active coefficient to reach zero
            drops.clear();
            if params.method == Method::Lasso {
                let mut z_min = f64::INFINITY;
                for (pos, &j) in active.iter().enumerate() {
                    if w[pos] != 0.0 {
                        let z = -beta[j] / w[pos];
                        if z > 0.0 && z < z_min {
                            z_min = z;
                        }
                    }
                }
                if z_min < gamma {
                    gamma = z_min;
                    for (pos, &j) in active.iter().enumerate() {
                        if w[pos] != 0.0 {
                            let z = -beta[j] / w[pos];
                            if z > 0.0 && z <= z_min * (1.0 + 1e-12) {
                                drops.push(pos);
                            }
                        }
                    }
                }
            }
            let full_step = drops.is_empty() && gamma >= gamma_hat;

            // --- move -------------------------------------------------------------------
            for (pos, &j) in active.iter().enumerate() {
                beta[j] += gamma * w[pos];
            }
            for (cj, aj) in c.iter_mut().zip(&a) {
                *cj -= gamma * aj;
            }
            if let Some(screen) = self.screen.as_mut() {
                screen.moved(&self.order, gamma, &self.u);
            }
            big_c = if full_step {
                0.0
            } else {
                (big_c - gamma * aa).max(0.0)
            };

            just_dropped.clear();
            for &pos in drops.iter().rev() {
                let j = active.remove(pos);
                signs.remove(pos);
                chol.remove(pos);
                z_stale = true;
                insert_sorted(&mut self.inactive, j);
                beta[j] = 0.0;
                just_dropped.push(j);
                events.push(PathEvent::Dropped { feature: j, step });
            }

            let alpha = big_c / nf;
            let prev_alpha = alphas[alphas.len() - 1];
            if params.alpha_min > 0.0 && alpha <= params.alpha_min {
                let prev = coefs.knot(coefs.len() - 1);
                let ss = if prev_alpha > alpha {
                    (prev_alpha - params.alpha_min) / (prev_alpha - alpha)
                } else {
                    1.0
                };
                let knot: Vec<f64> = prev
                    .iter()
                    .zip(&beta)
                    .map(|(b0, b1)| b0 + ss * (b1 - b0))
                    .collect();
                alphas.push(params.alpha_min);
                coefs.push(&knot);
                return finish(alphas, coefs, events, active, StopReason::AlphaMin, chol);
            }
            alphas.push(alpha);
            coefs.push(&beta);
            if full_step {
                let stop = if any_inactive {
                    StopReason::CorrelationVanished
                } else {
                    StopReason::Complete
                };
                return finish(alphas, coefs, events, active, stop, chol);
            }
        }
    }
}

/// Largest single-precision copy of `X` a [`Screen`] makes (bytes).
const SCREEN_BYTES: usize = 16 << 20;

/// Largest design copied by [`aligned_copy`] (bytes): the copy is kept for the next fit (see
/// [`crate::workspace`]), whose pool keeps at most 32 MiB.
const COPY_BYTES: usize = 32 << 20;

/// A copy of `xs` whose columns start on 64-byte lines (an AVX-512 vector load from a column
/// then never straddles two lines: on 200 x 1000, 4.8-5.1 -> 4.2-4.6 ms per path), and its
/// column stride; `(None, n)` when `xs` is already laid out so, or larger than
/// [`COPY_BYTES`]. Every column's sums are taken in the same order either way.
fn aligned_copy(xs: &DMatrix<f64>) -> (Option<Aligned>, usize) {
    let (n, p) = xs.shape();
    let data = xs.as_slice();
    let ld = n.next_multiple_of(8);
    let aligned = (data.as_ptr() as usize).is_multiple_of(64) && ld == n;
    if aligned || n == 0 || ld * p * size_of::<f64>() > COPY_BYTES {
        return (None, n);
    }
    let mut copy = Aligned::zeroed(ld * p);
    for (dst, src) in copy
        .as_mut_slice()
        .chunks_exact_mut(ld)
        .zip(data.chunks_exact(n))
    {
        dst[..n].copy_from_slice(src);
    }
    (Some(copy), ld)
}

/// The design the path reads: the aligned copy when there is one.
fn design<'b>(xs: &'b DMatrix<f64>, copy: &'b Option<Aligned>) -> &'b [f64] {
    match copy {
        Some(c) => c.as_slice(),
        None => xs.as_slice(),
    }
}

/// Removes `j` from the increasing list `list` (if present).
fn remove_sorted(list: &mut Vec<usize>, j: usize) {
    if let Ok(pos) = list.binary_search(&j) {
        list.remove(pos);
    }
}

/// Inserts `j` into the increasing list `list` (if absent).
fn insert_sorted(list: &mut Vec<usize>, j: usize) {
    if let Err(pos) = list.binary_search(&j) {
        list.insert(pos, j);
    }
}
