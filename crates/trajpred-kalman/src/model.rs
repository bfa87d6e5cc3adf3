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
use crate::linalg::{check_dim, check_pd, check_psd, check_square, mul, mul_tr_sym_plus, mul_vec};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};

/// A function `g` evaluated at the `2n + 1` symmetric sigma points `x`, `x + L_j`,
/// `x - L_j` (`L_j` the columns of a lower-triangular `L`): `g(x)`, and the matrices whose
/// column `j` is `g(x + L_j)`, respectively `g(x - L_j)`.
#[derive(Debug, Clone, PartialEq)]
pub struct SigmaImages<T: RealField, D: Dim, E: Dim>
where
    DefaultAllocator: Allocator<E> + Allocator<E, D>,
{
    /// `g(x)`.
    pub center: OVector<T, E>,
    /// Column `j`: `g(x + L_j)`.
    pub plus: OMatrix<T, E, D>,
    /// Column `j`: `g(x - L_j)`.
    pub minus: OMatrix<T, E, D>,
}

/// The per-point evaluation of [`SigmaImages`]: `g` once per sigma point, with one point
/// buffer (`L` lower triangular: `x +- L_j` differ from `x` only in rows `j..n`).
#[inline(always)]
pub(crate) fn sigma_images_per_point<T, D, E, G>(
    x: &OVector<T, D>,
    l: &OMatrix<T, D, D>,
    g: G,
) -> Result<SigmaImages<T, D, E>>
where
    T: RealField + Copy,
    D: Dim,
    E: Dim,
    G: Fn(&OVector<T, D>) -> Result<OVector<T, E>>,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<E> + Allocator<E, D>,
{
    let n = x.nrows();
    check_dim("sigma-point spread", n, l.nrows())?;
    check_dim("sigma-point spread", n, l.ncols())?;
    let center = g(x)?;
    let e = center.shape_generic().0;
    let d = x.shape_generic().0;
    let mut plus = OMatrix::<T, E, D>::zeros_generic(e, d);
    let mut minus = OMatrix::<T, E, D>::zeros_generic(e, d);
    let mut pt = x.clone();
    for j in 0..n {
        for i in j..n {
            pt[i] = x[i] + l[(i, j)];
        }
        let yp = g(&pt)?;
        check_dim("transformed sigma point", e.value(), yp.nrows())?;
        plus.set_column(j, &yp);
        for i in j..n {
            pt[i] = x[i] - l[(i, j)];
        }
        let ym = g(&pt)?;
        check_dim("transformed sigma point", e.value(), ym.nrows())?;
        minus.set_column(j, &ym);
        for i in j..n {
            pt[i] = x[i];
        }
    }
    Ok(SigmaImages {
        center,
        plus,
        minus,
    })
}

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

    /// Checks `Q`: square and symmetric positive semi-definite (the filters call it once,
    /// when they are built). A model whose `Q` is checked when it is made and cannot change
    /// afterwards ([`LinearTransition`]) answers `Ok(())`, so building a filter for every
    /// time step of a track does not check each `Q` twice.
    fn check_process_noise(&self) -> Result<()> {
        let q = self.process_noise();
        check_square(q, self.state_dim(), "Q")?;
        check_psd(q, "Q")
    }

    /// The difference `a - b` of two states; override it for states holding angles (wrap the
    /// angular components). The UKF computes every mean as `x0 + sum_i w_i residual(x_i, x0)`
    /// and every spread with this function, so wrapping here gives correct angular means.
    fn state_residual(&self, a: &OVector<T, D>, b: &OVector<T, D>) -> OVector<T, D> {
        a - b
    }

    /// `f` at the sigma points `x`, `x +- L_j` of a lower-triangular `L` (the UKF's
    /// predict). By default one [`Transition::transition`] call per point; a model may
    /// override it to share work between points (the coordinated turn shares `sin`/`cos`
    /// of the turn angle by the angle-addition formulas). The result must equal the
    /// per-point one up to rounding.
    fn transition_sigma_points(
        &self,
        x: &OVector<T, D>,
        l: &OMatrix<T, D, D>,
    ) -> Result<SigmaImages<T, D, D>> {
        sigma_images_per_point(x, l, |p| self.transition(p))
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

    /// The predicted mean `F x`. By default the dense product; a model with a structured
    /// `F` may override it (the result must equal `F x` up to rounding).
    #[inline(always)]
    fn propagate_mean(&self, x: &OVector<T, D>) -> OVector<T, D> {
        mul_vec(self.transition_matrix(), x)
    }

    /// The predicted covariance `F P F^T + (Q + Q^T) / 2`, exactly symmetric (the lower
    /// triangle is formed and mirrored), for a symmetric `P`. By default the dense
    /// products; a model with a structured `F` may override it (constant velocity and
    /// constant acceleration do, through [`LinearTransition`]'s structure detection).
    #[inline(always)]
    fn propagate_covariance(&self, p: &OMatrix<T, D, D>) -> OMatrix<T, D, D> {
        let f = self.transition_matrix();
        mul_tr_sym_plus(&mul(f, p), f, self.process_noise())
    }

    /// `true` when [`LinearTransitionModel::propagate_covariance`] exploits a structure of
    /// `F` (cheaper than the dense products). The KF then checks `P` by a factorisation of
    /// its own before propagating it; otherwise (the default) it fuses the check with the
    /// dense products (`F L D L^T F^T` from `P = L D L^T`).
    fn has_structured_propagation(&self) -> bool {
        false
    }

    /// `true` promises that [`LinearTransitionModel::propagate_covariance`] returns, for
    /// every input, a matrix whose two triangles are equal bit for bit (one triangle formed
    /// and mirrored, as the default method and [`LinearTransition`] do). The KF's observed
    /// step then proves the prediction finite from the posterior's finiteness (which covers
    /// the lower triangle) without comparing the triangles. `false` by default, so that a
    /// model overriding `propagate_covariance` is checked unless it says otherwise; a model
    /// that returns `true` without mirroring could pass a non-finite upper triangle of the
    /// prediction to the caller without an error.
    ///
    /// A speed hint for the filter driver, hidden from the documented API: a model that does
    /// not know it can ignore it.
    #[doc(hidden)]
    fn mirrors_covariance(&self) -> bool {
        false
    }
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

    /// Checks `R`: square and symmetric positive definite (the filters call it once, when
    /// they are built). A model whose `R` is checked when it is made and cannot change
    /// afterwards ([`LinearObservation`]) answers `Ok(())`.
    fn check_observation_noise(&self) -> Result<()> {
        let r = self.observation_noise();
        check_square(r, self.observation_dim(), "R")?;
        check_pd(r, "R")
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

    /// `h` at the sigma points `x`, `x +- L_j` of a lower-triangular `L` (the UKF's update).
    /// By default one [`Observation::observe`] call per point; a model may override it to
    /// share work between points (range-bearing reuses `h(x)` for the points that do not
    /// move the position). The result must equal the per-point one up to rounding.
    fn observe_sigma_points(
        &self,
        x: &OVector<T, D>,
        l: &OMatrix<T, D, D>,
    ) -> Result<SigmaImages<T, D, M>>
    where
        DefaultAllocator: Allocator<M, D>,
    {
        sigma_images_per_point(x, l, |p| self.observe(p))
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

    /// When every row `a` of `H` is the unit vector selecting state component `idx[a]`
    /// (a position observation), the indices `idx` (one per observation component): the
    /// KF then forms `H x`, `H P` and `H P H^T` by picking components instead of products.
    /// `None` (the default) for a general `H`.
    fn selected_components(&self) -> Option<&[usize]> {
        None
    }
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
    fn check_process_noise(&self) -> Result<()> {
        (**self).check_process_noise()
    }
    fn state_residual(&self, a: &OVector<T, D>, b: &OVector<T, D>) -> OVector<T, D> {
        (**self).state_residual(a, b)
    }
    fn transition_sigma_points(
        &self,
        x: &OVector<T, D>,
        l: &OMatrix<T, D, D>,
    ) -> Result<SigmaImages<T, D, D>> {
        (**self).transition_sigma_points(x, l)
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
    #[inline(always)]
    fn propagate_mean(&self, x: &OVector<T, D>) -> OVector<T, D> {
        (**self).propagate_mean(x)
    }
    #[inline(always)]
    fn propagate_covariance(&self, p: &OMatrix<T, D, D>) -> OMatrix<T, D, D> {
        (**self).propagate_covariance(p)
    }
    fn has_structured_propagation(&self) -> bool {
        (**self).has_structured_propagation()
    }
    #[inline(always)]
    fn mirrors_covariance(&self) -> bool {
        (**self).mirrors_covariance()
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
    fn check_observation_noise(&self) -> Result<()> {
        (**self).check_observation_noise()
    }
    fn observation_residual(&self, a: &OVector<T, M>, b: &OVector<T, M>) -> OVector<T, M> {
        (**self).observation_residual(a, b)
    }
    fn normalize_observation(&self, z: OVector<T, M>) -> OVector<T, M> {
        (**self).normalize_observation(z)
    }
    fn observe_sigma_points(
        &self,
        x: &OVector<T, D>,
        l: &OMatrix<T, D, D>,
    ) -> Result<SigmaImages<T, D, M>>
    where
        DefaultAllocator: Allocator<M, D>,
    {
        (**self).observe_sigma_points(x, l)
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
    fn selected_components(&self) -> Option<&[usize]> {
        (**self).selected_components()
    }
}

mod linear;
pub use linear::{LinearObservation, LinearTransition};

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
    tr.check_process_noise()?;
    ob.check_observation_noise()
}
