//! Model traits: the state transition (f, its Jacobian F, process noise Q) and the observation
//! (h, its Jacobian H, observation noise R), kept apart as in adskalman so that any transition
//! can be paired with any observation; and the two linear models [`LinearTransition`] and
//! [`LinearObservation`].
//!
//! | trait | provides | used by |
//! |---|---|---|
//! | [`Transition`] | `f(x)`, `Q`, residual | [`Ukf`](crate::Ukf) |
//! | [`TransitionJacobian`] | + `F(x) = df/dx` | [`Ekf`](crate::Ekf) |
//! | [`LinearTransitionModel`] | + constant `F` by reference | [`Kf`](crate::Kf), [`Ikf`](crate::Ikf) |
//! | [`Observation`] | `h(x)`, `R`, residual | [`Ukf`](crate::Ukf) |
//! | [`ObservationJacobian`] | + `H(x) = dh/dx` | [`Ekf`](crate::Ekf) |
//! | [`LinearObservationModel`] | + constant `H` by reference | [`Kf`](crate::Kf), [`Ikf`](crate::Ikf) |
//!
//! Every trait is implemented for references too, so one model value can serve several
//! filters (the MKPF proposal runs a UKF step and an EKF step on the same models).

use crate::error::Result;
use crate::linalg::{check_dim, check_finite, check_pd, check_psd, check_square};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};

/// A state transition `x(k+1) = f(x(k)) + w`, `w ~ N(0, Q)`.
pub trait Transition<T: RealField + Copy, D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The transition function `f(x)`.
    fn transition(&self, x: &OVector<T, D>) -> Result<OVector<T, D>>;

    /// The process noise covariance `Q` (symmetric positive semi-definite).
    fn process_noise(&self) -> &OMatrix<T, D, D>;

    /// The state dimension `n` (by default the size of `Q`).
    fn state_dim(&self) -> usize {
        self.process_noise().nrows()
    }

    /// The difference `a - b` of two states; override it for states holding angles (wrap the
    /// angular components). The UKF computes every mean as `x0 + sum_i w_i residual(x_i, x0)`
    /// and every spread with this function, so wrapping here gives correct angular means.
    fn state_residual(&self, a: &OVector<T, D>, b: &OVector<T, D>) -> OVector<T, D> {
        a - b
    }
}

/// A [`Transition`] with its Jacobian `F(x) = df/dx`, needed by the EKF.
pub trait TransitionJacobian<T: RealField + Copy, D: Dim>: Transition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The Jacobian `F(x) = df/dx` evaluated at `x`.
    fn transition_jacobian(&self, x: &OVector<T, D>) -> Result<OMatrix<T, D, D>>;
}

/// A linear transition `x(k+1) = F x(k) + w`, exposing `F` by reference (no copy per step).
pub trait LinearTransitionModel<T: RealField + Copy, D: Dim>: TransitionJacobian<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The transition matrix `F`.
    fn transition_matrix(&self) -> &OMatrix<T, D, D>;
}

/// An observation `z = h(x) + v`, `v ~ N(0, R)`, of dimension `M`.
pub trait Observation<T: RealField + Copy, D: Dim, M: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    /// The observation function `h(x)`.
    fn observe(&self, x: &OVector<T, D>) -> Result<OVector<T, M>>;

    /// The observation noise covariance `R` (symmetric positive definite).
    fn observation_noise(&self) -> &OMatrix<T, M, M>;

    /// The observation dimension `m` (by default the size of `R`).
    fn observation_dim(&self) -> usize {
        self.observation_noise().nrows()
    }

    /// The difference `a - b` of two observations (the innovation is
    /// `residual(z, h(x))`); override it to wrap angles such as a bearing.
    fn observation_residual(&self, a: &OVector<T, M>, b: &OVector<T, M>) -> OVector<T, M> {
        a - b
    }

    /// Brings an observation-space mean back into its canonical range (e.g. a bearing into
    /// `[-pi, pi)`) after the UKF has averaged sigma points. Identity by default.
    fn normalize_observation(&self, z: OVector<T, M>) -> OVector<T, M> {
        z
    }
}

/// An [`Observation`] with its Jacobian `H(x) = dh/dx` (an `m x n` matrix), needed by the EKF.
pub trait ObservationJacobian<T: RealField + Copy, D: Dim, M: Dim>: Observation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    /// The Jacobian `H(x) = dh/dx` evaluated at `x`.
    fn observation_jacobian(&self, x: &OVector<T, D>) -> Result<OMatrix<T, M, D>>;
}

/// A linear observation `z = H x + v`, exposing `H` by reference.
pub trait LinearObservationModel<T: RealField + Copy, D: Dim, M: Dim>:
    ObservationJacobian<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    /// The observation matrix `H`.
    fn observation_matrix(&self) -> &OMatrix<T, M, D>;
}

// ---- references -----------------------------------------------------------------------------

impl<T: RealField + Copy, D: Dim, X: Transition<T, D> + ?Sized> Transition<T, D> for &X
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition(&self, x: &OVector<T, D>) -> Result<OVector<T, D>> {
        (**self).transition(x)
    }
    fn process_noise(&self) -> &OMatrix<T, D, D> {
        (**self).process_noise()
    }
    fn state_dim(&self) -> usize {
        (**self).state_dim()
    }
    fn state_residual(&self, a: &OVector<T, D>, b: &OVector<T, D>) -> OVector<T, D> {
        (**self).state_residual(a, b)
    }
}

impl<T: RealField + Copy, D: Dim, X: TransitionJacobian<T, D> + ?Sized> TransitionJacobian<T, D>
    for &X
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition_jacobian(&self, x: &OVector<T, D>) -> Result<OMatrix<T, D, D>> {
        (**self).transition_jacobian(x)
    }
}

impl<T: RealField + Copy, D: Dim, X: LinearTransitionModel<T, D> + ?Sized>
    LinearTransitionModel<T, D> for &X
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition_matrix(&self) -> &OMatrix<T, D, D> {
        (**self).transition_matrix()
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, X: Observation<T, D, M> + ?Sized> Observation<T, D, M>
    for &X
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    fn observe(&self, x: &OVector<T, D>) -> Result<OVector<T, M>> {
        (**self).observe(x)
    }
    fn observation_noise(&self) -> &OMatrix<T, M, M> {
        (**self).observation_noise()
    }
    fn observation_dim(&self) -> usize {
        (**self).observation_dim()
    }
    fn observation_residual(&self, a: &OVector<T, M>, b: &OVector<T, M>) -> OVector<T, M> {
        (**self).observation_residual(a, b)
    }
    fn normalize_observation(&self, z: OVector<T, M>) -> OVector<T, M> {
        (**self).normalize_observation(z)
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, X: ObservationJacobian<T, D, M> + ?Sized>
    ObservationJacobian<T, D, M> for &X
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observation_jacobian(&self, x: &OVector<T, D>) -> Result<OMatrix<T, M, D>> {
        (**self).observation_jacobian(x)
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, X: LinearObservationModel<T, D, M> + ?Sized>
    LinearObservationModel<T, D, M> for &X
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observation_matrix(&self) -> &OMatrix<T, M, D> {
        (**self).observation_matrix()
    }
}

// ---- linear models --------------------------------------------------------------------------

/// The linear transition `x(k+1) = F x(k) + w`, `w ~ N(0, Q)`, validated at construction.
///
/// ```
/// use nalgebra::{Matrix2, Vector2};
/// use trajpred_kalman::{LinearTransition, Transition};
/// let tr = LinearTransition::new(Matrix2::new(1.0, 1.0, 0.0, 1.0), Matrix2::identity() * 0.1)?;
/// assert_eq!(tr.transition(&Vector2::new(1.0, 2.0))?, Vector2::new(3.0, 2.0));
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LinearTransition<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D, D>,
{
    f: OMatrix<T, D, D>,
    q: OMatrix<T, D, D>,
}

impl<T: RealField + Copy, D: Dim> LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// `F` and `Q`: both square of the same size, finite, `Q` symmetric positive
    /// semi-definite. Errors: [`DimensionMismatch`](crate::KalmanError::DimensionMismatch),
    /// [`NonFinite`](crate::KalmanError::NonFinite),
    /// [`NotPositiveDefinite`](crate::KalmanError::NotPositiveDefinite) (`"Q"`).
    pub fn new(f: OMatrix<T, D, D>, q: OMatrix<T, D, D>) -> Result<Self> {
        let n = f.nrows();
        check_square(&f, n, "F")?;
        check_square(&q, n, "Q vs F")?;
        check_finite(&f, "F")?;
        check_psd(&q, "Q")?;
        Ok(LinearTransition { f, q })
    }

    /// The transition matrix `F`.
    pub fn f(&self) -> &OMatrix<T, D, D> {
        &self.f
    }

    /// The process noise covariance `Q`.
    pub fn q(&self) -> &OMatrix<T, D, D> {
        &self.q
    }
}

impl<T: RealField + Copy, D: Dim> Transition<T, D> for LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition(&self, x: &OVector<T, D>) -> Result<OVector<T, D>> {
        check_dim("state", self.f.ncols(), x.nrows())?;
        Ok(&self.f * x)
    }
    fn process_noise(&self) -> &OMatrix<T, D, D> {
        &self.q
    }
}

impl<T: RealField + Copy, D: Dim> TransitionJacobian<T, D> for LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition_jacobian(&self, _x: &OVector<T, D>) -> Result<OMatrix<T, D, D>> {
        Ok(self.f.clone())
    }
}

impl<T: RealField + Copy, D: Dim> LinearTransitionModel<T, D> for LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition_matrix(&self) -> &OMatrix<T, D, D> {
        &self.f
    }
}

/// The linear observation `z = H x + v`, `v ~ N(0, R)`, validated at construction.
///
/// ```
/// use nalgebra::{Matrix1, Matrix1x2, Vector1, Vector2};
/// use trajpred_kalman::{LinearObservation, Observation};
/// let ob = LinearObservation::new(Matrix1x2::new(1.0, 0.0), Matrix1::new(0.5))?;
/// assert_eq!(ob.observe(&Vector2::new(3.0, 4.0))?, Vector1::new(3.0));
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LinearObservation<T: RealField, D: Dim, M: Dim>
where
    DefaultAllocator: Allocator<M, D> + Allocator<M, M>,
{
    h: OMatrix<T, M, D>,
    r: OMatrix<T, M, M>,
}

impl<T: RealField + Copy, D: Dim, M: Dim> LinearObservation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    /// `H` (`m x n`) and `R` (`m x m`, symmetric positive definite). Errors:
    /// [`DimensionMismatch`](crate::KalmanError::DimensionMismatch),
    /// [`NonFinite`](crate::KalmanError::NonFinite),
    /// [`NotPositiveDefinite`](crate::KalmanError::NotPositiveDefinite) (`"R"`).
    pub fn new(h: OMatrix<T, M, D>, r: OMatrix<T, M, M>) -> Result<Self> {
        check_square(&r, h.nrows(), "R vs H")?;
        check_finite(&h, "H")?;
        check_pd(&r, "R")?;
        Ok(LinearObservation { h, r })
    }

    /// The observation matrix `H`.
    pub fn h(&self) -> &OMatrix<T, M, D> {
        &self.h
    }

    /// The observation noise covariance `R`.
    pub fn r(&self) -> &OMatrix<T, M, M> {
        &self.r
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim> Observation<T, D, M> for LinearObservation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observe(&self, x: &OVector<T, D>) -> Result<OVector<T, M>> {
        check_dim("state", self.h.ncols(), x.nrows())?;
        Ok(&self.h * x)
    }
    fn observation_noise(&self) -> &OMatrix<T, M, M> {
        &self.r
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim> ObservationJacobian<T, D, M>
    for LinearObservation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observation_jacobian(&self, _x: &OVector<T, D>) -> Result<OMatrix<T, M, D>> {
        Ok(self.h.clone())
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim> LinearObservationModel<T, D, M>
    for LinearObservation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observation_matrix(&self) -> &OMatrix<T, M, D> {
        &self.h
    }
}

/// Validates a transition and observation pair once, when a filter is built: `Q` symmetric
/// positive semi-definite, `R` symmetric positive definite, consistent sizes.
pub(crate) fn validate_models<T, D, M, Tr, Ob>(tr: &Tr, ob: &Ob) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    Tr: Transition<T, D>,
    Ob: Observation<T, D, M>,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    let n = tr.state_dim();
    check_square(tr.process_noise(), n, "Q")?;
    check_psd(tr.process_noise(), "Q")?;
    let m = ob.observation_dim();
    check_square(ob.observation_noise(), m, "R")?;
    check_pd(ob.observation_noise(), "R")
}
