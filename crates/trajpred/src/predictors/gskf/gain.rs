//! The Kalman correction's gain fitted to the training series (the prediction-error method),
//! as an alternative to the gain of the paper's covariance recursion (issue 27, item 5).
//!
//! The IKF corrects the GSC prediction with `K V(k-1)`, where the steady-state gain
//! `K = P(k|k-1) S(k-1)^-1` follows from `F`, `Q = q I` and `R`. A steady-state Kalman
//! predictor is a fixed linear map of the most recent innovations; instead of deriving that
//! map from assumed noise covariances, it can be identified from data by minimising the
//! prediction error (the prediction-error method; for Gaussian innovations the maximum
//! likelihood estimate of the innovations model). Here the map takes the residual vectors of
//! the `lags + 1` most recent origins, `z_i = [V(i); V(i-1); ...; V(i-lags)]`, and is fitted
//! by least squares over the training origins:
//! `K = argmin sum_i |x_{i+1..i+T} - X_hat^0(i) - K z_i|^2`. With `lags = 0` it has the IKF's
//! form (one residual vector) with a free `T x T` gain; each lag reaches one point further
//! back, which noisy series need (see `docs/gskf.md`).

use super::super::fitted::{At, exact_matrix, exact_vec};
use super::{AxisFilter, gsc_at, residuals};
use nalgebra::{DMatrix, DVector};
use trajpred_core::{Error, Result};
use trajpred_sparse::GroupSparseCoder;

/// The most residual lags a fitted gain may use.
pub(super) const MAX_LAGS: usize = 64;

/// The gain fitted by least squares with one number of lags: `T x T (lags + 1)`, and the
/// per-horizon variance of the corrected training residuals (the forecast's covariance).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct LagGain {
    pub(super) k: DMatrix<f64>,
    pub(super) variances: Vec<f64>,
}

/// A fitted gain with `lags` lags, and the gains with fewer lags fitted beside it: entry `l`
/// has `l` lags. A history too short for `lags` lags is corrected with the gain of as many
/// lags as it has the points for.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct FittedGain {
    pub(super) by_lags: Vec<LagGain>,
}

impl FittedGain {
    /// The number of lags chosen.
    pub(super) fn lags(&self) -> usize {
        self.by_lags.len().saturating_sub(1)
    }
}

/// Which of a series' usable origins a fit or a score takes: all of them, the first three
/// quarters or the last quarter (a validation split in time for a single group).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Part {
    All,
    Head,
    Tail,
}

/// The origins of a series of `len` points that `part` takes, from `first` (the first origin
/// whose regressors exist) to the last whose `t` targets exist.
pub(super) fn origins(len: usize, first: usize, t: usize, part: Part) -> std::ops::Range<usize> {
    let end = len.saturating_sub(t).max(first);
    let cut = first + (end - first) * 3 / 4;
    match part {
        Part::All => first..end,
        Part::Head => first..cut,
        Part::Tail => cut..end,
    }
}

/// `z_i = [V(i); V(i-1); ...; V(i-lags)]` of origin `i` of `x`.
pub(super) fn regressors(
    gsc: &GroupSparseCoder,
    x: &[f64],
    i: usize,
    lags: usize,
) -> Result<DVector<f64>> {
    let t = gsc.horizons();
    let mut z = DVector::zeros(t * (lags + 1));
    for l in 0..=lags {
        z.rows_mut(l * t, t).copy_from(&residuals(gsc, x, i - l)?);
    }
    Ok(z)
}

/// The GSC's residuals `x_{i+1..i+T} - X_hat^0(i)` at origin `i`.
fn targets(gsc: &GroupSparseCoder, x: &[f64], i: usize) -> Result<DVector<f64>> {
    let p = gsc_at(gsc, x, i)?;
    Ok(DVector::from_iterator(
        p.len(),
        p.iter().enumerate().map(|(k, v)| x[i + 1 + k] - v),
    ))
}

/// The first origin of a series at which a gain with `lags` lags has its regressors: the
/// residual of horizon `T` at origin `i - lags` needs the GSC window ending at
/// `i - lags - T`.
pub(super) fn first_origin(gsc: &GroupSparseCoder, lags: usize) -> usize {
    gsc.window() + gsc.horizons() - 1 + lags
}

/// Fits the gains with 0 to `lags` lags ([`fit_one`]) on the origins `part` of every series
/// from `first` (or the first each number of lags can use).
pub(super) fn fit(
    gsc: &GroupSparseCoder,
    series: &[&[f64]],
    lags: usize,
    first: usize,
    part: Part,
) -> Result<FittedGain> {
    let by_lags = (0..=lags)
        .map(|l| fit_one(gsc, series, l, first, part))
        .collect::<Result<_>>()?;
    Ok(FittedGain { by_lags })
}

/// Fits the gain with `lags` lags by least squares on the origins `part` of every series
/// (`first` at least [`first_origin`]). The normal equations are solved by SVD with singular
/// values below `1e-12` of the largest dropped (the minimum-norm solution when residual
/// vectors are collinear, as on noise-free series).
pub(super) fn fit_one(
    gsc: &GroupSparseCoder,
    series: &[&[f64]],
    lags: usize,
    first: usize,
    part: Part,
) -> Result<LagGain> {
    let t = gsc.horizons();
    let d = t * (lags + 1);
    let first = first.max(first_origin(gsc, lags));
    let (mut zz, mut zr) = (DMatrix::<f64>::zeros(d, d), DMatrix::<f64>::zeros(d, t));
    let mut n = 0usize;
    for x in series {
        for i in origins(x.len(), first, t, part) {
            let z = regressors(gsc, x, i, lags)?;
            let r = targets(gsc, x, i)?;
            zz.syger(1.0, &z, &z, 1.0);
            zr.ger(1.0, &z, &r, 1.0);
            n += 1;
        }
    }
    if n <= d {
        return Err(Error::TooShort {
            what: "training origins for the fitted GSKF gain",
            needed: d + 1,
            got: n,
        });
    }
    // `syger` fills the lower triangle only
    zz.fill_upper_triangle_with_lower_triangle();
    let svd = zz.svd(true, true);
    let eps = svd.singular_values.max() * 1e-12;
    let kt = svd
        .solve(&zr, eps)
        .map_err(|e| Error::method("gskf", GainError(e.to_string())))?;
    let k = kt.transpose();
    if k.iter().any(|v| !v.is_finite()) {
        return Err(Error::method("gskf", GainError("a non-finite gain".into())));
    }
    let mut gain = LagGain {
        k,
        variances: vec![0.0; t],
    };
    // the corrected residuals' variances, over the same origins
    let mut sums = vec![0.0; t];
    for x in series {
        for i in origins(x.len(), first, t, part) {
            let e = targets(gsc, x, i)? - &gain.k * regressors(gsc, x, i, lags)?;
            for (s, v) in sums.iter_mut().zip(e.iter()) {
                *s += v * v;
            }
        }
    }
    gain.variances = sums.iter().map(|s| (s / n as f64).max(1e-300)).collect();
    Ok(gain)
}

/// Why a gain could not be fitted.
#[derive(Debug)]
pub(super) struct GainError(String);

impl std::fmt::Display for GainError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "fitting the GSKF gain by least squares: {}", self.0)
    }
}

impl std::error::Error for GainError {}

/// Chooses, for one axis fitted without groups to hold out, between `riccati` (the paper's
/// IKF with the `q` chosen in sample) and a gain fitted with each of `lags`: each fitted gain
/// is fitted on the first three quarters of every series' origins and all of them are
/// scored by the mean squared error over the last quarter (the same origins for every
/// option, from the first origin of the longest lag); the best fitted gain replaces the
/// Riccati one only when its error is lower, and is then refitted on all the origins.
/// Returns the filter and what was chosen, in words.
pub(super) fn choose_in_time(
    riccati: AxisFilter,
    series: &[&[f64]],
    lags: &[usize],
) -> Result<(AxisFilter, String)> {
    let Some(&longest) = lags.iter().max() else {
        return Ok((riccati, String::new()));
    };
    let gsc = riccati.gsc.clone();
    let t = gsc.horizons();
    let first = first_origin(&gsc, longest);
    let score = |f: &AxisFilter| -> Result<f64> {
        let (mut sum, mut n) = (0.0, 0usize);
        for x in series {
            for i in origins(x.len(), first, t, Part::Tail) {
                let p = f.predict(x, i)?;
                for k in 0..t {
                    let e = p.mean[k] - x[i + 1 + k];
                    sum += e * e;
                    n += 1;
                }
            }
        }
        Ok(if n > 0 { sum / n as f64 } else { f64::INFINITY })
    };
    let base = score(&riccati)?;
    let mut said = format!("last quarter of the training origins: q {base:.4e}");
    let mut best: Option<(f64, usize)> = None;
    for &l in lags {
        let e = fit(&gsc, series, l, first, Part::Head)
            .and_then(|g| score(&AxisFilter::fitted(gsc.clone(), g)?));
        match e {
            Ok(e) => {
                said.push_str(&format!(", fitted gain {l} lags {e:.4e}"));
                if e < best.map_or(base, |b| b.0) {
                    best = Some((e, l));
                }
            }
            Err(err) => said.push_str(&format!(", fitted gain {l} lags failed ({err})")),
        }
    }
    match best {
        Some((_, l)) => {
            let g = fit(&gsc, series, l, 0, Part::All)?;
            said.push_str(&format!(" -> fitted gain, {l} lags"));
            Ok((AxisFilter::fitted(gsc, g)?, said))
        }
        None => {
            said.push_str(" -> the Riccati gain");
            Ok((riccati, said))
        }
    }
}

/// A fitted gain as saved: `{"lags", "k", "variances"}` with `k` and `variances` one entry
/// per number of lags from 0 to `lags` (each gain row by row), numbers as exact strings.
pub(super) fn to_json(g: &FittedGain) -> serde_json::Value {
    serde_json::json!({
        "lags": g.lags(),
        "k": g.by_lags.iter().map(|l| exact_matrix(&l.k)).collect::<Vec<_>>(),
        "variances": g.by_lags.iter().map(|l| exact_vec(&l.variances)).collect::<Vec<_>>(),
    })
}

/// Reads a gain saved by [`to_json`] for `t` horizons, checking its shape.
pub(super) fn from_json(at: &At, t: usize) -> Result<FittedGain> {
    let [lags, k, variances] = at.fields(["lags", "k", "variances"])?;
    let l = lags.f64_min(0.0, false)?;
    if l.fract() != 0.0 || l > MAX_LAGS as f64 {
        return Err(lags.error(format!("expected a whole number up to {MAX_LAGS}, got {l}")));
    }
    let n = l as usize + 1;
    let by_lags = k
        .items(Some(n), n)?
        .iter()
        .zip(variances.items(Some(n), n)?)
        .enumerate()
        .map(|(l, (k, v))| {
            Ok(LagGain {
                k: k.matrix(t, t * (l + 1))?,
                variances: v.vector(t, |v| v.f64_min(0.0, true))?.as_slice().to_vec(),
            })
        })
        .collect::<Result<_>>()?;
    Ok(FittedGain { by_lags })
}

#[cfg(test)]
mod tests {
    use super::{AxisFilter, Part, first_origin, fit};
    use serde_json::Value;
    use trajpred_sparse::GroupSparseCoder;

    fn num(v: &Value) -> f64 {
        v.as_str().unwrap().parse().unwrap()
    }

    /// The gains of `fixtures/gskf/make_fitted_gain.py` (numpy's least squares on the
    /// least-squares GSC of a noisy series, m = 3, T = 2, 0 to 2 lags): the gain, the
    /// corrected residuals' variances and three corrected forecasts. Tolerance 1e-9
    /// relative (plus 1e-12): the GSC here comes from the LAR path and the gain from the
    /// normal equations, numpy's from orthogonal factorisations of the designs.
    #[test]
    fn the_fitted_gain_is_numpys_least_squares() {
        let fx: Value = serde_json::from_str(include_str!(
            "../../../../../fixtures/gskf/fitted_gain.json"
        ))
        .unwrap();
        let x: Vec<f64> = fx["series"].as_array().unwrap().iter().map(num).collect();
        let gsc = GroupSparseCoder::params(3, 2).fit_many(&[&x[..]]).unwrap();
        let close = |a: f64, b: f64, what: &str| {
            assert!(
                (a - b).abs() <= 1e-12 + 1e-9 * b.abs(),
                "{what}: {a} against numpy's {b}"
            );
        };
        for g in fx["gains"].as_array().unwrap() {
            let lags = g["lags"].as_u64().unwrap() as usize;
            let got = fit(&gsc, &[&x[..]], lags, first_origin(&gsc, lags), Part::All).unwrap();
            for (r, row) in g["k"].as_array().unwrap().iter().enumerate() {
                for (c, v) in row.as_array().unwrap().iter().enumerate() {
                    close(
                        got.by_lags[lags].k[(r, c)],
                        num(v),
                        &format!("{lags} lags, K[{r}, {c}]"),
                    );
                }
            }
            for (k, v) in g["variances"].as_array().unwrap().iter().enumerate() {
                close(
                    got.by_lags[lags].variances[k],
                    num(v),
                    &format!("{lags} lags, variance {k}"),
                );
            }
            let filter = AxisFilter::fitted(gsc.clone(), got).unwrap();
            for (origin, want) in g["forecasts"].as_object().unwrap() {
                let i: usize = origin.parse().unwrap();
                let p = filter.predict(&x, i).unwrap();
                for (k, v) in want.as_array().unwrap().iter().enumerate() {
                    close(
                        p.mean[k],
                        num(v),
                        &format!("{lags} lags, origin {i}, step {k}"),
                    );
                }
            }
        }
    }

    #[test]
    fn too_few_origins_for_the_gain_is_a_typed_error() {
        let x: Vec<f64> = (0..14)
            .map(|i| (0.3 * i as f64).sin() + 0.01 * i as f64)
            .collect();
        let gsc = GroupSparseCoder::params(3, 2).fit_many(&[&x[..]]).unwrap();
        // origins 6..12: 6 of them for 2 x 3 = 6 unknowns per horizon
        let e = fit(&gsc, &[&x[..]], 2, 0, Part::All).unwrap_err();
        assert!(
            matches!(
                e,
                trajpred_core::Error::TooShort {
                    needed: 7,
                    got: 6,
                    ..
                }
            ),
            "{e}"
        );
    }
}
