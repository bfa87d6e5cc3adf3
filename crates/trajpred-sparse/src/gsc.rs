//! Group sparse coding (`docs/papers.md` A.3, eq. 4 and 14-16 of the GSKF paper): one LARS model
//! per horizon `t = 1..T` on the Hankel design of a series, stacked into the coefficient matrix
//! `A` (T x m) and the intercepts `b`, so that the multi-step prediction from a window `w` is
//! `X_hat = A w + b` (eq. 19 with intercepts).

use crate::error::{Error, Result};
use crate::lars::{Lars, LarsParams};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use trajpred_core::Error as CoreError;
use trajpred_core::window::{HankelDesign, design_rows, hankel_design};

/// Below this many design entries (rows x m x T) the horizons are fitted one after another:
/// spawning rayon tasks costs more than it saves.
const PARALLEL_MIN_WORK: usize = 50_000;

/// Builder of a [`GroupSparseCoder`].
///
/// ```
/// use trajpred_sparse::GroupSparseCoder;
/// // x_k = sin(0.3 k): an exact order-2 recurrence, so every horizon is predicted exactly
/// let series: Vec<f64> = (0..200).map(|k| (0.3 * k as f64).sin()).collect();
/// let gsc = GroupSparseCoder::params(4, 3).fit(&series[..150])?;
/// assert_eq!(gsc.coefficients().shape(), (3, 4)); // A is T x m
/// let pred = gsc.predict(&series[146..150])?;
/// for (t, p) in pred.iter().enumerate() {
///     assert!((p - series[150 + t]).abs() < 1e-8);
/// }
/// # Ok::<(), trajpred_sparse::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GscParams {
    window: usize,
    horizons: usize,
    lars: LarsParams,
    parallel: bool,
    #[serde(default)]
    relative: bool,
}

impl GscParams {
    setters! {
        /// The LARS settings of every horizon's fit (default: [`Lars::params`], the full LAR
        /// path with intercept and unit-norm columns, whose end is least squares).
        lars(lars: LarsParams) => self.lars = lars;
        /// Fit the horizons in parallel with rayon when the problem is large enough to pay
        /// (default `true`); `false` always fits them one after another.
        parallel(yes: bool) => self.parallel = yes;
        /// Work in the frame of each window's last value (default `false`: the paper's
        /// absolute values): every design row and its target have the row's last value
        /// subtracted, and a prediction adds the window's last value back, so that
        /// `predict(w + c) = predict(w) + c` for any shift `c`. In absolute values that holds
        /// only when every row of `A` sums to 1, which a LAR path stopped early does not
        /// give: series far from the training ones' level are then forecast with a bias
        /// (see `docs/gskf.md`). The last column of `A` stays 0 in this frame.
        relative(yes: bool) => self.relative = yes;
    }

    /// Fits the `T` horizon models on `series` (oldest first).
    ///
    /// Horizon `t` uses the windows `(x_j, ..., x_{j+m-1})` whose target `x_{j+m-1+t}` lies in
    /// the series, `p_t = h - t - m + 1` rows. Needs `h >= m + T + 1` (two rows for the
    /// longest horizon). A constant series (every window column constant) gives `A = 0` and
    /// `b` = the mean target, instead of an error.
    ///
    /// Errors (the shared ones as [`Error::Core`]): [`CoreError::InvalidParameter`] for
    /// `m = 0` or `T = 0`, [`CoreError::TooShort`], [`Error::NonFiniteEntry`] for a NaN or
    /// infinite value, and the errors of [`LarsParams::fit`].
    pub fn fit(&self, series: &[f64]) -> Result<GroupSparseCoder> {
        self.fit_many(&[series])
    }

    /// Fits the `T` horizon models on several series at once (e.g. many trajectories of one
    /// axis): the Hankel designs of the series are stacked, so no window straddles two series.
    /// Series too short for any window of a horizon contribute no rows to it. Needs at least
    /// one series of `m + T + 1` values.
    ///
    /// ```
    /// use trajpred_sparse::GroupSparseCoder;
    /// let a: Vec<f64> = (0..40).map(|k| (0.3 * k as f64).sin()).collect();
    /// let b: Vec<f64> = (0..40).map(|k| 2.0 * (0.3 * k as f64 + 1.0).sin()).collect();
    /// let gsc = GroupSparseCoder::params(3, 2).fit_many(&[&a, &b])?;
    /// let p = gsc.predict(&b[10..13])?;
    /// assert!((p[1] - b[14]).abs() < 1e-8); // both obey the same recurrence
    /// # Ok::<(), trajpred_sparse::Error>(())
    /// ```
    ///
    /// Errors: as [`GscParams::fit`]; `TooShort` names the longest series when none is long
    /// enough, `NonFiniteEntry` gives the point as `row` and the series index as `col`.
    pub fn fit_many(&self, series: &[&[f64]]) -> Result<GroupSparseCoder> {
        let (m, horizons) = (self.window, self.horizons);
        if m == 0 {
            return Err(CoreError::InvalidParameter {
                name: "window",
                reason: format!("window length m must be at least 1, got {m}"),
            }
            .into());
        }
        if horizons == 0 {
            return Err(CoreError::InvalidParameter {
                name: "horizons",
                reason: format!("number of horizons T must be at least 1, got {horizons}"),
            }
            .into());
        }
        let needed = m + horizons + 1;
        let longest = series.iter().map(|s| s.len()).max().unwrap_or(0);
        if longest < needed {
            return Err(CoreError::TooShort {
                what: "series for group sparse coding",
                needed,
                got: longest,
            }
            .into());
        }
        for (col, s) in series.iter().enumerate() {
            if let Some(row) = s.iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFiniteEntry {
                    what: "series",
                    row,
                    col,
                });
            }
        }
        let work = series.iter().map(|s| s.len()).sum::<usize>() * m * horizons;
        let fit_one = |t: usize| self.fit_horizon(series, t);
        let models: Vec<HorizonModel> =
            if self.parallel && horizons > 1 && work >= PARALLEL_MIN_WORK {
                (1..=horizons)
                    .into_par_iter()
                    .map(fit_one)
                    .collect::<Result<_>>()?
            } else {
                (1..=horizons).map(fit_one).collect::<Result<_>>()?
            };
        let a = DMatrix::from_fn(horizons, m, |t, k| models[t].coef[k]);
        let b = DVector::from_fn(horizons, |t, _| models[t].intercept);
        let residual_variances = models.iter().map(|h| h.residual_variance).collect();
        let paths = models.into_iter().map(|h| h.path).collect();
        Ok(GroupSparseCoder {
            params: self.clone(),
            a,
            b,
            residual_variances,
            paths,
        })
    }

    fn fit_horizon(&self, series: &[&[f64]], t: usize) -> Result<HorizonModel> {
        let mut blocks = Vec::new();
        for s in series {
            if design_rows(s.len(), self.window, t).is_some() {
                blocks.push(hankel_design(s, self.window, t)?);
            }
        }
        let d = if blocks.len() == 1 {
            blocks.pop().ok_or(Error::Core(CoreError::TooShort {
                what: "series for group sparse coding",
                needed: self.window + t,
                got: 0,
            }))?
        } else {
            let rows: usize = blocks.iter().map(|b| b.target.len()).sum();
            let mut design = DMatrix::zeros(rows, self.window);
            let mut target = DVector::zeros(rows);
            let mut r = 0;
            for b in &blocks {
                let n = b.target.len();
                design.rows_mut(r, n).copy_from(&b.design);
                target.rows_mut(r, n).copy_from(&b.target);
                r += n;
            }
            HankelDesign { design, target }
        };
        let mut d = d;
        if self.relative {
            let m = self.window;
            for r in 0..d.target.len() {
                let last = d.design[(r, m - 1)];
                for k in 0..m {
                    d.design[(r, k)] -= last;
                }
                d.target[r] -= last;
            }
        }
        let y = d.target.as_slice();
        let rows = y.len() as f64;
        let (coef, intercept, path) = match self.lars.fit(&d.design, y) {
            Ok(fit) => (fit.coef(), fit.intercept(), Some(fit)),
            Err(Error::AllColumnsConstant { .. }) => {
                let mean = y.iter().sum::<f64>() / rows;
                (DVector::zeros(self.window), mean, None)
            }
            Err(e) => return Err(e),
        };
        let fitted = &d.design * &coef;
        let residual_variance = y
            .iter()
            .zip(fitted.iter())
            .map(|(yi, fi)| {
                let e = yi - fi - intercept;
                e * e
            })
            .sum::<f64>()
            / rows;
        Ok(HorizonModel {
            coef: coef.iter().copied().collect(),
            intercept,
            residual_variance,
            path,
        })
    }
}

struct HorizonModel {
    coef: Vec<f64>,
    intercept: f64,
    residual_variance: f64,
    path: Option<Lars>,
}

/// The fitted group sparse coder: `A` (T x m), `b` (T) and the per-horizon LARS paths.
///
/// Row `t - 1` of `A` and entry `t - 1` of `b` predict `x_{i+t}` from the window
/// `w_i = (x_{i-m+1}, ..., x_i)` (oldest first): `x_hat_{i+t} = A[t-1, :] . w_i + b[t-1]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupSparseCoder {
    params: GscParams,
    a: DMatrix<f64>,
    b: DVector<f64>,
    residual_variances: Vec<f64>,
    paths: Vec<Option<Lars>>,
}

impl GroupSparseCoder {
    /// A builder for window length `m` and `horizons` = T steps ahead (T may exceed m).
    pub fn params(m: usize, horizons: usize) -> GscParams {
        GscParams {
            window: m,
            horizons,
            lars: Lars::params(),
            parallel: true,
            relative: false,
        }
    }

    /// A coder from its fitted parts, as [`coefficients`](Self::coefficients),
    /// [`intercepts`](Self::intercepts) and [`residual_variances`](Self::residual_variances)
    /// return them (e.g. read back from a saved parameter file): `a` is T x m, `b` and the
    /// residual variances have length T. It predicts exactly as the coder they came from;
    /// it has no LARS paths ([`path`](Self::path) is `None`).
    ///
    /// Errors (the shared ones as [`Error::Core`]): [`CoreError::InvalidParameter`] for m = 0
    /// or T = 0, [`CoreError::DimensionMismatch`] for inconsistent shapes,
    /// [`Error::NonFiniteEntry`] for a NaN or infinite coefficient, [`CoreError::NonFinite`]
    /// for one in the intercepts or residual variances (and a negative residual variance is
    /// an `InvalidParameter`).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use trajpred_sparse::GroupSparseCoder;
    /// let series: Vec<f64> = (0..60).map(|k| (0.3 * k as f64).sin()).collect();
    /// let gsc = GroupSparseCoder::params(4, 2).fit(&series)?;
    /// let back = GroupSparseCoder::from_parts(
    ///     gsc.coefficients().clone(),
    ///     gsc.intercepts().clone(),
    ///     gsc.residual_variances().to_vec(),
    /// )?;
    /// assert_eq!(back.predict(&series[10..14])?, gsc.predict(&series[10..14])?);
    /// # Ok::<(), trajpred_sparse::Error>(())
    /// ```
    pub fn from_parts(
        a: DMatrix<f64>,
        b: DVector<f64>,
        residual_variances: Vec<f64>,
    ) -> Result<Self> {
        let (horizons, m) = a.shape();
        if m == 0 || horizons == 0 {
            return Err(CoreError::InvalidParameter {
                name: "coefficients",
                reason: format!("A must be at least 1 x 1, got {horizons} x {m}"),
            }
            .into());
        }
        for (what, len) in [
            ("intercepts vs rows of A", b.len()),
            ("residual variances vs rows of A", residual_variances.len()),
        ] {
            if len != horizons {
                return Err(CoreError::DimensionMismatch {
                    what,
                    expected: horizons,
                    got: len,
                }
                .into());
            }
        }
        if let Some(k) = a.iter().position(|v| !v.is_finite()) {
            // column-major storage: entry k is (k % T, k / T)
            return Err(Error::NonFiniteEntry {
                what: "coefficients",
                row: k % horizons,
                col: k / horizons,
            });
        }
        for (what, v) in [
            ("intercepts", b.as_slice()),
            ("residual variances", &residual_variances),
        ] {
            if let Some(row) = v.iter().position(|v| !v.is_finite()) {
                return Err(CoreError::NonFinite { what, index: row }.into());
            }
        }
        if let Some(row) = residual_variances.iter().position(|v| *v < 0.0) {
            return Err(CoreError::InvalidParameter {
                name: "residual_variances",
                reason: format!("entry {row} is negative: {}", residual_variances[row]),
            }
            .into());
        }
        Ok(GroupSparseCoder {
            params: GroupSparseCoder::params(m, horizons),
            a,
            b,
            residual_variances,
            paths: vec![None; horizons],
        })
    }

    /// Whether the coder works in the frame of each window's last value
    /// ([`GscParams::relative`]).
    pub fn is_relative(&self) -> bool {
        self.params.relative
    }

    /// The same coefficients read in the frame of each window's last value (`true`) or in
    /// absolute values: for a coder rebuilt with [`from_parts`](Self::from_parts) from one
    /// fitted with [`GscParams::relative`].
    pub fn in_relative_frame(mut self, yes: bool) -> Self {
        self.params.relative = yes;
        self
    }

    /// Window length m.
    pub fn window(&self) -> usize {
        self.params.window
    }

    /// Number of horizons T.
    pub fn horizons(&self) -> usize {
        self.params.horizons
    }

    /// The coefficient matrix `A` (T x m): row `t - 1` is the horizon-`t` model, column `k`
    /// multiplies the `k`-th oldest value of the window.
    pub fn coefficients(&self) -> &DMatrix<f64> {
        &self.a
    }

    /// The intercepts `b` (length T).
    pub fn intercepts(&self) -> &DVector<f64> {
        &self.b
    }

    /// Per horizon, the mean squared training residual `sum_j e_j^2 / p_t` of that horizon's
    /// model on its own design (the default diagonal of R in the GSKF).
    pub fn residual_variances(&self) -> &[f64] {
        &self.residual_variances
    }

    /// The LARS path of horizon `t` (1-based), or `None` for a constant series (no path was
    /// needed) or `t` out of range.
    pub fn path(&self, t: usize) -> Option<&Lars> {
        t.checked_sub(1)
            .and_then(|i| self.paths.get(i))
            .and_then(Option::as_ref)
    }

    /// The T-step prediction `A w + b` from a window of the m most recent values, oldest
    /// first.
    pub fn predict(&self, window: &[f64]) -> Result<Vec<f64>> {
        let m = self.window();
        if window.len() != m {
            return Err(CoreError::DimensionMismatch {
                what: "window length vs m",
                expected: m,
                got: window.len(),
            }
            .into());
        }
        if let Some(row) = window.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite {
                what: "window",
                index: row,
            }
            .into());
        }
        let origin = if self.params.relative {
            window[m - 1]
        } else {
            0.0
        };
        Ok((0..self.horizons())
            .map(|t| {
                origin
                    + self.b[t]
                    + self
                        .a
                        .row(t)
                        .iter()
                        .zip(window)
                        .map(|(a, w)| a * (w - origin))
                        .sum::<f64>()
            })
            .collect())
    }

    /// The T-step prediction from the last m values of `history`.
    pub fn predict_next(&self, history: &[f64]) -> Result<Vec<f64>> {
        let m = self.window();
        if history.len() < m {
            return Err(CoreError::TooShort {
                what: "history",
                needed: m,
                got: history.len(),
            }
            .into());
        }
        self.predict(&history[history.len() - m..])
    }
}
