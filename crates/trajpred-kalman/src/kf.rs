//! The linear Kalman filter [`Kf`] and the extended Kalman filter [`Ekf`]: one linearised
//! predict/update code path, the KF with constant `F`, `H`, the EKF with `f`, `h` and their
//! Jacobians evaluated at the current estimate.

use crate::alloc::FilterAllocator;
use crate::error::Result;
use crate::filter::{
    CovarianceUpdate, Filter, InputChecks, PredictionAndUpdate, PredictionWithCross, Smoother,
    Update, check_prediction, finish_update, linear_predict_unchecked_output, linearized_predict,
    linearized_update, selection_products, validate_state,
};
use crate::linalg::{check_dim, check_finite, exactly_symmetric, is_static, mul_vec};
use crate::model::{
    LinearObservationModel, LinearTransitionModel, ObservationJacobian, TransitionJacobian,
    validate_models,
};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OVector, RealField};
use trajpred_core::Gaussian;

/// The settings and accessors that [`Kf`] and [`Ekf`] share (both hold a transition, an
/// observation, a covariance update form and input checks).
macro_rules! settings {
    ($filter:ident) => {
        impl<Tr, Ob> $filter<Tr, Ob> {
            /// Selects the covariance update form.
            pub fn with_covariance_update(mut self, form: CovarianceUpdate) -> Self {
                self.covariance_update = form;
                self
            }

            /// Selects how much of the input state is verified ([`InputChecks::Full`] by
            /// default).
            pub fn with_input_checks(mut self, checks: InputChecks) -> Self {
                self.checks = checks;
                self
            }

            /// The covariance update form in use.
            pub fn covariance_update(&self) -> CovarianceUpdate {
                self.covariance_update
            }

            /// The transition model.
            pub fn transition(&self) -> &Tr {
                &self.transition
            }

            /// The observation model.
            pub fn observation(&self) -> &Ob {
                &self.observation
            }
        }
    };
}
settings!(Kf);
settings!(Ekf);

// The RTS smoother of the linearised filters: the cross-covariance `C = P F^T`, with `F` the
// transition matrix (KF) or its Jacobian at the filtered mean (EKF).
macro_rules! smoother {
    ($filter:ident, $tr:ident, $ob:ident, |$t:ident, $x:ident| $jacobian:expr) => {
        impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> Smoother<T, D, M> for $filter<Tr, Ob>
        where
            Tr: $tr<T, D>,
            Ob: $ob<T, D, M>,
            DefaultAllocator: FilterAllocator<D, M>,
        {
            fn prediction_with_cross_covariance(
                &self,
                filtered: &Gaussian<T, D>,
            ) -> Result<PredictionWithCross<T, D>> {
                let pred = self.predict(filtered)?;
                let ($t, $x) = (&self.transition, &filtered.mean);
                let f = $jacobian;
                Ok((pred, &filtered.covariance * f.transpose()))
            }
        }
    };
}

/// The linear Kalman filter.
///
/// Predict: `x(k|k-1) = F x(k-1|k-1)`, `P(k|k-1) = F P F^T + Q`.
/// Update: `y = z - H x`, `S = H P H^T + R`, `K = P H^T S^-1` (Cholesky solve, no inverse),
/// `x(k|k) = x + K y`, `P(k|k)` by the [`CovarianceUpdate`] form (Joseph by default).
///
/// ```
/// use nalgebra::{Matrix1, Matrix1x2, Matrix2, Vector1, Vector2};
/// use trajpred_core::Gaussian;
/// use trajpred_kalman::{Filter, Kf, LinearObservation, LinearTransition};
/// let tr = LinearTransition::new(Matrix2::new(1.0, 1.0, 0.0, 1.0), Matrix2::identity() * 1e-3)?;
/// let ob = LinearObservation::new(Matrix1x2::new(1.0, 0.0), Matrix1::new(0.25))?;
/// let kf = Kf::new(tr, ob)?;
/// let x0 = Gaussian { mean: Vector2::new(0.0, 1.0), covariance: Matrix2::identity() };
/// let step = kf.step(&x0, Some(&Vector1::new(1.1)))?;
/// assert!(step.posterior().covariance[(0, 0)] < step.prior.covariance[(0, 0)]);
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Kf<Tr, Ob> {
    transition: Tr,
    observation: Ob,
    covariance_update: CovarianceUpdate,
    checks: InputChecks,
    /// How the observation selects state components (checked against the sizes once, in
    /// [`Kf::new`]).
    selection: Selection,
}

/// How the rows of `H` select state components ([`LinearObservationModel::selected_components`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Selection {
    /// `H` is not a selection: the products with `H`.
    None,
    /// Row `a` selects component `stride * a` (`stride` 1 to 3: the positions of the
    /// kinematic states in either order), indices the compiler knows for static sizes.
    Strided(usize),
    /// Any other selection `idx[a] < n`.
    General,
}

impl<Tr, Ob> Kf<Tr, Ob> {
    /// A KF from a linear transition (F, Q) and a linear observation (H, R), with the
    /// Joseph-form covariance update. Checks `Q` (positive semi-definite) and `R` (positive
    /// definite) once here.
    #[inline]
    pub fn new<T: RealField + Copy, D: Dim, M: Dim>(transition: Tr, observation: Ob) -> Result<Self>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator:
            Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
    {
        validate_models(&transition, &observation)?;
        check_dim(
            "H columns",
            transition.state_dim(),
            observation.observation_matrix().ncols(),
        )?;
        let (n, m) = (transition.state_dim(), observation.observation_dim());
        let selection = match observation.selected_components() {
            Some(idx) if idx.len() == m && idx.iter().all(|&i| i < n) => (1..=3)
                .find(|&stride| idx.iter().enumerate().all(|(a, &i)| i == stride * a))
                .map_or(Selection::General, Selection::Strided),
            _ => Selection::None,
        };
        Ok(Kf {
            transition,
            observation,
            covariance_update: CovarianceUpdate::Joseph,
            checks: InputChecks::Full,
            selection,
        })
    }

    /// Changes the transition in place through `change` (for example
    /// [`kinematic_continuous_in_place`](crate::motion::kinematic_continuous_in_place) for the
    /// next interval of an irregular track: no new filter is built), then checks it as
    /// [`Kf::new`] does: its `Q` ([`Transition::check_process_noise`](crate::Transition::check_process_noise))
    /// and its size against `H`. On an error the filter holds whatever `change` left, and
    /// should not be used.
    pub fn update_transition<T: RealField + Copy, D: Dim, M: Dim>(
        &mut self,
        change: impl FnOnce(&mut Tr) -> Result<()>,
    ) -> Result<()>
    where
        Tr: LinearTransitionModel<T, D>,
        Ob: LinearObservationModel<T, D, M>,
        DefaultAllocator:
            Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
    {
        change(&mut self.transition)?;
        self.transition.check_process_noise()?;
        check_dim(
            "H columns",
            self.transition.state_dim(),
            self.observation.observation_matrix().ncols(),
        )
    }

    /// The prediction with the input checks `checks`, its finiteness not yet checked
    /// ([`linear_predict_unchecked_output`]).
    #[inline(always)]
    fn prior<T, D>(&self, state: &Gaussian<T, D>, checks: InputChecks) -> Result<Gaussian<T, D>>
    where
        T: RealField + Copy,
        D: Dim,
        Tr: LinearTransitionModel<T, D>,
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let n = self.transition.state_dim();
        let factorise = self.checks == InputChecks::Full;
        linear_predict_unchecked_output(&self.transition, state, n, factorise, checks)
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> Filter<T, D, M> for Kf<Tr, Ob>
where
    Tr: LinearTransitionModel<T, D>,
    Ob: LinearObservationModel<T, D, M>,
    DefaultAllocator: FilterAllocator<D, M>,
{
    #[inline(always)]
    fn predict(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>> {
        let prior = self.prior(state, self.checks)?;
        check_prediction(&prior)?;
        Ok(prior)
    }

    fn predict_own_output(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>> {
        let prior = self.prior(state, InputChecks::Cheap)?;
        check_prediction(&prior)?;
        Ok(prior)
    }

    fn update(&self, prior: &Gaussian<T, D>, z: &OVector<T, M>) -> Result<Update<T, D, M>> {
        validate_state(prior, self.transition.state_dim(), self.checks)?;
        self.update_predicted(prior, z)
    }

    /// The prediction's finiteness is proven by the update's: every element of the prior
    /// enters the same element of the posterior with coefficient 1 (`x + K y`, and
    /// `P + U K^T + K U^T` from the lower triangle of `P` or `P - K H P`), so a finite
    /// posterior and an exactly symmetric prior covariance prove the prior finite. The
    /// triangles are compared only when the transition does not promise them equal
    /// ([`LinearTransitionModel::mirrors_covariance`]; [`LinearTransition`](crate::LinearTransition)
    /// does). The prior is checked itself only when the update fails or the prior is not
    /// exactly symmetric, so the errors are those of `predict` then `update_predicted`.
    #[inline(always)]
    fn predict_update(
        &self,
        state: &Gaussian<T, D>,
        z: &OVector<T, M>,
        own_output: bool,
    ) -> Result<PredictionAndUpdate<T, D, M>> {
        let checks = if own_output {
            InputChecks::Cheap
        } else {
            self.checks
        };
        let prior = self.prior(state, checks)?;
        match self.update_predicted(&prior, z) {
            Ok(update) => {
                if !self.transition.mirrors_covariance() && !exactly_symmetric(&prior.covariance) {
                    check_prediction(&prior)?;
                }
                Ok((prior, update))
            }
            Err(e) => {
                check_prediction(&prior)?;
                Err(e)
            }
        }
    }

    #[inline(always)]
    fn update_predicted(
        &self,
        prior: &Gaussian<T, D>,
        z: &OVector<T, M>,
    ) -> Result<Update<T, D, M>> {
        check_dim("prior", self.transition.state_dim(), prior.mean.nrows())?;
        if self.selection != Selection::None
            && let Some(idx) = self.observation.selected_components()
        {
            check_dim("observation", self.observation.observation_dim(), z.nrows())?;
            check_finite(z, "observation")?;
            let r = self.observation.observation_noise();
            let last = prior.mean.nrows().saturating_sub(1);
            // one arm per stride, so that the indices are constants for static sizes (and
            // the prior can stay in registers); for static sizes the general arm reads a
            // copy of the prior (a stack copy, which keeps the run-time indices from
            // holding the prior itself in memory on every path)
            let (zp, hp, s) = match self.selection {
                Selection::Strided(1) => selection_products(|a| a.min(last), prior, r),
                Selection::Strided(2) => selection_products(|a| (2 * a).min(last), prior, r),
                Selection::Strided(3) => selection_products(|a| (3 * a).min(last), prior, r),
                _ if is_static::<D, D>() => {
                    let copy = prior.clone();
                    selection_products(|a| idx[a].min(last), &copy, r)
                }
                _ => selection_products(|a| idx[a].min(last), prior, r),
            };
            return finish_update(
                &self.observation,
                prior,
                &zp,
                hp,
                s,
                z,
                self.covariance_update,
            );
        }
        let h = self.observation.observation_matrix();
        let zp = mul_vec(h, &prior.mean);
        linearized_update(&self.observation, prior, &zp, h, z, self.covariance_update)
    }
}

smoother!(
    Kf,
    LinearTransitionModel,
    LinearObservationModel,
    |tr, _x| { tr.transition_matrix() }
);

/// The extended Kalman filter: nonlinear transition **and** observation, each linearised at
/// the current estimate.
///
/// Predict: `x(k|k-1) = f(x)`, `P(k|k-1) = F(x) P F(x)^T + Q` with `F = df/dx` at
/// `x(k-1|k-1)`. Update: `y = residual(z, h(x))`, `H = dh/dx` at `x(k|k-1)`, then as the KF
/// (same code). filterpy's `ExtendedKalmanFilter` linearises only `h`; here both are.
#[derive(Debug, Clone)]
pub struct Ekf<Tr, Ob> {
    transition: Tr,
    observation: Ob,
    covariance_update: CovarianceUpdate,
    checks: InputChecks,
}

impl<Tr, Ob> Ekf<Tr, Ob> {
    /// An EKF from models with Jacobians; checks `Q` and `R` once here.
    pub fn new<T: RealField + Copy, D: Dim, M: Dim>(transition: Tr, observation: Ob) -> Result<Self>
    where
        Tr: TransitionJacobian<T, D>,
        Ob: ObservationJacobian<T, D, M>,
        DefaultAllocator:
            Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
    {
        validate_models(&transition, &observation)?;
        Ok(Ekf {
            transition,
            observation,
            covariance_update: CovarianceUpdate::Joseph,
            checks: InputChecks::Full,
        })
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> Filter<T, D, M> for Ekf<Tr, Ob>
where
    Tr: TransitionJacobian<T, D>,
    Ob: ObservationJacobian<T, D, M>,
    DefaultAllocator: FilterAllocator<D, M>,
{
    fn predict(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>> {
        validate_state(state, self.transition.state_dim(), self.checks)?;
        self.predict_validated(state)
    }

    fn predict_own_output(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>> {
        validate_state(state, self.transition.state_dim(), InputChecks::Cheap)?;
        self.predict_validated(state)
    }

    fn update(&self, prior: &Gaussian<T, D>, z: &OVector<T, M>) -> Result<Update<T, D, M>> {
        validate_state(prior, self.transition.state_dim(), self.checks)?;
        self.update_predicted(prior, z)
    }

    #[inline(always)]
    fn update_predicted(
        &self,
        prior: &Gaussian<T, D>,
        z: &OVector<T, M>,
    ) -> Result<Update<T, D, M>> {
        check_dim("prior", self.transition.state_dim(), prior.mean.nrows())?;
        let zp = self.observation.observe(&prior.mean)?;
        let h = self.observation.observation_jacobian(&prior.mean)?;
        linearized_update(&self.observation, prior, &zp, &h, z, self.covariance_update)
    }
}

impl<Tr, Ob> Ekf<Tr, Ob> {
    /// The prediction of an already validated state.
    fn predict_validated<T, D>(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>>
    where
        T: RealField + Copy,
        D: Dim,
        Tr: TransitionJacobian<T, D>,
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let n = self.transition.state_dim();
        let mean = self.transition.transition(&state.mean)?;
        check_dim("f(x)", n, mean.nrows())?;
        let f = self.transition.transition_jacobian(&state.mean)?;
        linearized_predict(mean, &f, state, self.transition.process_noise())
    }
}

smoother!(Ekf, TransitionJacobian, ObservationJacobian, |tr, x| {
    tr.transition_jacobian(x)?
});
