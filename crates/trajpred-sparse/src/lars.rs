//! Least angle regression: the LAR path and its lasso modification (Efron, Hastie,
//! Johnstone, Tibshirani 2004), with a validating builder ([`LarsParams`]) and the whole
//! fitted path ([`Lars`]).

use crate::cholesky::{Append, CholeskyFactor};
use crate::error::{Error, Result};
use crate::kernels::{self, dot};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Which path to compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Method {
    /// Plain least angle regression: variables only enter; the end of the full path is the
    /// least-squares fit. The sign `s_j` of an active variable is the sign of its correlation
    /// when it entered and never changes, even when its coefficient crosses zero.
    #[default]
    Lar,
    /// The lasso modification: a variable whose coefficient reaches zero is dropped from the
    /// active set at that point, so the path is the lasso solution path.
    Lasso,
}

/// When to use the precomputed Gram matrix `X^T X` (p x p) instead of passes over `X`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Gram {
    /// Precompute when `p <= n` and `p <= 4096` (the Gram matrix then costs less than the
    /// passes over `X` a full path needs, and at most 128 MiB).
    #[default]
    Auto,
    /// Always precompute `X^T X`.
    Precompute,
    /// Never: every step does two passes over `X` (for wide or very large designs).
    Never,
}

/// Why a column never entered the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ExclusionReason {
    /// The column is constant (zero after centring; exactly zero without an intercept).
    ZeroVariance,
    /// When it tied for the largest correlation, the column lay in the span of the active
    /// columns (an exact or numerical duplicate or linear combination), so it cannot change
    /// the fit; it is dropped for good, as in R's `lars`.
    Collinear,
}

/// A column that is kept out of the path, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Exclusion {
    /// Column index (0-based, as in the input).
    pub feature: usize,
    /// Why it is excluded.
    pub reason: ExclusionReason,
    /// Step during which it was excluded (0 for zero-variance columns, found before the path).
    pub step: usize,
}

/// One change of the active set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum PathEvent {
    /// `feature` entered the active set at the start of step `step` (1-based), that is at knot
    /// `step - 1`.
    Added {
        /// Column index.
        feature: usize,
        /// Step number (1-based).
        step: usize,
    },
    /// Lasso only: `feature`'s coefficient reached zero at the end of step `step`, i.e. at
    /// knot `step`, and it left the active set.
    Dropped {
        /// Column index.
        feature: usize,
        /// Step number (1-based).
        step: usize,
    },
}

/// Why the path ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum StopReason {
    /// Every usable column is active and the last knot is the least-squares fit on them.
    Complete,
    /// The largest residual correlation vanished (relative to its starting value) before all
    /// columns entered: the residual is orthogonal to every column (for instance `p > n`
    /// after `rank(X)` steps, or an exactly representable target).
    CorrelationVanished,
    /// The requested number of steps was taken.
    MaxSteps,
    /// The path reached `alpha_min`; the last knot is interpolated to exactly `alpha_min`.
    AlphaMin,
    /// The equiangular direction could not be computed (the active Gram matrix is numerically
    /// singular despite the collinearity check); the path ends at the last good knot.
    NumericalBreakdown,
}

/// Builder of a LARS fit; validates its parameters and the data in [`LarsParams::fit`].
///
/// Defaults: [`Method::Lar`], intercept fitted, columns centred and scaled to unit L2 norm
/// (`docs/papers.md` A.2), full path, `alpha_min = 0`, tie tolerance `1e-12`, collinearity
/// tolerance `1e-12`, vanishing-correlation tolerance `1e-12`.
///
/// ```
/// use nalgebra::DMatrix;
/// use trajpred_sparse::{Lars, Method, Error};
/// let x = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 2.0, 1.0, 3.0, 0.0, 4.0, 2.0]);
/// let y = [1.0, 3.0, 3.0, 6.0];
/// let fit = Lars::params().method(Method::Lasso).fit(&x, &y)?;
/// // the full path ends at least squares: y = 0 + 1 * x1 + 1 * x2 fits exactly
/// assert!((fit.predict_row(&[5.0, 1.0])? - 6.0).abs() < 1e-9);
/// // bad parameters are typed errors
/// assert!(matches!(Lars::params().alpha_min(-1.0).fit(&x, &y), Err(Error::InvalidParameter { .. })));
/// # Ok::<(), Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LarsParams {
    method: Method,
    fit_intercept: bool,
    normalize: bool,
    max_steps: Option<usize>,
    alpha_min: f64,
    tie_tolerance: f64,
    collinearity_tolerance: f64,
    vanish_tolerance: f64,
    gram: Gram,
}

impl Default for LarsParams {
    fn default() -> Self {
        LarsParams {
            method: Method::Lar,
            fit_intercept: true,
            normalize: true,
            max_steps: None,
            alpha_min: 0.0,
            tie_tolerance: 1e-12,
            collinearity_tolerance: 1e-12,
            vanish_tolerance: 1e-12,
            gram: Gram::Auto,
        }
    }
}

impl LarsParams {
    /// LAR or lasso.
    pub fn method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// Fit an intercept (centre the columns and the target). Default `true`.
    pub fn fit_intercept(mut self, yes: bool) -> Self {
        self.fit_intercept = yes;
        self
    }

    /// Scale every (centred, if `fit_intercept`) column to unit L2 norm before the path.
    /// Default `true`. Alphas and [`Lars::standardized_coef_path`] refer to the scaled
    /// problem; [`Lars::coef_path`] is always on the original scale.
    pub fn normalize(mut self, yes: bool) -> Self {
        self.normalize = yes;
        self
    }

    /// Stop after `steps` steps (a step moves from one knot to the next; the path then has at
    /// most `steps + 1` knots). Default: no limit.
    pub fn max_steps(mut self, steps: usize) -> Self {
        self.max_steps = Some(steps);
        self
    }

    /// Stop when alpha (the largest absolute residual correlation divided by the number of
    /// rows, scikit-learn's convention) reaches `alpha_min`; the last knot is interpolated
    /// to exactly `alpha_min`. Default `0` (no stop). Must be finite and non-negative.
    pub fn alpha_min(mut self, alpha: f64) -> Self {
        self.alpha_min = alpha;
        self
    }

    /// Variables whose absolute correlation is within `tol * C` of the maximum `C` enter
    /// together at the same knot (R `lars`'s rule). Default `1e-12`, in `[0, 1e-3]`.
    pub fn tie_tolerance(mut self, tol: f64) -> Self {
        self.tie_tolerance = tol;
        self
    }

    /// A column whose part orthogonal to the active columns has squared norm at most
    /// `tol * ||x_j||^2` is collinear and excluded for good. Default `1e-12` (the angle to
    /// the active span below about 1e-6 rad), in `[0, 1e-2]`.
    pub fn collinearity_tolerance(mut self, tol: f64) -> Self {
        self.collinearity_tolerance = tol;
        self
    }

    /// The path stops when the largest residual correlation falls to `tol` times its
    /// starting value. Default `1e-12`, in `[0, 1e-3]`.
    pub fn vanish_tolerance(mut self, tol: f64) -> Self {
        self.vanish_tolerance = tol;
        self
    }

    /// Gram matrix policy (speed only; the path is the same up to rounding).
    pub fn gram(mut self, gram: Gram) -> Self {
        self.gram = gram;
        self
    }

    fn validate(&self) -> Result<()> {
        if !(self.alpha_min.is_finite() && self.alpha_min >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "alpha_min",
                reason: format!("must be finite and non-negative, got {}", self.alpha_min),
            });
        }
        let checks: [(&'static str, f64, f64); 3] = [
            ("tie_tolerance", self.tie_tolerance, 1e-3),
            ("collinearity_tolerance", self.collinearity_tolerance, 1e-2),
            ("vanish_tolerance", self.vanish_tolerance, 1e-3),
        ];
        for (name, v, max) in checks {
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err(Error::InvalidParameter {
                    name,
                    reason: format!("must lie in [0, {max}], got {v}"),
                });
            }
        }
        Ok(())
    }

    /// Computes the path for design `x` (n x p, one row per sample) and target `y` (length n).
    ///
    /// Errors: [`Error::Empty`] for no rows or no columns, [`Error::DimensionMismatch`] if
    /// `y.len() != n`, [`Error::NonFinite`] for NaN or infinite input, for a target whose sum
    /// or (centred) squared norm overflows `f64` (`row` is where the running sum overflows;
    /// values beyond about 1e154 in magnitude), and for a path whose alphas, coefficients or
    /// intercepts overflow; [`Error::Overflow`] for a design column whose squared norm, mean
    /// or centred norm overflows;
    /// [`Error::AllColumnsConstant`] when no column can enter, [`Error::InvalidParameter`]
    /// for a bad setting.
    pub fn fit(&self, x: &DMatrix<f64>, y: &[f64]) -> Result<Lars> {
        self.validate()?;
        let (n, p) = x.shape();
        if n == 0 {
            return Err(Error::Empty {
                what: "design rows",
            });
        }
        if p == 0 {
            return Err(Error::Empty {
                what: "design columns",
            });
        }
        if y.len() != n {
            return Err(Error::DimensionMismatch {
                what: "target length vs design rows",
                expected: n,
                got: y.len(),
            });
        }
        // one pass per column: a NaN or infinity makes the squared norm non-finite, and only
        // then is the offending entry located
        let mut raw_norms = Vec::with_capacity(p);
        for j in 0..p {
            let col = x.column(j);
            let sq = dot(col.as_slice(), col.as_slice());
            if !sq.is_finite() {
                if let Some(row) = col.iter().position(|v| !v.is_finite()) {
                    return Err(Error::NonFinite {
                        what: "design",
                        row,
                        col: j,
                    });
                }
                return Err(Error::Overflow { col: j });
            }
            raw_norms.push(sq.sqrt());
        }
        if let Some(row) = y.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "target",
                row,
                col: 0,
            });
        }

        // --- standardise ------------------------------------------------------------------
        let nf = n as f64;
        let mut x_mean = vec![0.0; p];
        let mut x_scale = vec![1.0; p];
        // without centring or scaling the design is used as given (no copy)
        let mut owned = (self.fit_intercept || self.normalize).then(|| x.clone());
        let mut excluded = Vec::new();
        for j in 0..p {
            let raw_norm = raw_norms[j];
            let mut norm = raw_norm;
            if let Some(xs) = owned.as_mut() {
                if self.fit_intercept {
                    x_mean[j] = x.column(j).sum() / nf;
                    let m = x_mean[j];
                    xs.column_mut(j).iter_mut().for_each(|v| *v -= m);
                }
                norm = xs.column(j).norm();
                if !(x_mean[j].is_finite() && norm.is_finite()) {
                    return Err(Error::Overflow { col: j });
                }
            }
            // a constant column leaves only rounding (~ n eps |x|) after centring
            if raw_norm == 0.0 || norm <= 1e-10 * raw_norm {
                if let Some(xs) = owned.as_mut() {
                    xs.column_mut(j).fill(0.0);
                }
                x_scale[j] = 1.0;
                excluded.push(Exclusion {
                    feature: j,
                    reason: ExclusionReason::ZeroVariance,
                    step: 0,
                });
                continue;
            }
            if self.normalize
                && let Some(xs) = owned.as_mut()
            {
                x_scale[j] = norm;
                xs.column_mut(j).iter_mut().for_each(|v| *v /= norm);
            }
        }
        let xs: &DMatrix<f64> = owned.as_ref().unwrap_or(x);
        if excluded.len() == p {
            return Err(Error::AllColumnsConstant { columns: p });
        }
        let y_mean = if self.fit_intercept {
            y.iter().sum::<f64>() / nf
        } else {
            0.0
        };
        if !y_mean.is_finite() {
            return Err(Error::NonFinite {
                what: "target sum (it overflows f64: rescale y)",
                row: first_overflow(y.iter().copied()),
                col: 0,
            });
        }
        let ys: Vec<f64> = y.iter().map(|v| v - y_mean).collect();
        // every correlation is bounded by |x_j| |y|: a finite squared norm keeps them finite
        if !dot(&ys, &ys).is_finite() {
            return Err(Error::NonFinite {
                what: "centred target's squared norm (it overflows f64: rescale y)",
                row: first_overflow(ys.iter().map(|v| v * v)),
                col: 0,
            });
        }

        let use_gram = match self.gram {
            Gram::Auto => p <= n && p <= 4096,
            Gram::Precompute => true,
            Gram::Never => false,
        };
        let mut eligible = vec![true; p];
        for e in &excluded {
            eligible[e.feature] = false;
        }
        let mut core = Core::new(xs, use_gram);
        let mut path = core.run(self, &ys, eligible, &mut excluded);
        if matches!(
            path.stop,
            StopReason::Complete | StopReason::CorrelationVanished
        ) && let Some(last) = path.coefs.rchunks_exact_mut(p).next()
        {
            core.refine(&path.active, &path.chol, &ys, last);
        }
        excluded.sort_by_key(|e| e.feature);

        // --- back to the original scale ---------------------------------------------------
        let knots = path.alphas.len();
        // row-major knots x p (one knot after another): transposed into the column-major
        // matrices once, and checked with one linear scan each
        let std_path = DMatrix::from_row_slice(knots, p, &path.coefs);
        let coef_path = if x_scale.iter().all(|&s| s == 1.0) {
            std_path.clone()
        } else {
            let mut m = std_path.clone();
            for (j, s) in x_scale.iter().enumerate() {
                m.column_mut(j).iter_mut().for_each(|v| *v /= s);
            }
            m
        };
        let mut intercepts = vec![y_mean; knots];
        for (j, &m) in x_mean.iter().enumerate() {
            if m != 0.0 {
                for (b0, bj) in intercepts.iter_mut().zip(coef_path.column(j).iter()) {
                    *b0 -= bj * m;
                }
            }
        }
        // whatever overflowed inside the path shows in its output: an error, never inf or NaN
        let bad_coef = |m: &DMatrix<f64>| {
            m.as_slice()
                .iter()
                .position(|v| !v.is_finite())
                .map(|i| (i % knots, i / knots))
        };
        if let Some(k) = path.alphas.iter().position(|a| !a.is_finite()) {
            return Err(Error::NonFinite {
                what: "path alphas (an intermediate value overflowed: rescale X or y)",
                row: k,
                col: 0,
            });
        }
        if let Some((k, j)) = bad_coef(&std_path).or_else(|| bad_coef(&coef_path)) {
            return Err(Error::NonFinite {
                what: "path coefficients (knot, feature; an intermediate value overflowed: \
                       rescale X or y)",
                row: k,
                col: j,
            });
        }
        if let Some(k) = intercepts.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "path intercepts (an intermediate value overflowed: rescale X or y)",
                row: k,
                col: 0,
            });
        }
        Ok(Lars {
            params: self.clone(),
            n_features: p,
            alphas: path.alphas,
            std_path,
            coef_path,
            intercepts,
            events: path.events,
            active: path.active,
            excluded,
            stop: path.stop,
            x_mean,
            x_scale,
            y_mean,
        })
    }
}

/// The index at which the running sum of `values` first stops being finite (the last index if
/// it never does).
fn first_overflow(values: impl Iterator<Item = f64>) -> usize {
    let mut sum = 0.0;
    let mut last = 0;
    for (i, v) in values.enumerate() {
        sum += v;
        last = i;
        if !sum.is_finite() {
            return i;
        }
    }
    last
}

/// A fitted LARS path: every knot, the events that changed the active set, and the final
/// model on the original scale.
///
/// Knot `k` (0-based) holds `alphas()[k]` and row `k` of [`Lars::coef_path`]; knot 0 is the
/// all-zero model (the intercept alone) at the largest alpha. Between knots the coefficients
/// are linear in alpha.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Lars {
    params: LarsParams,
    n_features: usize,
    alphas: Vec<f64>,
    std_path: DMatrix<f64>,
    coef_path: DMatrix<f64>,
    intercepts: Vec<f64>,
    events: Vec<PathEvent>,
    active: Vec<usize>,
    excluded: Vec<Exclusion>,
    stop: StopReason,
    x_mean: Vec<f64>,
    x_scale: Vec<f64>,
    y_mean: f64,
}

impl Lars {
    /// A builder with the defaults of [`LarsParams`].
    pub fn params() -> LarsParams {
        LarsParams::default()
    }

    /// The parameters the path was computed with.
    pub fn parameters(&self) -> &LarsParams {
        &self.params
    }

    /// Number of columns of the design.
    pub fn n_features(&self) -> usize {
        self.n_features
    }

    /// Number of knots (at least 1).
    pub fn n_knots(&self) -> usize {
        self.alphas.len()
    }

    /// Alpha at every knot, non-increasing: `max_j |x_j^T r| / n` in the standardised
    /// problem (scikit-learn's convention), `r` the residual at that knot.
    pub fn alphas(&self) -> &[f64] {
        &self.alphas
    }

    /// Coefficients at every knot on the original scale: row `k` is knot `k`, `knots x p`.
    pub fn coef_path(&self) -> &DMatrix<f64> {
        &self.coef_path
    }

    /// Coefficients at every knot in the standardised problem (centred and/or unit-norm
    /// columns), the coordinates in which LAR moves; `knots x p`.
    pub fn standardized_coef_path(&self) -> &DMatrix<f64> {
        &self.std_path
    }

    /// The intercept at every knot (all zero without `fit_intercept`).
    pub fn intercepts(&self) -> &[f64] {
        &self.intercepts
    }

    /// Final coefficients (last knot), original scale.
    pub fn coef(&self) -> DVector<f64> {
        let last = self.alphas.len() - 1;
        self.coef_path.row(last).transpose()
    }

    /// Final intercept (last knot).
    pub fn intercept(&self) -> f64 {
        self.intercepts[self.intercepts.len() - 1]
    }

    /// Changes of the active set in order: additions and (lasso) drops.
    pub fn events(&self) -> &[PathEvent] {
        &self.events
    }

    /// The active set at the end of the path, in order of entry (scikit-learn's `active`).
    pub fn active(&self) -> &[usize] {
        &self.active
    }

    /// Columns kept out of the path (zero variance or collinear), sorted by column.
    pub fn excluded(&self) -> &[Exclusion] {
        &self.excluded
    }

    /// Why the path ended.
    pub fn stop_reason(&self) -> StopReason {
        self.stop
    }

    /// Column means subtracted before the path (zeros without an intercept).
    pub fn x_mean(&self) -> &[f64] {
        &self.x_mean
    }

    /// Column scales divided out before the path (ones without normalisation).
    pub fn x_scale(&self) -> &[f64] {
        &self.x_scale
    }

    /// Target mean subtracted before the path (zero without an intercept).
    pub fn y_mean(&self) -> f64 {
        self.y_mean
    }

    /// Prediction of the final model for one sample `row` (length p), original scale.
    pub fn predict_row(&self, row: &[f64]) -> Result<f64> {
        self.predict_row_at(self.alphas.len() - 1, row)
    }

    /// Prediction of the model at knot `knot` for one sample.
    pub fn predict_row_at(&self, knot: usize, row: &[f64]) -> Result<f64> {
        if knot >= self.alphas.len() {
            return Err(Error::InvalidParameter {
                name: "knot",
                reason: format!("path has {} knots, got {knot}", self.alphas.len()),
            });
        }
        if row.len() != self.n_features {
            return Err(Error::DimensionMismatch {
                what: "sample length vs features",
                expected: self.n_features,
                got: row.len(),
            });
        }
        if let Some(i) = row.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "sample",
                row: i,
                col: 0,
            });
        }
        let b = self.coef_path.row(knot);
        Ok(self.intercepts[knot] + b.iter().zip(row).map(|(b, x)| b * x).sum::<f64>())
    }

    /// Predictions of the final model for every row of `x` (n x p), original scale.
    pub fn predict(&self, x: &DMatrix<f64>) -> Result<DVector<f64>> {
        if x.ncols() != self.n_features {
            return Err(Error::DimensionMismatch {
                what: "design columns vs features",
                expected: self.n_features,
                got: x.ncols(),
            });
        }
        for j in 0..x.ncols() {
            if let Some(row) = x.column(j).iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "design",
                    row,
                    col: j,
                });
            }
        }
        let mut out = x * self.coef();
        out.add_scalar_mut(self.intercept());
        Ok(out)
    }
}

// ------------------------------------------------------------------------------------------
// The path itself, on the standardised problem.

struct Path {
    alphas: Vec<f64>,
    /// knot after knot, `p` coefficients each
    coefs: Vec<f64>,
    events: Vec<PathEvent>,
    active: Vec<usize>,
    stop: StopReason,
    chol: CholeskyFactor,
}

struct Core<'a> {
    xs: &'a DMatrix<f64>,
    n: usize,
    p: usize,
    /// `X^T X` (column-major p x p), when precomputed.
    gram: Option<Vec<f64>>,
    /// `||x_j||^2`.
    sq_norms: Vec<f64>,
    /// Scratch without the Gram matrix: the equiangular vector `u = X_A w` (length n), the
    /// eligible inactive columns and their `a_j`.
    u: Vec<f64>,
    inactive: Vec<usize>,
    a_inactive: Vec<f64>,
    /// With the Gram matrix: `G[gc_rows, :]` (column-major), a superset of the inactive
    /// columns' rows, and which columns it has rows for.
    gc: Vec<f64>,
    gc_rows: Vec<usize>,
    in_gc: Vec<bool>,
}

impl<'a> Core<'a> {
    fn new(xs: &'a DMatrix<f64>, use_gram: bool) -> Self {
        let (n, p) = xs.shape();
        let gram = use_gram.then(|| kernels::gram(xs.as_slice(), n, p));
        let sq_norms = match &gram {
            Some(g) => (0..p).map(|j| g[j * p + j]).collect(),
            None => (0..p)
                .map(|j| {
                    let c = &xs.as_slice()[j * n..(j + 1) * n];
                    dot(c, c)
                })
                .collect(),
        };
        Core {
            xs,
            n,
            p,
            gram,
            sq_norms,
            u: vec![0.0; if use_gram { 0 } else { n }],
            inactive: Vec::with_capacity(p),
            a_inactive: Vec::with_capacity(p),
            gc: Vec::new(),
            gc_rows: Vec::new(),
            in_gc: vec![false; p],
        }
    }

    fn col(&self, j: usize) -> &[f64] {
        &self.xs.as_slice()[j * self.n..(j + 1) * self.n]
    }

    /// `G[A, j]` in the order of `active`.
    fn gram_with_active(&self, active: &[usize], j: usize, out: &mut Vec<f64>) {
        out.clear();
        match &self.gram {
            Some(g) => out.extend(active.iter().map(|&a| g[j * self.p + a])),
            None => {
                out.resize(active.len(), 0.0);
                kernels::dots(self.xs.as_slice(), self.n, active, self.col(j), out);
            }
        }
    }

    /// `a = X^T X_A w` for the eligible inactive columns (from the Gram matrix's rows of
    /// those columns, or from `u = X_A w`), and `a_j = aa s_j` (eq. 2.6) on the active set.
    #[allow(clippy::too_many_arguments)]
    fn equiangular_correlations(
        &mut self,
        active: &[usize],
        w: &[f64],
        signs: &[f64],
        aa: f64,
        usable: impl Fn(usize) -> bool,
        a: &mut [f64],
    ) {
        self.inactive.clear();
        self.inactive.extend((0..self.p).filter(|&j| usable(j)));
        match &self.gram {
            Some(g) => {
                // rows of G for the inactive columns only (sklearn keeps them apart by
                // swapping rows of G): a compacted copy, rebuilt when a quarter of its rows
                // has become active or a dropped column needs a row it lacks
                let p = self.p;
                let stale = self.inactive.len() * 4 < self.gc_rows.len() * 3
                    || self.inactive.iter().any(|&j| !self.in_gc[j]);
                if stale {
                    self.gc_rows.clone_from(&self.inactive);
                    self.in_gc.iter_mut().for_each(|v| *v = false);
                    for &j in &self.gc_rows {
                        self.in_gc[j] = true;
                    }
                    let m = self.gc_rows.len();
                    self.gc.resize(m * p, 0.0);
                    for (k, gk) in self.gc.chunks_exact_mut(m.max(1)).enumerate().take(p) {
                        let src = &g[k * p..(k + 1) * p];
                        for (dst, &j) in gk.iter_mut().zip(&self.gc_rows) {
                            *dst = src[j];
                        }
                    }
                }
                let m = self.gc_rows.len();
                self.a_inactive.resize(m, 0.0);
                if m > 0 {
                    kernels::combine(&self.gc, m, active, w, &mut self.a_inactive);
                }
                a.fill(0.0);
                for (&j, &v) in self.gc_rows.iter().zip(&self.a_inactive) {
                    a[j] = v;
                }
            }
            None => {
                let data = self.xs.as_slice();
                kernels::combine(data, self.n, active, w, &mut self.u);
                self.a_inactive.resize(self.inactive.len(), 0.0);
                kernels::dots(data, self.n, &self.inactive, &self.u, &mut self.a_inactive);
                a.fill(0.0);
                for (&j, &v) in self.inactive.iter().zip(&self.a_inactive) {
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
    /// accuracy of a least-squares solve (cond(X) * eps for a small residual).
    fn refine(&self, active: &[usize], chol: &CholeskyFactor, ys: &[f64], beta: &mut [f64]) {
        if active.is_empty() || chol.len() != active.len() {
            return;
        }
        let data = self.xs.as_slice();
        let mut delta = vec![0.0; active.len()];
        let mut b = vec![0.0; active.len()];
        for _ in 0..2 {
            for (bk, &k) in b.iter_mut().zip(active) {
                *bk = beta[k];
            }
            kernels::residual_dots(data, self.n, active, &b, ys, &mut delta);
            chol.solve_in_place(&mut delta);
            if delta.iter().any(|d| !d.is_finite()) {
                return;
            }
            for (&k, d) in active.iter().zip(&delta) {
                beta[k] += d;
            }
        }
    }

    fn run(
        &mut self,
        params: &LarsParams,
        ys: &[f64],
        mut eligible: Vec<bool>,
        excluded: &mut Vec<Exclusion>,
    ) -> Path {
        let p = self.p;
        let nf = self.n as f64;
        let mut c = vec![0.0; p];
        {
            let cols: Vec<usize> = (0..p).filter(|&j| eligible[j]).collect();
            let mut cc = vec![0.0; cols.len()];
            kernels::dots(self.xs.as_slice(), self.n, &cols, ys, &mut cc);
            for (&j, v) in cols.iter().zip(cc) {
                c[j] = v;
            }
        }
        let c0 = (0..p)
            .filter(|&j| eligible[j])
            .map(|j| c[j].abs())
            .fold(0.0, f64::max);

        let mut beta = vec![0.0; p];
        let mut alphas = vec![c0 / nf];
        let mut coefs = beta.clone();
        let mut events = Vec::new();
        let mut active: Vec<usize> = Vec::new();
        let mut signs: Vec<f64> = Vec::new();
        let mut is_active = vec![false; p];
        let mut chol = CholeskyFactor::default();
        // z = L^{-1} s, extended on each entry, recomputed after drops (the downdate changes L)
        let mut z: Vec<f64> = Vec::new();
        let mut z_stale = false;
        let mut just_dropped: Vec<usize> = Vec::new();
        let mut big_c = c0;
        let mut step = 0usize;
        let mut scratch = Vec::new();
        let mut a = vec![0.0; p];

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
            let mut candidates: Vec<usize> = (0..p)
                .filter(|&j| {
                    eligible[j]
                        && !is_active[j]
                        && !just_dropped.contains(&j)
                        && c[j].abs() >= threshold
                })
                .collect();
            candidates.sort_by(|&i, &j| c[j].abs().total_cmp(&c[i].abs()).then(i.cmp(&j)));
            if z_stale {
                z.clone_from(&signs);
                chol.forward_in_place(&mut z);
                z_stale = false;
            }
            for j in candidates {
                self.gram_with_active(&active, j, &mut scratch);
                match chol.append(&scratch, self.sq_norms[j], params.collinearity_tolerance) {
                    Append::Appended => {
                        active.push(j);
                        let sj = if c[j] >= 0.0 { 1.0 } else { -1.0 };
                        signs.push(sj);
                        // the factor grew by one row: z = L^{-1} s grows by one entry, the
                        // same value a full forward solve would give
                        chol.forward_extend(&mut z, sj);
                        is_active[j] = true;
                        events.push(PathEvent::Added { feature: j, step });
                    }
                    Append::Collinear => {
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
            let mut w = z.clone();
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
            self.equiangular_correlations(
                &active,
                &w,
                &signs,
                aa,
                |j| eligible[j] && !is_active[j],
                &mut a,
            );

            // --- step length --------------------------------------------------------------
            let gamma_hat = big_c / aa;
            let mut gamma = gamma_hat;
            let mut any_inactive = false;
            for j in 0..p {
                if !eligible[j] || is_active[j] {
                    continue;
                }
                any_inactive = true;
                let dropped_now = just_dropped.contains(&j);
                for side in [1.0, -1.0] {
                    // a just-dropped variable sits exactly at |c_j| = C on its own side
                    if dropped_now && side * c[j] > 0.0 {
                        continue;
                    }
                    let num = big_c - side * c[j];
                    let den = aa - side * a[j];
                    if num > 0.0 && den > 0.0 {
                        let g = num / den;
                        if g < gamma {
                            gamma = g;
                        }
                    }
                }
            }
            // lasso: the first active coefficient to reach zero
            let mut drops: Vec<usize> = Vec::new(); // positions in `active`
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
                is_active[j] = false;
                beta[j] = 0.0;
                just_dropped.push(j);
                events.push(PathEvent::Dropped { feature: j, step });
            }

            let alpha = big_c / nf;
            let prev_alpha = alphas[alphas.len() - 1];
            if params.alpha_min > 0.0 && alpha <= params.alpha_min {
                let prev = &coefs[coefs.len() - p..];
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
                coefs.extend_from_slice(&knot);
                return finish(alphas, coefs, events, active, StopReason::AlphaMin, chol);
            }
            alphas.push(alpha);
            coefs.extend_from_slice(&beta);
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
