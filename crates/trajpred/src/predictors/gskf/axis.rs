//! One axis of a fitted [`Gskf`](super::Gskf): the GSC and its correction (the IKF's
//! converged gain, a gain fitted to the training series, or none), and its errors over rolling
//! origins.

use super::gain::{self, FittedGain};
use super::{Diverged, gsc_at, kalman_error, residuals};
use nalgebra::{DMatrix, DVector, Dyn};
use trajpred_core::{Error, Gaussian, Result};
use trajpred_kalman::{Ikf, Innovation, LinearObservation, LinearTransition};
use trajpred_sparse::GroupSparseCoder;

/// One axis of a fitted GSKF: the GSC, the IKF and its converged covariances.
#[derive(Debug, Clone)]
pub(super) struct AxisFilter {
    pub(super) gsc: GroupSparseCoder,
    ikf: Ikf<LinearTransition<f64, Dyn>, LinearObservation<f64, Dyn, Dyn>>,
    /// `P(k|k-1)` at convergence (`R` without a correction or with a fitted gain, whose
    /// forecasts carry their own variances).
    pub(super) p_prior: DMatrix<f64>,
    /// `S(k-1) = P(k-1|k-2) + R` at convergence.
    s: DMatrix<f64>,
    /// The process noise level, `Q = q I` (0 with a fitted gain).
    pub(super) q: f64,
    /// Whether the Kalman correction is applied; without it the forecast is the GSC's, with
    /// `R` as its covariance (chosen when no `q` beats the GSC on held-out groups).
    pub(super) correct: bool,
    /// The gain fitted to the training series, used instead of the IKF's (see [`gain`]).
    pub(super) gain: Option<FittedGain>,
}

impl AxisFilter {
    /// Builds the IKF for `q` and runs its covariance recursion, which does not depend on the
    /// data (F, Q, R are fixed), to convergence.
    pub(super) fn new(gsc: GroupSparseCoder, q: f64) -> Result<Self> {
        let (m, t) = (gsc.window(), gsc.horizons());
        // F: the T predicted rows and columns of the m x m matrix of eq. 17-19 (for T <= m,
        // the last T columns of A); identity when T > m (`docs/papers.md` A.4)
        let f = if t <= m {
            gsc.coefficients().columns(m - t, t).into_owned()
        } else {
            DMatrix::identity(t, t)
        };
        let r_diag: Vec<f64> = gsc
            .residual_variances()
            .iter()
            .map(|v| v.max(1e-300))
            .collect();
        let r = DMatrix::from_diagonal(&DVector::from_vec(r_diag));
        let transition =
            LinearTransition::new(f, DMatrix::identity(t, t) * q).map_err(kalman_error)?;
        let observation =
            LinearObservation::new(DMatrix::identity(t, t), r.clone()).map_err(kalman_error)?;
        let ikf = Ikf::new(transition, observation).map_err(kalman_error)?;
        // start from P(0|0) = R, with S(0) = F R F^T + Q + R
        let mut post = r.clone();
        let mut s = ikf
            .propagate_covariance::<f64, Dyn, Dyn>(&post)
            .map_err(kalman_error)?
            + &r;
        let mut p_prior = DMatrix::zeros(t, t);
        let from = post.norm();
        let diverged = |iterations: usize, to: f64, cause: String| {
            Error::method(
                "gskf",
                Diverged {
                    q,
                    from,
                    to,
                    iterations,
                    cause,
                },
            )
        };
        // an error at the first iteration is one of the inputs (`R`, `Q`), later ones are
        // the recursion's
        let failed = |it: usize, to: f64, e: trajpred_kalman::KalmanError| match it {
            0 => kalman_error(e),
            _ => diverged(it, to, e.to_string()),
        };
        for it in 0..5000 {
            p_prior = ikf
                .propagate_covariance::<f64, Dyn, Dyn>(&post)
                .map_err(|e| failed(it, post.norm(), e))?;
            let prior = Gaussian {
                mean: DVector::zeros(t),
                covariance: p_prior.clone(),
            };
            let innov = Innovation::new(DVector::zeros(t), s.clone())?;
            let next = ikf
                .correct(&prior, &innov)
                .map_err(|e| failed(it, p_prior.norm(), e))?
                .covariance;
            let change = (&next - &post).norm() / next.norm().max(1e-300);
            post = next;
            s = &p_prior + &r;
            if change < 1e-13 {
                break;
            }
        }
        if p_prior.iter().any(|v| !v.is_finite()) {
            return Err(diverged(5000, p_prior.norm(), "a non-finite P".into()));
        }
        Ok(AxisFilter {
            gsc,
            ikf,
            p_prior,
            s,
            q,
            correct: true,
            gain: None,
        })
    }

    /// The GSC alone, without the Kalman correction: the forecast is the GSC's, its
    /// covariance the diagonal of the GSC residual variances (`R`); no covariance recursion
    /// is run, so this exists whatever the GSC's coefficients.
    pub(super) fn plain(gsc: GroupSparseCoder) -> Result<Self> {
        let t = gsc.horizons();
        let r = DMatrix::from_diagonal(&DVector::from_iterator(
            t,
            gsc.residual_variances().iter().map(|v| v.max(1e-300)),
        ));
        let transition = LinearTransition::new(DMatrix::identity(t, t), DMatrix::zeros(t, t))
            .map_err(kalman_error)?;
        let observation =
            LinearObservation::new(DMatrix::identity(t, t), r.clone()).map_err(kalman_error)?;
        let ikf = Ikf::new(transition, observation).map_err(kalman_error)?;
        Ok(AxisFilter {
            gsc,
            ikf,
            p_prior: r.clone(),
            s: r,
            q: 0.0,
            correct: false,
            gain: None,
        })
    }

    /// The GSC corrected by a gain fitted to the training series: the forecast is
    /// `X_hat^0(i) + K z_i` ([`gain::regressors`]) with the gain of as many lags as the
    /// history has the points for (at most the chosen number), its covariance the diagonal of
    /// that gain's corrected training residuals' variances.
    pub(super) fn fitted(gsc: GroupSparseCoder, gain: FittedGain) -> Result<Self> {
        let mut f = Self::plain(gsc)?;
        f.correct = true;
        f.gain = Some(gain);
        Ok(f)
    }

    /// The lags of the fitted gain (0 for the IKF's gain or none).
    pub(super) fn lags(&self) -> usize {
        self.gain.as_ref().map_or(0, FittedGain::lags)
    }

    /// The corrected T-step prediction at origin `i` of `x` and its covariance.
    pub(super) fn predict(&self, x: &[f64], i: usize) -> Result<Gaussian<f64, Dyn>> {
        let prior = Gaussian {
            mean: DVector::from_vec(gsc_at(&self.gsc, x, i)?),
            covariance: self.p_prior.clone(),
        };
        if !self.correct {
            return Ok(prior);
        }
        if let Some(g) = &self.gain {
            // origin i has the residuals of i + 1 - m - T earlier origins
            let have = (i + 1).saturating_sub(self.gsc.window() + self.gsc.horizons());
            let l = g.lags().min(have);
            let lg = g.by_lags.get(l).ok_or(Error::NotFitted {
                method: "gskf".into(),
            })?;
            let z = gain::regressors(&self.gsc, x, i, l)?;
            return Ok(Gaussian {
                mean: prior.mean + &lg.k * z,
                covariance: DMatrix::from_diagonal(&DVector::from_column_slice(&lg.variances)),
            });
        }
        let v = residuals(&self.gsc, x, i)?;
        let innov = Innovation::new(v, self.s.clone())?;
        self.ikf.correct(&prior, &innov).map_err(kalman_error)
    }
}

/// Mean squared error of every horizon of the GSKF over the rolling origins of `series`.
pub(super) fn in_sample_error(filter: &AxisFilter, series: &[&[f64]]) -> Result<f64> {
    let (sum, _, n) = errors(filter, series, 0)?;
    Ok(if n > 0 { sum / n as f64 } else { f64::INFINITY })
}

/// The sums of squared and of absolute errors of every horizon of the GSKF over the rolling
/// origins of `series` (from the first whose regressors exist for `lags` residual lags, or
/// the filter's own if more), and how many errors there are.
pub(super) fn errors(
    filter: &AxisFilter,
    series: &[&[f64]],
    lags: usize,
) -> Result<(f64, f64, usize)> {
    let t = filter.gsc.horizons();
    let first = gain::first_origin(&filter.gsc, lags.max(filter.lags()));
    let (mut sum, mut abs, mut n) = (0.0, 0.0, 0usize);
    for x in series {
        for i in first..x.len().saturating_sub(t) {
            let g = filter.predict(x, i)?;
            for k in 0..t {
                let e = g.mean[k] - x[i + 1 + k];
                sum += e * e;
                abs += e.abs();
                n += 1;
            }
        }
    }
    Ok((sum, abs, n))
}
