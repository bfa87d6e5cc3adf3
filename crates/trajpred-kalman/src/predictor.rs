//! The KF-dynamic predictor form of the dynamic trajectory prediction paper (eq.
//! 13-15) and its multi-step forecast, as methods of [`Kf`].
//!
//! ```text
//! K(k)     = A P(k|k-1) H^T (H P(k|k-1) H^T + R)^-1                       (eq. 13)
//! X(k+1|k) = A X(k|k-1) + K(k) (Z(k) - H X(k|k-1))                        (eq. 14)
//! P(k+1|k) = A P A^T - A P H^T (H P H^T + R)^-1 H P A^T + Q               (eq. 15)
//! ```
//!
//! (The paper prints `- R` in eq. 15; it is a typo for `+ R` inside the inverse.) This is the
//! KF written as one recursion on the one-step-ahead prediction; it equals
//! [`Filter::update`] with the plain covariance form followed by [`Filter::predict`].

use crate::alloc::FilterAllocator;
use crate::driver::scan;
use crate::error::Result;
use crate::filter::{Filter, InputChecks, validate_state};
use crate::kf::Kf;
use crate::linalg::{check_dim, check_finite, ldl, symmetrise};
use crate::model::{LinearObservationModel, LinearTransitionModel};
use nalgebra::{DefaultAllocator, Dim, OVector, RealField};
use trajpred_core::Gaussian;

/// How [`Kf::predictor_forecast`] continues after the first step, for which the latest
/// observation is used.
///
/// The paper says to "use the previous moment's observation and iterate k steps" of eq.
/// 13-15. Read literally ([`MultiStep::ReuseLastObservation`]), every later step corrects
/// towards the same `Z(k)` again, as if the target were seen at that place once more, which
/// pulls the forecast back to where the target was. [`MultiStep::Extrapolate`] (the
/// default) uses `Z(k)` once and then predicts alone; its forecast equals the standard
/// filter's `X(k|k)` extrapolated by `A`.
///
/// ```
/// use trajpred_kalman::MultiStep;
/// assert_eq!(MultiStep::default(), MultiStep::Extrapolate);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MultiStep {
    /// Re-apply eq. 13-15 with the latest observation `Z(k)` at every step: the literal
    /// reading of the paper, kept for its reproduction.
    ReuseLastObservation,
    /// After the first step, extrapolate without correction: `X(k+j+1|k) = A X(k+j|k)`,
    /// `P = A P A^T + Q`. The default.
    #[default]
    Extrapolate,
}

impl<Tr, Ob> Kf<Tr, Ob> {
    /// Eq. 13-15: from the one-step-ahead prediction `N(X(k|k-1), P(k|k-1))` and the
    /// observation `Z(k)` (or `None` when missing: then `K = 0`), the next one
    /// `N(X(k+1|k), P(k+1|k))`.
    pub fn predictor_step<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        prediction: &Gaussian<T, D>,
        z: Option<&OVector<T, M>>,
    ) -> Result<Gaussian<T, D>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        self.predictor_step_checked(prediction, z, InputChecks::Full)
    }

    /// [`Kf::predictor_step`] with the input checks `checks`: the recursions below check the
    /// caller's state fully once and their own outputs cheaply (shapes, finite values,
    /// symmetry; an output of eq. 15 is positive semi-definite by construction).
    fn predictor_step_checked<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        prediction: &Gaussian<T, D>,
        z: Option<&OVector<T, M>>,
        checks: InputChecks,
    ) -> Result<Gaussian<T, D>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let Some(z) = z else {
            return match checks {
                InputChecks::Full => self.predict(prediction),
                _ => self.predict_own_output(prediction),
            };
        };
        let tr = self.transition();
        let ob = self.observation();
        validate_state(prediction, tr.state_dim(), checks)?;
        check_dim("observation", ob.observation_dim(), z.nrows())?;
        check_finite(z, "observation")?;
        let a = tr.transition_matrix();
        let h = ob.observation_matrix();
        let p = &prediction.covariance;
        let hp = h * p;
        let mut s = &hp * h.transpose() + ob.observation_noise();
        symmetrise(&mut s);
        let factors = ldl(s, "S")?;
        // H P A^T (m x n); K = A P H^T S^-1 = (S^-1 H P A^T)^T
        let hpa = &hp * a.transpose();
        let mut kt = hpa.clone();
        factors.solve_mut(&mut kt);
        let gain = kt.transpose();
        let innovation = z - h * &prediction.mean;
        let mean = a * &prediction.mean + &gain * innovation;
        let mut cov = a * p * a.transpose() - &gain * &hpa + tr.process_noise();
        symmetrise(&mut cov);
        check_finite(&mean, "predicted mean")?;
        check_finite(&cov, "predicted covariance")?;
        Ok(Gaussian {
            mean,
            covariance: cov,
        })
    }

    /// Runs eq. 13-15 over a sequence from `N(X(1|0), P(1|0))`: element `k` is
    /// `N(X(k+2|k+1), ...)`, the prediction of the time after observation `k`.
    pub fn predictor_filter<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        first_prediction: &Gaussian<T, D>,
        observations: &[Option<OVector<T, M>>],
    ) -> Result<Vec<Gaussian<T, D>>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        scan(
            observations,
            |prev: Option<&Gaussian<T, D>>, z| match prev {
                Some(prev) => self.predictor_step_checked(prev, z.as_ref(), InputChecks::Cheap),
                None => self.predictor_step(first_prediction, z.as_ref()),
            },
        )
    }

    /// The `steps`-step forecast `N(X(k+j|k), P(k+j|k))`, `j = 1..=steps`, from the
    /// prediction `N(X(k|k-1), P(k|k-1))` and the latest observation `Z(k)`: the first step
    /// is eq. 13-15; later steps follow `mode`.
    pub fn predictor_forecast<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        prediction: &Gaussian<T, D>,
        last_observation: &OVector<T, M>,
        steps: usize,
        mode: MultiStep,
    ) -> Result<Vec<Gaussian<T, D>>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        scan(0..steps, |prev: Option<&Gaussian<T, D>>, _| match prev {
            None => self.predictor_step(prediction, Some(last_observation)),
            Some(current) if mode == MultiStep::ReuseLastObservation => {
                self.predictor_step_checked(current, Some(last_observation), InputChecks::Cheap)
            }
            Some(current) => self.predict_own_output(current),
        })
    }
}
