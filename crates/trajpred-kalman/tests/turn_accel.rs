//! The seven-state models of `turn_accel` (`[x, vx, y, vy, omega, ax, ay]`) worked by hand
//! and against the five-state coordinated turn they embed.

use nalgebra::{SMatrix, SVector, Vector5};
use trajpred_kalman::imm::coordinated_turn_continuous;
use trajpred_kalman::turn_accel::{
    TurnWithAcceleration, constant_acceleration, constant_velocity, position_observation,
};
use trajpred_kalman::{
    KalmanError, LinearObservationModel, LinearTransitionModel, Transition, TransitionJacobian,
};

/// dt = 2, jerk density q = 3: per axis `F = [[1, 2, 2], [0, 1, 2], [0, 0, 1]]` and
/// `Q = q [[dt^5/20, dt^4/8, dt^3/6], [dt^4/8, dt^3/3, dt^2/2], [dt^3/6, dt^2/2, dt]]`
/// `= [[4.8, 6, 4], [6, 8, 6], [4, 6, 6]]`, on (x, vx, ax) = (0, 1, 5) and (y, vy, ay) =
/// (2, 3, 6); the turn rate kept.
#[test]
fn constant_acceleration_by_hand() {
    let m = constant_acceleration::<f64>(2.0, 3.0).unwrap();
    let (f, q) = (m.transition_matrix(), m.process_noise());
    let fb = [[1.0, 2.0, 2.0], [0.0, 1.0, 2.0], [0.0, 0.0, 1.0]];
    let qb = [[4.8, 6.0, 4.0], [6.0, 8.0, 6.0], [4.0, 6.0, 6.0]];
    let mut want_f = SMatrix::<f64, 7, 7>::zeros();
    let mut want_q = SMatrix::<f64, 7, 7>::zeros();
    want_f[(4, 4)] = 1.0;
    for at in [[0, 1, 5], [2, 3, 6]] {
        for i in 0..3 {
            for j in 0..3 {
                want_f[(at[i], at[j])] = fb[i][j];
                want_q[(at[i], at[j])] = qb[i][j];
            }
        }
    }
    assert_eq!(*f, want_f);
    assert!((q - want_q).abs().max() < 1e-12, "{q}");
}

/// dt = 2, acceleration density q = 3: `F` moves positions by `2 v`, keeps the turn rate,
/// zeroes the accelerations; `Q = q [[dt^3/3, dt^2/2], [dt^2/2, dt]]` per axis.
#[test]
fn constant_velocity_by_hand() {
    let m = constant_velocity::<f64>(2.0, 3.0).unwrap();
    let x = SVector::<f64, 7>::from_column_slice(&[1.0, 2.0, 3.0, 4.0, 0.5, 7.0, 8.0]);
    let fx = m.transition_matrix() * x;
    assert_eq!(fx.as_slice(), &[5.0, 2.0, 11.0, 4.0, 0.5, 0.0, 0.0]);
    let q = m.process_noise();
    assert_eq!((q[(0, 0)], q[(0, 1)], q[(1, 1)]), (8.0, 6.0, 6.0));
    assert_eq!((q[(2, 2)], q[(2, 3)], q[(3, 3)]), (8.0, 6.0, 6.0));
    assert_eq!(q.fixed_view::<3, 7>(4, 0).abs().max(), 0.0);
}

/// The seven-state turn is the five-state coordinated turn on `[x, vx, y, vy, omega]`
/// (mean, Jacobian, noise) with the accelerations zeroed.
#[test]
fn the_turn_embeds_the_coordinated_turn() {
    let turn = coordinated_turn_continuous::<f64>(1.5, 2.0, 1e-3).unwrap();
    let seven = TurnWithAcceleration::new(turn.clone());
    let x5 = Vector5::new(1.0, 10.0, -2.0, 4.0, 0.2);
    let x7 = SVector::<f64, 7>::from_column_slice(&[1.0, 10.0, -2.0, 4.0, 0.2, 3.0, -1.0]);
    let (f5, f7) = (
        turn.transition(&x5).unwrap(),
        seven.transition(&x7).unwrap(),
    );
    assert_eq!(f7.fixed_rows::<5>(0), f5);
    assert_eq!((f7[5], f7[6]), (0.0, 0.0));
    let (j5, j7) = (
        turn.transition_jacobian(&x5).unwrap(),
        seven.transition_jacobian(&x7).unwrap(),
    );
    assert_eq!(j7.fixed_view::<5, 5>(0, 0), j5);
    assert_eq!(j7.fixed_view::<2, 7>(5, 0).abs().max(), 0.0);
    assert_eq!(j7.fixed_view::<7, 2>(0, 5).abs().max(), 0.0);
    assert_eq!(
        seven.process_noise().fixed_view::<5, 5>(0, 0),
        *turn.process_noise()
    );
    // the observation picks x and y
    let h = position_observation::<f64>(4.0).unwrap();
    assert_eq!((h.observation_matrix() * x7).as_slice(), &[1.0, -2.0]);
    assert!(matches!(
        position_observation::<f64>(0.0),
        Err(KalmanError::Core(_))
    ));
    assert!(constant_acceleration::<f64>(-1.0, 1.0).is_err());
}
