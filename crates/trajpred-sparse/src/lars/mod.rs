//! Least angle regression: the LAR path and its lasso modification (Efron, Hastie,
//! Johnstone, Tibshirani 2004), with a validating builder ([`LarsParams`]) and the whole
//! fitted path ([`Lars`]), and a scikit-learn-style entry point ([`lars_path`]).
//!
//! Files: this one holds the options and the preprocessing (validation, centring, scaling,
//! the return to the original scale); `path.rs` the steps themselves; `fitted.rs` the fitted
//! path; `sklearn.rs` [`lars_path`].

mod fitted;
mod knots;
mod path;
mod screen;
mod sklearn;

pub use fitted::Lars;
pub use sklearn::{LarsPath, LarsPathOptions, lars_path};

use crate::error::{Error, Result};
use crate::kernels::dot;
use nalgebra::DMatrix;
use path::Core;
use serde::{Deserialize, Serialize};
use trajpred_core::Error as CoreError;

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
/// use trajpred_core::Error as CoreError;
/// let x = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 2.0, 1.0, 3.0, 0.0, 4.0, 2.0]);
/// let y = [1.0, 3.0, 3.0, 6.0];
/// let fit = Lars::params().method(Method::Lasso).fit(&x, &y)?;
/// // the full path ends at least squares: y = 0 + 1 * x1 + 1 * x2 fits exactly
/// assert!((fit.predict_row(&[5.0, 1.0])? - 6.0).abs() < 1e-9);
/// // bad parameters are typed errors
/// assert!(matches!(
///     Lars::params().alpha_min(-1.0).fit(&x, &y),
///     Err(Error::Core(CoreError::InvalidParameter { name: "alpha_min", .. }))
/// ));
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
    #[serde(default = "screen_default")]
    screen: bool,
}

fn screen_default() -> bool {
    true
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
            screen: true,
        }
    }
}

impl LarsParams {
    setters! {
        /// LAR or lasso.
        method(method: Method) => self.method = method;
        /// Fit an intercept (centre the columns and the target). Default `true`.
        fit_intercept(yes: bool) => self.fit_intercept = yes;
        /// Scale every (centred, if `fit_intercept`) column to unit L2 norm before the path.
        /// Default `true`. Alphas and [`Lars::standardized_coef_path`] refer to the scaled
        /// problem; [`Lars::coef_path`] is always on the original scale.
        normalize(yes: bool) => self.normalize = yes;
        /// Stop after `steps` steps (a step moves from one knot to the next; the path then has at
        /// most `steps + 1` knots). Default: no limit.
        max_steps(steps: usize) => self.max_steps = Some(steps);
        /// Stop when alpha (the largest absolute residual correlation divided by the number of
        /// rows, scikit-learn's convention) reaches `alpha_min`; the last knot is interpolated
        /// to exactly `alpha_min`. Default `0` (no stop). Must be finite and non-negative.
        alpha_min(alpha: f64) => self.alpha_min = alpha;
        /// Variables whose absolute correlation is within `tol * C` of the maximum `C` enter
        /// together at the same knot (R `lars`'s rule). Default `1e-12`, in `[0, 1e-3]`.
        tie_tolerance(tol: f64) => self.tie_tolerance = tol;
        /// A column whose part orthogonal to the active columns has squared norm at most
        /// `tol * ||x_j||^2` is collinear and excluded for good. Default `1e-12` (the angle to
        /// the active span below about 1e-6 rad), in `[0, 1e-2]`.
        collinearity_tolerance(tol: f64) => self.collinearity_tolerance = tol;
        /// The path stops when the largest residual correlation falls to `tol` times its
        /// starting value. Default `1e-12`, in `[0, 1e-3]`.
        vanish_tolerance(tol: f64) => self.vanish_tolerance = tol;
        /// Gram matrix policy (speed only; the path is the same up to rounding).
        gram(gram: Gram) => self.gram = gram;
        /// On a wide LAR path without the Gram matrix (`p > n`), read a single-precision copy
        /// of `X` in each step's pass and take again in double precision only the columns
        /// whose step length its error bounds cannot rule out (speed only: the same
        /// variables enter at the same steps, and the path agrees to rounding). Default
        /// `true`.
        screen(yes: bool) => self.screen = yes;
    }

    fn validate(&self) -> Result<()> {
        if !(self.alpha_min.is_finite() && self.alpha_min >= 0.0) {
            return Err(CoreError::InvalidParameter {
                name: "alpha_min",
                reason: format!("must be finite and non-negative, got {}", self.alpha_min),
            }
            .into());
        }
        let checks: [(&'static str, f64, f64); 3] = [
            ("tie_tolerance", self.tie_tolerance, 1e-3),
            ("collinearity_tolerance", self.collinearity_tolerance, 1e-2),
            ("vanish_tolerance", self.vanish_tolerance, 1e-3),
        ];
        for (name, v, max) in checks {
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err(CoreError::InvalidParameter {
                    name,
                    reason: format!("must lie in [0, {max}], got {v}"),
                }
                .into());
            }
        }
        Ok(())
    }

    /// Computes the path for design `x` (n x p, one row per sample) and target `y` (length n).
    ///
    /// Errors (the shared ones as [`Error::Core`]): [`CoreError::Empty`] for no rows or no
    /// columns, [`CoreError::DimensionMismatch`] if `y.len() != n`,
    /// [`Error::NonFiniteEntry`] for a NaN or infinite design entry (and for path
    /// coefficients that overflow: row = knot, column = feature), [`CoreError::NonFinite`] for
    /// a NaN or infinite target value, for a target whose sum or (centred) squared norm
    /// overflows `f64` (`index` is where the running sum overflows; values beyond about 1e154
    /// in magnitude), and for path alphas or intercepts that overflow (`index` is the knot);
    /// [`Error::Overflow`] for a design column whose squared norm, mean or centred norm
    /// overflows; [`Error::AllColumnsConstant`] when no column can enter,
    /// [`CoreError::InvalidParameter`] for a bad setting.
    pub fn fit(&self, x: &DMatrix<f64>, y: &[f64]) -> Result<Lars> {
        self.validate()?;
        let (n, p) = x.shape();
        if n == 0 {
            return Err(CoreError::Empty {
                what: "design rows",
            }
            .into());
        }
        if p == 0 {
            return Err(CoreError::Empty {
                what: "design columns",
            }
            .into());
        }
        if y.len() != n {
            return Err(CoreError::DimensionMismatch {
                what: "target length vs design rows",
                expected: n,
                got: y.len(),
            }
            .into());
        }
        let use_gram = match self.gram {
            Gram::Auto => p <= n && p <= 4096,
            Gram::Precompute => true,
            Gram::Never => false,
        };
        // used as given (neither centred nor scaled), the design's Gram matrix is computed
        // first: its diagonal holds the squared norms, so its pass over X is the check's
        let direct = use_gram && !self.fit_intercept && !self.normalize;
        let early = direct.then(|| Core::new(x, y, true));
        // one pass per column: a NaN or infinity makes the squared norm non-finite, and only
        // then is the offending entry located
        let mut raw_norms = Vec::with_capacity(p);
        for j in 0..p {
            let col = x.column(j);
            let sq = match &early {
                Some(core) => core.sq_norm(j),
                None => dot(col.as_slice(), col.as_slice()),
            };
            if !sq.is_finite() {
                if let Some(row) = col.iter().position(|v| !v.is_finite()) {
                    return Err(Error::NonFiniteEntry {
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
            return Err(CoreError::NonFinite {
                what: "target",
                index: row,
            }
            .into());
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
            return Err(CoreError::NonFinite {
                what: "target sum (it overflows f64: rescale y)",
                index: first_overflow(y.iter().copied()),
            }
            .into());
        }
        let ys: Vec<f64> = y.iter().map(|v| v - y_mean).collect();
        // every correlation is bounded by |x_j| |y|: a finite squared norm keeps them finite
        if !dot(&ys, &ys).is_finite() {
            return Err(CoreError::NonFinite {
                what: "centred target's squared norm (it overflows f64: rescale y)",
                index: first_overflow(ys.iter().map(|v| v * v)),
            }
            .into());
        }

        let mut eligible = vec![true; p];
        for e in &excluded {
            eligible[e.feature] = false;
        }
        // (without centring, `ys` is `y`: the early Gram matrix's `X^T y` is the one needed)
        let mut core = early.unwrap_or_else(|| Core::new(xs, &ys, use_gram));
        let mut path = core.run(self, &ys, eligible, &mut excluded);
        if matches!(
            path.stop,
            StopReason::Complete | StopReason::CorrelationVanished
        ) && let Some(k) = path.coefs.len().checked_sub(1)
        {
            let mut last = path.coefs.knot(k);
            core.refine(&path.active, &path.chol, &ys, &mut last);
            path.coefs.set_knot(k, &last);
        }
        excluded.sort_by_key(|e| e.feature);

        // --- back to the original scale ---------------------------------------------------
        let knots = path.alphas.len();
        // the knots were stored column-major (knots x p) as they came: each matrix is checked
        // with one linear scan
        let std_path = path.coefs.into_matrix();
        debug_assert_eq!(std_path.nrows(), knots);
        // without scaling the original-scale path is the same matrix: stored once
        let coef_path = if x_scale.iter().all(|&s| s == 1.0) {
            None
        } else {
            let mut m = std_path.clone();
            for (j, s) in x_scale.iter().enumerate() {
                m.column_mut(j).iter_mut().for_each(|v| *v /= s);
            }
            Some(m)
        };
        let mut intercepts = vec![y_mean; knots];
        let orig = coef_path.as_ref().unwrap_or(&std_path);
        for (j, &m) in x_mean.iter().enumerate() {
            if m != 0.0 {
                for (b0, bj) in intercepts.iter_mut().zip(orig.column(j).iter()) {
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
            return Err(CoreError::NonFinite {
                what: "path alphas (an intermediate value overflowed: rescale X or y)",
                index: k,
            }
            .into());
        }
        if let Some((k, j)) = bad_coef(&std_path).or_else(|| bad_coef(orig)) {
            return Err(Error::NonFiniteEntry {
                what: "path coefficients (knot, feature; an intermediate value overflowed: \
                       rescale X or y)",
                row: k,
                col: j,
            });
        }
        if let Some(k) = intercepts.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite {
                what: "path intercepts (an intermediate value overflowed: rescale X or y)",
                index: k,
            }
            .into());
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
