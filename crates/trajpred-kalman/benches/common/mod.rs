//! The inputs shared by the criterion benchmarks (`benches/kalman.rs`) and the timing loop
//! (`examples/profile_step_loop.rs`, which includes this file): the KF problems with their adskalman
//! twins, and the UKF problem.
#![allow(non_snake_case)]

use adskalman::{ObservationModel, StateAndCovariance, TransitionModelLinearNoControl};
use nalgebra::{
    Matrix2, Matrix2x4, Matrix4, Matrix4x2, Matrix5, U2, U4, Vector2, Vector4, Vector5,
};
use trajpred_core::Gaussian;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_velocity, position_observation,
};
use trajpred_kalman::{
    CoordinatedTurn, Kf, LinearObservation, LinearTransition, MerweSigmaPoints, RangeBearing, Ukf,
};

/// adskalman's transition model from our `F` and `Q`.
pub struct AdsTransition {
    f: Matrix4<f64>,
    ft: Matrix4<f64>,
    q: Matrix4<f64>,
}

impl TransitionModelLinearNoControl<f64, U4> for AdsTransition {
    fn F(&self) -> &Matrix4<f64> {
        &self.f
    }
    fn FT(&self) -> &Matrix4<f64> {
        &self.ft
    }
    fn Q(&self) -> &Matrix4<f64> {
        &self.q
    }
}

/// adskalman's observation model from our `H` and `R`.
pub struct AdsObservation {
    h: Matrix2x4<f64>,
    ht: Matrix4x2<f64>,
    r: Matrix2<f64>,
}

impl ObservationModel<f64, U4, U2> for AdsObservation {
    fn H(&self) -> &Matrix2x4<f64> {
        &self.h
    }
    fn HT(&self) -> &Matrix4x2<f64> {
        &self.ht
    }
    fn R(&self) -> &Matrix2<f64> {
        &self.r
    }
}

/// One KF step problem: our filter (Joseph form, default checks), the same models for
/// adskalman (build its filter with `KalmanFilterNoControl::new(&ads_tr, &ads_ob)`), the
/// input state for both and the observation.
pub struct KfCase {
    pub kf: Kf<LinearTransition<f64, U4>, LinearObservation<f64, U4, U2>>,
    pub ads_tr: AdsTransition,
    pub ads_ob: AdsObservation,
    pub state: Gaussian<f64, U4>,
    pub ads_state: StateAndCovariance<f64, U4>,
    pub z: Vector2<f64>,
}

fn kf_case(
    tr: LinearTransition<f64, U4>,
    ob: LinearObservation<f64, U4, U2>,
    z: Vector2<f64>,
) -> KfCase {
    let ads_tr = AdsTransition {
        f: *tr.f(),
        ft: tr.f().transpose(),
        q: *tr.q(),
    };
    let ads_ob = AdsObservation {
        h: *ob.h(),
        ht: ob.h().transpose(),
        r: *ob.r(),
    };
    let mean = Vector4::new(1.0, 0.5, -2.0, 0.3);
    let cov = Matrix4::from_diagonal(&Vector4::new(0.5, 0.2, 0.5, 0.2));
    KfCase {
        kf: Kf::new(tr, ob).expect("filter"),
        ads_tr,
        ads_ob,
        state: Gaussian {
            mean,
            covariance: cov,
        },
        ads_state: StateAndCovariance::new(mean, cov),
        z,
    }
}

/// The benchmark's problem: 2-D constant velocity (`dt = 0.1`, axis blocks) with a position
/// observation.
pub fn cv_case() -> KfCase {
    let tr = constant_velocity(2, 0.1, 0.5, StateOrder::AxisBlocks).expect("model");
    let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks).expect("layout");
    let ob = position_observation(layout, 0.3).expect("model");
    kf_case(tr, ob, Vector2::new(1.07, -1.95))
}

/// The same problem changed so that neither model has the structure the KF exploits:
/// velocities damped by 2 % per step (`F` no longer `I + N`: the dense products and the
/// `L D L^T` check fused with them) and positions measured at twice their scale (`H` not a
/// selection: the products with `H`).
pub fn general_case() -> KfCase {
    let cv: LinearTransition<f64, U4> =
        constant_velocity(2, 0.1, 0.5, StateOrder::AxisBlocks).expect("model");
    let mut f = *cv.f();
    f[(1, 1)] = 0.98;
    f[(3, 3)] = 0.98;
    let mut h = Matrix2x4::zeros();
    h[(0, 0)] = 2.0;
    h[(1, 2)] = 2.0;
    let tr = LinearTransition::new(f, *cv.q()).expect("model");
    let ob = LinearObservation::new(h, Matrix2::identity() * 0.3).expect("model");
    kf_case(tr, ob, Vector2::new(2.14, -3.9))
}

/// The UKF of the benchmark.
pub type CtUkf = Ukf<f64, CoordinatedTurn<f64>, RangeBearing<f64>>;

/// The UKF problem: the 5-state coordinated turn with a range-bearing observation, its input
/// state and observation.
pub fn ukf_case() -> (CtUkf, Gaussian<f64, nalgebra::U5>, Vector2<f64>) {
    let ct = CoordinatedTurn::new(0.5, 0.2, 1e-3).expect("model");
    let rb = RangeBearing::new(Vector2::new(-20.0, 15.0), 0, 2, 0.5, 1e-3).expect("model");
    let ukf = Ukf::new(ct, rb, MerweSigmaPoints::new(0.5, 2.0, -2.0)).expect("filter");
    let state = Gaussian {
        mean: Vector5::new(0.5, 7.0, -0.5, 2.5, 0.1),
        covariance: Matrix5::from_diagonal(&Vector5::new(2.0, 1.0, 2.0, 1.0, 0.01)),
    };
    (ukf, state, Vector2::new(27.4, -0.586))
}
