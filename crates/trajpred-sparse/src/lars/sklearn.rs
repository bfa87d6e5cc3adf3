//! A scikit-learn-style entry point: [`lars_path`], with `sklearn.linear_model.lars_path`'s
//! defaults and output layout.

use super::{Gram, Lars, Method};
use crate::error::Result;
use nalgebra::DMatrix;

/// Options of [`lars_path`], with scikit-learn's defaults: `max_iter = 500`, `alpha_min = 0`.
///
/// ```
/// use trajpred_sparse::{Gram, LarsPathOptions};
/// let opts = LarsPathOptions::default().max_iter(20).alpha_min(0.1).gram(Gram::Never);
/// assert_eq!(opts.get_max_iter(), 20);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LarsPathOptions {
    max_iter: usize,
    alpha_min: f64,
    gram: Gram,
}

impl Default for LarsPathOptions {
    fn default() -> Self {
        LarsPathOptions {
            max_iter: 500,
            alpha_min: 0.0,
            gram: Gram::Auto,
        }
    }
}

impl LarsPathOptions {
    setters! {
        /// At most `max_iter` steps, so at most `max_iter + 1` alphas (scikit-learn's
        /// `max_iter`, default 500). `usize::MAX` means no limit.
        max_iter(max_iter: usize) => self.max_iter = max_iter;
        /// Stop at this alpha; the last knot is interpolated to exactly `alpha_min`
        /// (scikit-learn's `alpha_min`, default 0). Must be finite and non-negative.
        alpha_min(alpha_min: f64) => self.alpha_min = alpha_min;
        /// Whether to precompute `X^T X` (speed only). scikit-learn's `Gram=None` computes
        /// without it and `Gram='auto'` with it when `n_samples > n_features`; the default here
        /// is [`Gram::Auto`] (with it when `p <= n`), the faster choice, which gives the same
        /// path up to rounding.
        gram(gram: Gram) => self.gram = gram;
    }

    /// The step limit.
    pub fn get_max_iter(&self) -> usize {
        self.max_iter
    }

    /// The alpha at which the path stops.
    pub fn get_alpha_min(&self) -> f64 {
        self.alpha_min
    }

    /// The Gram matrix policy.
    pub fn get_gram(&self) -> Gram {
        self.gram
    }
}

/// What `sklearn.linear_model.lars_path` returns, in its layout, plus the full fit.
#[derive(Debug, Clone, PartialEq)]
pub struct LarsPath {
    /// Alpha at every knot, non-increasing, `max_j |x_j^T r| / n` (length `n_alphas`).
    pub alphas: Vec<f64>,
    /// The active set at the end of the path, in order of entry.
    pub active: Vec<usize>,
    /// Coefficients, `n_features x n_alphas`: column `k` is the model at `alphas[k]`
    /// (scikit-learn's `coefs`; [`Lars::coef_path`] holds the transpose).
    pub coefs: DMatrix<f64>,
    /// Number of steps taken (`n_alphas - 1`, scikit-learn's `n_iter`).
    pub n_iter: usize,
    /// The fit itself: events (additions, drops), excluded columns, why the path stopped.
    pub fit: Lars,
}

/// The LAR or lasso path of `y` on `x` (n x p, one row per sample), as
/// `sklearn.linear_model.lars_path(X, y, method=..., max_iter=..., alpha_min=...)` computes
/// it: on the data as given, with no intercept and no scaling of the columns (unlike
/// [`Lars::params`], whose defaults centre and normalise), and with the coefficients laid out
/// `n_features x n_alphas`.
///
/// Where the result can differ from scikit-learn's (each documented in `docs/sparse.md`):
/// variables that tie for the largest correlation enter at the same knot (scikit-learn adds
/// one per step and records a zero-length step); an active variable's LAR sign never flips
/// (scikit-learn's `'lar'` flips it when a coefficient crosses zero, which leaves the LAR
/// path); a column in the span of the active ones is excluded for good with a scale-free
/// test; and for `p >= n` the path stops when the residual correlation vanishes (after
/// `rank(X)` steps) where scikit-learn goes on until `max_iter`.
///
/// Errors: those of [`LarsParams::fit`](super::LarsParams::fit); an invalid `alpha_min` is
/// [`trajpred_core::Error::InvalidParameter`].
///
/// ```
/// use nalgebra::DMatrix;
/// use trajpred_sparse::{lars_path, LarsPathOptions, Method};
///
/// // y = 3 x0 - 2 x2 exactly, on four columns
/// let x = DMatrix::from_fn(20, 4, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0 + 0.1 * (i * j) as f64);
/// let y: Vec<f64> = (0..20).map(|i| 3.0 * x[(i, 0)] - 2.0 * x[(i, 2)]).collect();
///
/// let path = lars_path(&x, &y, Method::Lasso, &LarsPathOptions::default())?;
/// assert_eq!(path.coefs.shape(), (4, path.alphas.len())); // n_features x n_alphas
/// let last = path.coefs.column(path.alphas.len() - 1);
/// assert!((last[0] - 3.0).abs() < 1e-9 && (last[2] + 2.0).abs() < 1e-9);
/// assert!(path.alphas.windows(2).all(|w| w[1] <= w[0]));
/// # Ok::<(), trajpred_sparse::Error>(())
/// ```
pub fn lars_path(
    x: &DMatrix<f64>,
    y: &[f64],
    method: Method,
    options: &LarsPathOptions,
) -> Result<LarsPath> {
    let mut params = Lars::params()
        .method(method)
        .fit_intercept(false)
        .normalize(false)
        .alpha_min(options.alpha_min)
        .gram(options.gram);
    if options.max_iter != usize::MAX {
        params = params.max_steps(options.max_iter);
    }
    let fit = params.fit(x, y)?;
    Ok(LarsPath {
        alphas: fit.alphas().to_vec(),
        active: fit.active().to_vec(),
        coefs: fit.coef_path().transpose(),
        n_iter: fit.n_knots() - 1,
        fit,
    })
}
