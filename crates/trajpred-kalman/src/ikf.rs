//! The improved one-step-ahead Kalman filter [`Ikf`] of the MSTPM-GSKF paper (`docs/papers.md` A.4,
//! eq. 12-13).
//!
//! At prediction time the observation `Z(k)` is not known yet, so the paper replaces the
//! current innovation covariance and residual by the previous ones:
//!
//! ```text
//! X(k|k-1) = F X(k-1|k-1)                 P(k|k-1) = F P(k-1|k-1) F^T + Q
//! K(k)     = P(k|k-1) H^T S(k-1)^-1                                     (eq. 12)
//! X(k|k)   = X(k|k-1) + K(k) V(k-1)                                     (eq. 13)
//! P(k|k)   = (I - K H) P(k|k-1)   (Joseph form by default, see below)
//! V(k) = Z(k) - H X(k|k-1),  S(k) = H P(k|k-1) H^T + R   once Z(k) is observed.
//! ```
//!
//! `X(k|k)` is a corrected **one-step-ahead prediction** of time `k` made at time `k-1`,
//! not a filtered estimate.

use crate::alloc::FilterAllocator;
use crate::driver::scan;
use crate::error::Result;
use crate::filter::{CovarianceUpdate, InputChecks, validate_state};
use crate::linalg::{check_dim, check_finite, ldl, symmetrise};
use crate::model::{LinearObservationModel, LinearTransitionModel, validate_models};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};
use trajpred_core::Gaussian;

/// A residual `V = Z - H X(k|k-1)` and its covariance `S = H P(k|k-1) H^T + R`: what the IKF
/// carries from one step to the next, as the core [`Gaussian`] `N(V, S)` (the residual in
/// `mean`). It is the IKF's model of the innovation it cannot see yet: eq. 12-13 correct the
/// prediction of step `k` with `V(k-1)` in place of `V(k)`, and `S(k-1)` in place of `S(k)`.
/// [`Gaussian::new`] checks the shapes, finiteness and symmetry; [`Ikf::correct`] checks that
/// `S` is positive definite where it solves with it.
pub type Innovation<T, M> = Gaussian<T, M>;

/// One IKF step: the plain prediction, the corrected one-step-ahead prediction, and the
/// innovation of this step's observation (when there was one).
#[derive(Debug, Clone, PartialEq)]
pub struct IkfStep<T: RealField, D: Dim, M: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    /// `N(X(k|k-1), P(k|k-1))`.
    pub prior: Gaussian<T, D>,
    /// `N(X(k|k), P(k|k))` of eq. 13: the corrected one-step-ahead prediction of time `k`.
    pub corrected: Gaussian<T, D>,
    /// `V(k)`, `S(k)` once `Z(k)` is observed.
    pub innovation: Option<Innovation<T, M>>,
}

/// The improved one-step-ahead Kalman filter (`docs/papers.md` A.4), for any `F`, `H`, `Q`, `R`,
/// static or dynamic sizes (the GSKF chooses the state size `T` at run time).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use trajpred_core::Gaussian;
/// use trajpred_kalman::{Ikf, Innovation, LinearObservation, LinearTransition};
/// let n = 3; // e.g. three horizons
/// let tr = LinearTransition::new(DMatrix::identity(n, n), DMatrix::identity(n, n) * 0.01)?;
/// let ob = LinearObservation::new(DMatrix::identity(n, n), DMatrix::identity(n, n) * 0.1)?;
/// let ikf = Ikf::new(tr, ob)?;
/// // the prediction X(k|k-1) comes from elsewhere (GSC); P is propagated by F and Q
/// let prior = Gaussian { mean: DVector::from_element(n, 1.0), covariance: ikf.propagate_covariance(&DMatrix::identity(n, n))? };
/// let previous = Innovation::new(DVector::from_element(n, 0.2), DMatrix::identity(n, n) * 1.11)?;
/// let corrected = ikf.correct(&prior, &previous)?;
/// assert!(corrected.mean[0] > 1.0 && corrected.mean[0] < 1.2);
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Ikf<Tr, Ob> {
    transition: Tr,
    observation: Ob,
    covariance_update: CovarianceUpdate,
}

impl<Tr, Ob> Ikf<Tr, Ob> {
    /// An IKF from a linear transition (`F`, `Q`) and observation (`H`, `R`).
    pub fn new<T: RealField + Copy, D: Dim, M: Dim>(transition: Tr, observation: Ob) -> Result<Self>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        validate_models(&transition, &observation)?;
        check_dim(
            "H columns",
            transition.state_dim(),
            observation.observation_matrix().ncols(),
        )?;
        Ok(Ikf {
            transition,
            observation,
            covariance_update: CovarianceUpdate::Joseph,
        })
    }

    /// Selects the covariance form of `P(k|k)`: Joseph (default) evaluates
    /// `(I - K H) P (I - K H)^T + K R K^T` with the IKF gain; `Plain` is the paper's
    /// `(I - K H) P`.
    pub fn with_covariance_update(mut self, form: CovarianceUpdate) -> Self {
        self.covariance_update = form;
        self
    }

    /// `P(k|k-1) = F P F^T + Q`.
    pub fn propagate_covariance<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        p: &OMatrix<T, D, D>,
    ) -> Result<OMatrix<T, D, D>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let n = self.transition.state_dim();
        check_dim("P rows", n, p.nrows())?;
        check_dim("P columns", n, p.ncols())?;
        crate::linalg::check_psd(p, "P")?;
        let f = self.transition.transition_matrix();
        let mut out = f * p * f.transpose() + self.transition.process_noise();
        symmetrise(&mut out);
        check_finite(&out, "predicted covariance")?;
        Ok(out)
    }

    /// The prediction `N(F x, F P F^T + Q)`.
    pub fn predict<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        state: &Gaussian<T, D>,
    ) -> Result<Gaussian<T, D>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        validate_state(state, self.transition.state_dim(), InputChecks::Full)?;
        let covariance = self.propagate_covariance::<T, D, M>(&state.covariance)?;
        let mean = self.transition.transition_matrix() * &state.mean;
        check_finite(&mean, "predicted mean")?;
        Ok(Gaussian { mean, covariance })
    }

    /// `V = z - H X(k|k-1)` and `S = H P(k|k-1) H^T + R` of an observation.
    pub fn innovation<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        prior: &Gaussian<T, D>,
        z: &OVector<T, M>,
    ) -> Result<Innovation<T, M>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        validate_state(prior, self.transition.state_dim(), InputChecks::Full)?;
        check_dim("observation", self.observation.observation_dim(), z.nrows())?;
        check_finite(z, "observation")?;
        let h = self.observation.observation_matrix();
        let residual = z - h * &prior.mean;
        let mut covariance =
            h * &prior.covariance * h.transpose() + self.observation.observation_noise();
        symmetrise(&mut covariance);
        Ok(Innovation::new(residual, covariance)?)
    }

    /// Eq. 12-13: the corrected one-step-ahead prediction
    /// `X(k|k) = X(k|k-1) + P(k|k-1) H^T S(k-1)^-1 V(k-1)` and its covariance.
    pub fn correct<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        prior: &Gaussian<T, D>,
        previous: &Innovation<T, M>,
    ) -> Result<Gaussian<T, D>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let n = self.transition.state_dim();
        validate_state(prior, n, InputChecks::Full)?;
        let m = self.observation.observation_dim();
        check_dim("previous residual", m, previous.mean.nrows())?;
        check_dim("previous S", m, previous.covariance.nrows())?;
        check_finite(&previous.mean, "previous residual")?;
        let h = self.observation.observation_matrix();
        let p = &prior.covariance;
        let hp = h * p;
        let factors = ldl(previous.covariance.clone(), "S")?;
        let mut kt = hp.clone();
        factors.solve_mut(&mut kt);
        let gain = kt.transpose();
        let mean = &prior.mean + &gain * &previous.mean;
        let mut cov = match self.covariance_update {
            CovarianceUpdate::Joseph => {
                let mut ikh = -(&gain * h);
                for i in 0..n {
                    ikh[(i, i)] += T::one();
                }
                &ikh * p * ikh.transpose()
                    + &gain * self.observation.observation_noise() * gain.transpose()
            }
            CovarianceUpdate::Plain | CovarianceUpdate::Symmetrised => p - &gain * &hp,
        };
        if self.covariance_update != CovarianceUpdate::Plain {
            symmetrise(&mut cov);
        }
        check_finite(&mean, "corrected mean")?;
        check_finite(&cov, "corrected covariance")?;
        Ok(Gaussian {
            mean,
            covariance: cov,
        })
    }

    /// One step: predict from `state`, correct with the previous innovation (if any), and
    /// form this step's innovation from `z` (if observed).
    pub fn step<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        state: &Gaussian<T, D>,
        previous: Option<&Innovation<T, M>>,
        z: Option<&OVector<T, M>>,
    ) -> Result<IkfStep<T, D, M>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let prior = self.predict::<T, D, M>(state)?;
        let corrected = match previous {
            Some(v) => self.correct(&prior, v)?,
            None => prior.clone(),
        };
        let innovation = match z {
            Some(z) => Some(self.innovation(&prior, z)?),
            None => None,
        };
        Ok(IkfStep {
            prior,
            corrected,
            innovation,
        })
    }

    /// Runs [`Ikf::step`] over a sequence: step `k`'s `corrected` is the one-step-ahead
    /// prediction of time `k` using observations up to `k-1` only. A missing observation
    /// leaves the most recent innovation in use.
    pub fn filter<T: RealField + Copy, D: Dim, M: Dim>(
        &self,
        initial: &Gaussian<T, D>,
        observations: &[Option<OVector<T, M>>],
    ) -> Result<Vec<IkfStep<T, D, M>>>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let mut memory: Option<Innovation<T, M>> = None;
        scan(observations, |prev: Option<&IkfStep<T, D, M>>, z| {
            let state = prev.map_or(initial, |s| &s.corrected);
            let step = self.step(state, memory.as_ref(), z.as_ref())?;
            if let Some(v) = &step.innovation {
                memory = Some(v.clone());
            }
            Ok(step)
        })
    }
}
