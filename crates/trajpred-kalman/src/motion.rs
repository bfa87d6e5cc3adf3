//! Motion and sensor models: constant velocity and constant acceleration in 1-3 axes with
//! the discrete white-noise `Q`, the coordinated turn ([`CoordinatedTurn`]) and the
//! range-bearing sensor ([`RangeBearing`]).
//!
//! The kinematic models are generic over the state dimension type `D`: ask for a static
//! size (`nalgebra::U4` for 2-D constant velocity) or `nalgebra::Dyn`; a static size that does
//! not fit the number of axes is a [`trajpred_core::Error::DimensionMismatch`].

use crate::error::Result;
use crate::linalg::{check_dim, check_psd};
use crate::model::{
    LinearObservation, LinearTransition, SigmaImages, Transition, TransitionJacobian,
};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, Matrix5, OMatrix, RealField, U5, Vector5};
use trajpred_core::Error as CoreError;

mod in_place;
mod range_bearing;
pub use in_place::kinematic_continuous_in_place;
pub use range_bearing::{RangeBearing, wrap_angle};

/// How the kinematic state of several axes is laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StateOrder {
    /// One block per axis: `[x, vx, y, vy]` (filterpy's order; `Q` block diagonal). Default.
    #[default]
    AxisBlocks,
    /// All positions, then all velocities (then accelerations): `[x, y, vx, vy]`, the order
    /// of the KF-dynamic paper (`docs/papers.md` B.1).
    PositionsFirst,
}

/// The layout of a kinematic state: `axes` axes, each with `derivatives` components
/// (2: position and velocity; 3: and acceleration), ordered by `order`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KinematicLayout {
    /// Number of axes (1, 2 or 3).
    pub axes: usize,
    /// Components per axis (2 for constant velocity, 3 for constant acceleration).
    pub derivatives: usize,
    /// The ordering of the components.
    pub order: StateOrder,
}

impl KinematicLayout {
    /// A layout; errors with [`trajpred_core::Error::InvalidParameter`] unless `axes` is 1..=3 and
    /// `derivatives` 2 or 3.
    pub fn new(axes: usize, derivatives: usize, order: StateOrder) -> Result<Self> {
        if !(1..=3).contains(&axes) {
            return Err(CoreError::InvalidParameter {
                name: "axes",
                reason: format!("must be 1, 2 or 3, got {axes}"),
            }
            .into());
        }
        if !(2..=3).contains(&derivatives) {
            return Err(CoreError::InvalidParameter {
                name: "derivatives",
                reason: format!("must be 2 (CV) or 3 (CA), got {derivatives}"),
            }
            .into());
        }
        Ok(KinematicLayout {
            axes,
            derivatives,
            order,
        })
    }

    /// The state dimension `axes * derivatives`.
    pub fn state_dim(&self) -> usize {
        self.axes * self.derivatives
    }

    /// The index in the state of derivative `derivative` (0 = position) of axis `axis`.
    #[inline]
    pub fn index(&self, axis: usize, derivative: usize) -> usize {
        match self.order {
            StateOrder::AxisBlocks => axis * self.derivatives + derivative,
            StateOrder::PositionsFirst => derivative * self.axes + axis,
        }
    }
}

/// filterpy's `Q_discrete_white_noise(dim, dt, var)` block for one axis (dim 2 or 3):
/// the piecewise-constant white-noise acceleration model.
fn white_noise_block(derivatives: usize, dt: f64, var: f64) -> [[f64; 3]; 3] {
    let (t2, t3, t4) = (dt * dt, dt * dt * dt, dt * dt * dt * dt);
    if derivatives == 2 {
        [
            [t4 / 4.0 * var, t3 / 2.0 * var, 0.0],
            [t3 / 2.0 * var, t2 * var, 0.0],
            [0.0; 3],
        ]
    } else {
        [
            [t4 / 4.0 * var, t3 / 2.0 * var, t2 / 2.0 * var],
            [t3 / 2.0 * var, t2 * var, dt * var],
            [t2 / 2.0 * var, dt * var, var],
        ]
    }
}

pub(crate) fn check_positive(name: &'static str, v: f64, allow_zero: bool) -> Result<()> {
    let ok = v.is_finite() && (v > 0.0 || (allow_zero && v == 0.0));
    if ok {
        Ok(())
    } else {
        Err(CoreError::InvalidParameter {
            name,
            reason: format!(
                "must be finite and {}, got {v}",
                if allow_zero { ">= 0" } else { "> 0" }
            ),
        }
        .into())
    }
}

fn state_dim_type<D: Dim>(n: usize) -> Result<D> {
    if let Some(s) = D::try_to_usize() {
        check_dim("static state size vs axes", n, s)?;
    }
    Ok(D::from_usize(n))
}

/// The kinematic transition of `layout` for the time step `dt`, with the discrete
/// white-noise process noise of variance `var` per axis (filterpy's
/// `Q_discrete_white_noise`).
pub fn kinematic<T: RealField + Copy, D: Dim>(
    layout: KinematicLayout,
    dt: f64,
    var: f64,
) -> Result<LinearTransition<T, D>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    kinematic_noise(layout, dt, ("var", var), white_noise_block)
}

/// The transition block of one axis: `[[1, dt, dt^2/2], [0, 1, dt], [0, 0, 1]]`.
fn polynomial_block(dt: f64) -> [[f64; 3]; 3] {
    [[1.0, dt, dt * dt / 2.0], [0.0, 1.0, dt], [0.0, 0.0, 1.0]]
}

/// The continuous white-noise block for one axis (filterpy's
/// `Q_continuous_white_noise(dim, dt, spectral_density)`, dim 2 or 3): the exact covariance
/// of a white noise of density `q` on the highest derivative integrated over `dt`.
fn continuous_noise_block(derivatives: usize, dt: f64, q: f64) -> [[f64; 3]; 3] {
    let t = |p: i32| dt.powi(p) * q;
    if derivatives == 2 {
        [
            [t(3) / 3.0, t(2) / 2.0, 0.0],
            [t(2) / 2.0, t(1), 0.0],
            [0.0; 3],
        ]
    } else {
        [
            [t(5) / 20.0, t(4) / 8.0, t(3) / 6.0],
            [t(4) / 8.0, t(3) / 3.0, t(2) / 2.0],
            [t(3) / 6.0, t(2) / 2.0, t(1)],
        ]
    }
}

/// The kinematic transition of `layout` for the time step `dt`, with the process noise of a
/// continuous white noise of spectral density `spectral_density` on the highest derivative
/// (acceleration for constant velocity, jerk for constant acceleration), per axis
/// (filterpy's `Q_continuous_white_noise`). Unlike the discrete model of [`kinematic`], two
/// steps of `dt / 2` give the same prediction as one step of `dt`, so a track sampled at
/// irregular times gets the noise its intervals call for.
///
/// ```
/// use nalgebra::U2;
/// use trajpred_kalman::motion::{KinematicLayout, StateOrder, kinematic_continuous};
/// use trajpred_kalman::{LinearTransitionModel, Transition};
/// let cv = kinematic_continuous::<f64, U2>(KinematicLayout::new(1, 2, StateOrder::PositionsFirst)?, 2.0, 3.0)?;
/// // q [[dt^3/3, dt^2/2], [dt^2/2, dt]] with q = 3, dt = 2
/// assert_eq!(cv.process_noise()[(0, 0)], 8.0);
/// assert_eq!(cv.process_noise()[(0, 1)], 6.0);
/// assert_eq!(cv.process_noise()[(1, 1)], 6.0);
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
#[inline]
pub fn kinematic_continuous<T: RealField + Copy, D: Dim>(
    layout: KinematicLayout,
    dt: f64,
    spectral_density: f64,
) -> Result<LinearTransition<T, D>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    kinematic_noise(
        layout,
        dt,
        ("spectral_density", spectral_density),
        continuous_noise_block,
    )
}

/// The kinematic transition of `layout` for `dt` with the noise block `noise(derivatives,
/// dt, level)`, after checking `dt > 0` and the named noise level `>= 0`.
#[inline]
fn kinematic_noise<T, D>(
    layout: KinematicLayout,
    dt: f64,
    (name, level): (&'static str, f64),
    noise: fn(usize, f64, f64) -> [[f64; 3]; 3],
) -> Result<LinearTransition<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    check_positive("dt", dt, false)?;
    check_positive(name, level, true)?;
    kinematic_with(
        layout,
        polynomial_block(dt),
        noise(layout.derivatives, dt, level),
    )
}

/// Damped velocity (the integrated Ornstein-Uhlenbeck model): per axis the velocity relaxes
/// towards zero with time constant `time_constant` seconds while a continuous white noise of
/// density `spectral_density` drives it; the position integrates it. With `beta = 1 / tau`
/// and `e = exp(-beta dt)`:
///
/// ```text
/// F = [[1, (1 - e) / beta], [0, e]]
/// Q = q [[(dt - 2 (1 - e) / beta + (1 - e^2) / (2 beta)) / beta^2, (1 - e)^2 / (2 beta^2)],
///        [(1 - e)^2 / (2 beta^2),                                  (1 - e^2) / (2 beta)]]
/// ```
///
/// (the position variance by its series
/// `dt^3 (1/3 - beta dt/4 + 7 (beta dt)^2/60 - (beta dt)^3/24)` when `beta dt < 0.01`, where
/// the closed form cancels). As `tau` grows it becomes
/// [`kinematic_continuous`]'s constant velocity; a forecast's displacement is bounded by
/// `v tau`, which suits targets that slow down and stop.
///
/// ```
/// use nalgebra::U2;
/// use trajpred_kalman::motion::{KinematicLayout, StateOrder, damped_velocity, kinematic_continuous};
/// use trajpred_kalman::{LinearTransitionModel, Transition};
/// let l = KinematicLayout::new(1, 2, StateOrder::AxisBlocks)?;
/// let damped = damped_velocity::<f64, U2>(l, 2.0, 1.0, 1e9)?;
/// let cv = kinematic_continuous::<f64, U2>(l, 2.0, 1.0)?;
/// assert!((damped.f() - cv.f()).abs().max() < 1e-8);
/// assert!((damped.process_noise() - cv.process_noise()).abs().max() < 1e-8);
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
pub fn damped_velocity<T: RealField + Copy, D: Dim>(
    layout: KinematicLayout,
    dt: f64,
    spectral_density: f64,
    time_constant: f64,
) -> Result<LinearTransition<T, D>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    check_positive("dt", dt, false)?;
    check_positive("spectral_density", spectral_density, true)?;
    check_positive("time_constant", time_constant, false)?;
    if layout.derivatives != 2 {
        return Err(CoreError::InvalidParameter {
            name: "layout",
            reason: format!(
                "damped velocity has 2 derivatives per axis, got {}",
                layout.derivatives
            ),
        }
        .into());
    }
    let (q, beta) = (spectral_density, 1.0 / time_constant);
    let bdt = beta * dt;
    let one_minus_e = -(-bdt).exp_m1();
    let e = 1.0 - one_minus_e;
    let var_x = if bdt < 0.01 {
        q * dt.powi(3) * (1.0 / 3.0 - bdt / 4.0 + 7.0 * bdt * bdt / 60.0 - bdt.powi(3) / 24.0)
    } else {
        q / (beta * beta) * (dt - 2.0 * one_minus_e / beta - (-2.0 * bdt).exp_m1() / (2.0 * beta))
    };
    let cov_xv = q * one_minus_e * one_minus_e / (2.0 * beta * beta);
    let var_v = -q * (-2.0 * bdt).exp_m1() / (2.0 * beta);
    kinematic_with(
        layout,
        [[1.0, one_minus_e / beta, 0.0], [0.0, e, 0.0], [0.0; 3]],
        [[var_x, cov_xv, 0.0], [cov_xv, var_v, 0.0], [0.0; 3]],
    )
}

#[inline]
fn kinematic_with<T, D>(
    layout: KinematicLayout,
    f_block: [[f64; 3]; 3],
    q_block: [[f64; 3]; 3],
) -> Result<LinearTransition<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let n = layout.state_dim();
    let d: D = state_dim_type(n)?;
    let k = layout.derivatives;
    let mut f = OMatrix::<T, D, D>::zeros_generic(d, d);
    let mut q = OMatrix::<T, D, D>::zeros_generic(d, d);
    for axis in 0..layout.axes {
        for (i, q_row) in q_block.iter().enumerate().take(k) {
            for (j, &qv) in q_row.iter().enumerate().take(k) {
                let (r, c) = (layout.index(axis, i), layout.index(axis, j));
                f[(r, c)] = nalgebra::convert(f_block[i][j]);
                q[(r, c)] = nalgebra::convert(qv);
            }
        }
    }
    LinearTransition::from_kinematic_blocks(layout, f_block, q_block, f, q)
}

/// Constant velocity in `axes` axes (state `2 * axes`) for the time step `dt` and the
/// white-noise acceleration variance `var`.
///
/// ```
/// use nalgebra::{Vector4, U4};
/// use trajpred_kalman::{motion::{constant_velocity, StateOrder}, Transition};
/// let cv = constant_velocity::<f64, U4>(2, 0.5, 1.0, StateOrder::PositionsFirst)?;
/// // [x, y, vx, vy] = [0, 0, 2, -2] moves to [1, -1, 2, -2] in 0.5 s
/// assert_eq!(cv.transition(&Vector4::new(0.0, 0.0, 2.0, -2.0))?, Vector4::new(1.0, -1.0, 2.0, -2.0));
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
pub fn constant_velocity<T: RealField + Copy, D: Dim>(
    axes: usize,
    dt: f64,
    var: f64,
    order: StateOrder,
) -> Result<LinearTransition<T, D>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    kinematic(KinematicLayout::new(axes, 2, order)?, dt, var)
}

/// Constant acceleration in `axes` axes (state `3 * axes`) for the time step `dt` and the
/// white-noise jerk variance `var`.
pub fn constant_acceleration<T: RealField + Copy, D: Dim>(
    axes: usize,
    dt: f64,
    var: f64,
    order: StateOrder,
) -> Result<LinearTransition<T, D>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    kinematic(KinematicLayout::new(axes, 3, order)?, dt, var)
}

/// The observation of the positions of a kinematic state (`m = axes`), with independent
/// noise of variance `var` per axis: `R = var I`.
pub fn position_observation<T, D, M>(
    layout: KinematicLayout,
    var: f64,
) -> Result<LinearObservation<T, D, M>>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    check_positive("var", var, false)?;
    let d: D = state_dim_type(layout.state_dim())?;
    if let Some(s) = M::try_to_usize() {
        check_dim("static observation size vs axes", layout.axes, s)?;
    }
    let m = M::from_usize(layout.axes);
    let mut h = OMatrix::<T, M, D>::zeros_generic(m, d);
    for axis in 0..layout.axes {
        h[(axis, layout.index(axis, 0))] = T::one();
    }
    let r = OMatrix::<T, M, M>::identity_generic(m, m) * nalgebra::convert::<f64, T>(var);
    LinearObservation::new(h, r)
}

// ---- coordinated turn -----------------------------------------------------------------------

/// The coordinated turn with unknown turn rate: state `[x, vx, y, vy, omega]`
/// (positions, velocities, turn rate in rad/s), time step `dt`:
///
/// ```text
/// x'  = x + sin(w T)/w vx - (1 - cos(w T))/w vy      vx' = cos(w T) vx - sin(w T) vy
/// y'  = y + (1 - cos(w T))/w vx + sin(w T)/w vy      vy' = sin(w T) vx + cos(w T) vy
/// w'  = w
/// ```
///
/// with the limits `sin(wT)/w -> T`, `(1 - cos(wT))/w -> 0` as `w -> 0` (a series is used for
/// `|w T| < 1e-2`, so the model and its Jacobian are smooth through straight flight).
#[derive(Debug, Clone, PartialEq)]
pub struct CoordinatedTurn<T: RealField> {
    dt: T,
    q: Matrix5<T>,
}

impl<T: RealField + Copy> CoordinatedTurn<T> {
    /// The model with Bar-Shalom's noise: white acceleration of variance `accel_var` on each
    /// axis (blocks `[[T^4/4, T^3/2], [T^3/2, T^2]] accel_var`) and a turn-rate increment of
    /// variance `T^2 turn_rate_var`.
    pub fn new(dt: f64, accel_var: f64, turn_rate_var: f64) -> Result<Self> {
        check_positive("dt", dt, false)?;
        check_positive("accel_var", accel_var, true)?;
        check_positive("turn_rate_var", turn_rate_var, true)?;
        let b = white_noise_block(2, dt, accel_var);
        let mut q = Matrix5::<T>::zeros();
        for o in [0usize, 2] {
            for (i, row) in b.iter().enumerate().take(2) {
                for (j, &v) in row.iter().enumerate().take(2) {
                    q[(o + i, o + j)] = nalgebra::convert(v);
                }
            }
        }
        q[(4, 4)] = nalgebra::convert(dt * dt * turn_rate_var);
        Self::with_process_noise(dt, q)
    }

    /// The model with any process noise `Q` (symmetric positive semi-definite).
    pub fn with_process_noise(dt: f64, q: Matrix5<T>) -> Result<Self> {
        check_positive("dt", dt, false)?;
        check_psd(&q, "Q")?;
        Ok(CoordinatedTurn {
            dt: nalgebra::convert(dt),
            q,
        })
    }

    /// `(sin(wT)/w, (1-cos(wT))/w, cos(wT), sin(wT))`: the part of
    /// [`CoordinatedTurn::coefficients`] that `f(x)` needs (the same expressions, without the
    /// derivatives and their divisions; the UKF calls it for every sigma point).
    #[inline(always)]
    fn transition_coefficients(&self, w: T) -> [T; 4] {
        let (s, c) = (w * self.dt).sin_cos();
        self.transition_coefficients_from(w, s, c)
    }

    /// [`CoordinatedTurn::transition_coefficients`] from `sin(wT)`, `cos(wT)` computed by the
    /// caller.
    #[inline(always)]
    fn transition_coefficients_from(&self, w: T, s: T, c: T) -> [T; 4] {
        let t = self.dt;
        let wt = w * t;
        let k = |v: f64| nalgebra::convert::<f64, T>(v);
        if wt.abs() < k(1e-2) {
            let x = wt;
            let x2 = x * x;
            [
                t * (T::one()
                    - x2 / k(6.0) * (T::one() - x2 / k(20.0) * (T::one() - x2 / k(42.0)))),
                t * x
                    * (k(0.5)
                        - x2 / k(24.0) * (T::one() - x2 / k(30.0) * (T::one() - x2 / k(56.0)))),
                c,
                s,
            ]
        } else {
            let one_minus_c = if c > T::zero() {
                s * s / (T::one() + c)
            } else {
                T::one() - c
            };
            [s / w, one_minus_c / w, c, s]
        }
    }

    /// `(sin(wT)/w, (1-cos(wT))/w, d/dw of both, cos(wT), sin(wT))`.
    fn coefficients(&self, w: T) -> [T; 6] {
        let t = self.dt;
        let wt = w * t;
        let (s, c) = wt.sin_cos();
        let k = |v: f64| nalgebra::convert::<f64, T>(v);
        if wt.abs() < k(1e-2) {
            // Taylor series in x = wT (truncation below 1e-20 relative for |x| < 1e-2);
            // the closed forms lose about eps / x^2 to cancellation there.
            let x = wt;
            let x2 = x * x;
            let t2 = t * t;
            [
                t * (T::one()
                    - x2 / k(6.0) * (T::one() - x2 / k(20.0) * (T::one() - x2 / k(42.0)))),
                t * x
                    * (k(0.5)
                        - x2 / k(24.0) * (T::one() - x2 / k(30.0) * (T::one() - x2 / k(56.0)))),
                t2 * x * (-T::one() / k(3.0) + x2 / k(30.0) - x2 * x2 / k(840.0)),
                t2 * (k(0.5) - x2 / k(8.0) + x2 * x2 / k(144.0) - x2 * x2 * x2 / k(5760.0)),
                c,
                s,
            ]
        } else {
            let w2 = w * w;
            // 1 - cos(wT) without cancellation: sin^2 / (1 + cos) while cos > 0
            let one_minus_c = if c > T::zero() {
                s * s / (T::one() + c)
            } else {
                T::one() - c
            };
            [
                s / w,
                one_minus_c / w,
                (wt * c - s) / w2,
                (wt * s - one_minus_c) / w2,
                c,
                s,
            ]
        }
    }
}

impl<T: RealField + Copy> CoordinatedTurn<T> {
    /// `f(x)` from the coefficients of `x[4]`.
    #[inline(always)]
    fn apply(x: &Vector5<T>, [a, b, c, s]: [T; 4]) -> Vector5<T> {
        let (vx, vy) = (x[1], x[3]);
        Vector5::new(
            x[0] + a * vx - b * vy,
            c * vx - s * vy,
            x[2] + b * vx + a * vy,
            s * vx + c * vy,
            x[4],
        )
    }
}

impl<T: RealField + Copy> Transition<T, U5> for CoordinatedTurn<T> {
    fn transition(&self, x: &Vector5<T>) -> Result<Vector5<T>> {
        Ok(Self::apply(x, self.transition_coefficients(x[4])))
    }
    fn process_noise(&self) -> &Matrix5<T> {
        &self.q
    }

    /// The sigma points' turn rates are `w +- d_j` (`d_j = L[4, j]`): their `sin`/`cos`
    /// follow from `sin_cos(w T)` (once) and `sin_cos(d_j T)` by the angle-addition
    /// formulas, and a pair with `d_j = 0` (every column of `L` before the last when the
    /// turn rate is uncorrelated with the rest) uses the centre's values exactly. At most
    /// `n + 1 = 6` `sin_cos` calls instead of `2n + 1 = 11`.
    fn transition_sigma_points(
        &self,
        x: &Vector5<T>,
        l: &Matrix5<T>,
    ) -> Result<SigmaImages<T, U5, U5>> {
        let w0 = x[4];
        let (s0, c0) = (w0 * self.dt).sin_cos();
        let center = Self::apply(x, self.transition_coefficients_from(w0, s0, c0));
        let mut plus = Matrix5::<T>::zeros();
        let mut minus = Matrix5::<T>::zeros();
        for j in 0..5 {
            let col = l.column(j);
            let (xp, xm) = (x + col, x - col);
            let d = col[4];
            let (cp, cm) = if d == T::zero() {
                let k = self.transition_coefficients_from(w0, s0, c0);
                (k, k)
            } else {
                let (sd, cd) = (d * self.dt).sin_cos();
                // sin(a +- b) = sin a cos b +- cos a sin b, cos(a +- b) = cos a cos b -+ sin a sin b
                let (sa, sb) = (s0 * cd, c0 * sd);
                let (ca, cb) = (c0 * cd, s0 * sd);
                (
                    self.transition_coefficients_from(xp[4], sa + sb, ca - cb),
                    self.transition_coefficients_from(xm[4], sa - sb, ca + cb),
                )
            };
            plus.set_column(j, &Self::apply(&xp, cp));
            minus.set_column(j, &Self::apply(&xm, cm));
        }
        Ok(SigmaImages {
            center,
            plus,
            minus,
        })
    }
}

impl<T: RealField + Copy> TransitionJacobian<T, U5> for CoordinatedTurn<T> {
    fn transition_jacobian(&self, x: &Vector5<T>) -> Result<Matrix5<T>> {
        let [a, b, da, db, c, s] = self.coefficients(x[4]);
        let (vx, vy) = (x[1], x[3]);
        let t = self.dt;
        let (o, z) = (T::one(), T::zero());
        Ok(Matrix5::new(
            o,
            a,
            z,
            -b,
            da * vx - db * vy, //
            z,
            c,
            z,
            -s,
            -t * (s * vx + c * vy), //
            z,
            b,
            o,
            a,
            db * vx + da * vy, //
            z,
            s,
            z,
            c,
            t * (c * vx - s * vy), //
            z,
            z,
            z,
            z,
            o,
        ))
    }
}
