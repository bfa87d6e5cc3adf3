//! One state space for constant-velocity, constant-acceleration and coordinated-turn modes of
//! an [`Imm`](crate::imm::Imm): `[x, vx, y, vy, omega, ax, ay]` (positions, velocities, turn
//! rate, accelerations). Every model has continuous white noise, so its `Q` follows the
//! length of the step.
//!
//! - [`constant_velocity`]: the velocities carried, the turn rate kept, the accelerations
//!   set to zero (this mode has none);
//! - [`constant_acceleration`]: the accelerations carried and driven by a white jerk;
//! - [`TurnWithAcceleration`]: [`CoordinatedTurn`] on the first five components, the
//!   accelerations set to zero.
//!
//! A mode that sets a component to zero also zeroes its variance; the IMM's mixing gives each
//! mode its components back from the others' estimates.
//!
//! ```
//! use trajpred_kalman::turn_accel::{constant_acceleration, position_observation};
//! use trajpred_kalman::{Filter, Gaussian, Kf, nalgebra::{SMatrix, SVector}};
//! let ca = Kf::new(constant_acceleration::<f64>(2.0, 0.1)?, position_observation::<f64>(1.0)?)?;
//! // at (0, 0), 1 m/s along x, 0.5 m/s^2 along y: after 2 s, (2, 1)
//! let x = SVector::<f64, 7>::from_column_slice(&[0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.5]);
//! let g = ca.predict(&Gaussian::new(x, SMatrix::identity())?)?;
//! assert_eq!((g.mean[0], g.mean[2]), (2.0, 1.0));
//! # Ok::<(), trajpred_kalman::KalmanError>(())
//! ```

use crate::error::Result;
use crate::model::{LinearObservation, LinearTransition, Transition, TransitionJacobian};
use crate::motion::{CoordinatedTurn, KinematicLayout, StateOrder, kinematic_continuous};
use nalgebra::{Matrix2, OMatrix, OVector, RealField, SMatrix, U3, U4, U7};
use trajpred_core::Error as CoreError;

/// The state size: `[x, vx, y, vy, omega, ax, ay]`.
pub const STATE: usize = 7;

type M7<T> = SMatrix<T, 7, 7>;

/// Index of the position, velocity and acceleration of axis `a` (0: x, 1: y).
const fn idx(a: usize) -> (usize, usize, usize) {
    (2 * a, 2 * a + 1, 5 + a)
}

/// Constant velocity on the seven-state space: the position-velocity blocks of
/// [`kinematic_continuous`] (white acceleration of density `spectral_density`), the turn rate
/// kept without noise, the accelerations set to zero.
pub fn constant_velocity<T: RealField + Copy>(
    dt: f64,
    spectral_density: f64,
) -> Result<LinearTransition<T, U7>> {
    let cv = kinematic_continuous::<T, U4>(
        KinematicLayout::new(2, 2, StateOrder::AxisBlocks)?,
        dt,
        spectral_density,
    )?;
    let (mut f, mut q) = (M7::<T>::zeros(), M7::<T>::zeros());
    f.fixed_view_mut::<4, 4>(0, 0).copy_from(cv.f());
    q.fixed_view_mut::<4, 4>(0, 0).copy_from(cv.q());
    f[(4, 4)] = T::one();
    LinearTransition::new(f, q)
}

/// Constant acceleration on the seven-state space: per axis the blocks of
/// [`kinematic_continuous`] with three derivatives (white jerk of density `jerk_density`),
/// the turn rate kept without noise.
pub fn constant_acceleration<T: RealField + Copy>(
    dt: f64,
    jerk_density: f64,
) -> Result<LinearTransition<T, U7>> {
    let ca = kinematic_continuous::<T, U3>(
        KinematicLayout::new(1, 3, StateOrder::AxisBlocks)?,
        dt,
        jerk_density,
    )?;
    let (mut f, mut q) = (M7::<T>::zeros(), M7::<T>::zeros());
    for a in 0..2 {
        let (p, v, acc) = idx(a);
        let at = [p, v, acc];
        for (i, &r) in at.iter().enumerate() {
            for (j, &c) in at.iter().enumerate() {
                f[(r, c)] = ca.f()[(i, j)];
                q[(r, c)] = ca.q()[(i, j)];
            }
        }
    }
    f[(4, 4)] = T::one();
    LinearTransition::new(f, q)
}

/// The coordinated turn on the seven-state space: [`CoordinatedTurn`] on
/// `[x, vx, y, vy, omega]` (its noise, its Jacobian), the accelerations set to zero.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnWithAcceleration<T: RealField> {
    turn: CoordinatedTurn<T>,
    q: M7<T>,
}

impl<T: RealField + Copy> TurnWithAcceleration<T> {
    /// The seven-state form of `turn`.
    pub fn new(turn: CoordinatedTurn<T>) -> Self {
        let mut q = M7::<T>::zeros();
        q.fixed_view_mut::<5, 5>(0, 0)
            .copy_from(turn.process_noise());
        TurnWithAcceleration { turn, q }
    }
}

impl<T: RealField + Copy> Transition<T, U7> for TurnWithAcceleration<T> {
    fn transition(&self, x: &OVector<T, U7>) -> Result<OVector<T, U7>> {
        let head = self.turn.transition(&x.fixed_rows::<5>(0).into_owned())?;
        let mut out = OVector::<T, U7>::zeros();
        out.fixed_rows_mut::<5>(0).copy_from(&head);
        Ok(out)
    }

    fn process_noise(&self) -> &OMatrix<T, U7, U7> {
        &self.q
    }
}

impl<T: RealField + Copy> TransitionJacobian<T, U7> for TurnWithAcceleration<T> {
    fn transition_jacobian(&self, x: &OVector<T, U7>) -> Result<OMatrix<T, U7, U7>> {
        let j = self
            .turn
            .transition_jacobian(&x.fixed_rows::<5>(0).into_owned())?;
        let mut out = M7::<T>::zeros();
        out.fixed_view_mut::<5, 5>(0, 0).copy_from(&j);
        Ok(out)
    }
}

/// The observation of the position `(x, y)` of the seven-state space, with independent noise
/// of variance `var` per axis.
pub fn position_observation<T: RealField + Copy>(
    var: f64,
) -> Result<LinearObservation<T, U7, nalgebra::U2>> {
    if !(var.is_finite() && var > 0.0) {
        return Err(CoreError::InvalidParameter {
            name: "var",
            reason: format!("observation variance must be finite and positive, got {var}"),
        }
        .into());
    }
    let mut h = SMatrix::<T, 2, 7>::zeros();
    h[(0, 0)] = T::one();
    h[(1, 2)] = T::one();
    LinearObservation::new(h, Matrix2::identity() * nalgebra::convert::<f64, T>(var))
}
