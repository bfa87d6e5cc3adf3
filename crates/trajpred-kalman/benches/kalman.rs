//! Criterion benchmarks of the hot paths, each beside a peer measured in the same run:
//!
//! - `kf_step_cv4_pos2`: one KF predict + update (Joseph form), 2-D constant velocity
//!   (4 states) with a 2-D position observation, trajpred vs adskalman 0.18 (Joseph form);
//! - `kf_step_general_cv4_pos2`: the same step with models that have neither structure the
//!   KF exploits (a damped constant velocity, positions measured at twice their scale), so
//!   both filters take their general products;
//! - `ukf_step_ct5_rb2`: one UKF predict + update on the 5-state coordinated turn with a
//!   range-bearing observation (filterpy's figure for the same step comes from
//!   `benches/filterpy_ukf_step.py`).
#![allow(non_snake_case)]

use adskalman::{
    CovarianceUpdateMethod, KalmanFilterNoControl, ObservationModel, StateAndCovariance,
    TransitionModelLinearNoControl,
};
use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{
    Matrix2, Matrix2x4, Matrix4, Matrix4x2, Matrix5, U2, U4, Vector2, Vector4, Vector5,
};
use std::hint::black_box;
use trajpred_core::Gaussian;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_velocity, position_observation,
};
use trajpred_kalman::{
    CoordinatedTurn, Filter, InputChecks, Kf, LinearObservation, LinearTransition,
    MerweSigmaPoints, RangeBearing, Ukf,
};

struct AdsTransition {
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

struct AdsObservation {
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

fn kf_step(c: &mut Criterion) {
    let dt = 0.1;
    let tr: LinearTransition<f64, U4> =
        constant_velocity(2, dt, 0.5, StateOrder::AxisBlocks).expect("model");
    let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks).expect("layout");
    let ob: LinearObservation<f64, U4, U2> = position_observation(layout, 0.3).expect("model");
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
    let kf = Kf::new(tr, ob).expect("filter");
    let kf_cheap = kf.clone().with_input_checks(InputChecks::Cheap);
    let ads = KalmanFilterNoControl::new(&ads_tr, &ads_ob);
    let mean = Vector4::new(1.0, 0.5, -2.0, 0.3);
    let cov = Matrix4::from_diagonal(&Vector4::new(0.5, 0.2, 0.5, 0.2));
    let state = Gaussian {
        mean,
        covariance: cov,
    };
    let ads_state = StateAndCovariance::new(mean, cov);
    let z = Vector2::new(1.07, -1.95);

    let mut g = c.benchmark_group("kf_step_cv4_pos2");
    g.bench_function("trajpred_joseph", |b| {
        b.iter(|| {
            let s = kf
                .step(black_box(&state), Some(black_box(&z)))
                .expect("step");
            black_box(&s);
        })
    });
    g.bench_function("trajpred_joseph_cheap_input_checks", |b| {
        b.iter(|| {
            let s = kf_cheap
                .step(black_box(&state), Some(black_box(&z)))
                .expect("step");
            black_box(&s);
        })
    });
    g.bench_function("trajpred_predict_only", |b| {
        b.iter(|| {
            let prior = kf.predict(black_box(&state)).expect("predict");
            black_box(&prior);
        })
    });
    g.bench_function("trajpred_update_only", |b| {
        b.iter(|| {
            let update = kf
                .update_predicted(black_box(&state), black_box(&z))
                .expect("update");
            black_box(&update);
        })
    });
    g.bench_function("adskalman_predict_only", |b| {
        b.iter(|| {
            let prior = ads_tr.predict(black_box(&ads_state));
            black_box(&prior);
        })
    });
    g.bench_function("adskalman_update_only", |b| {
        b.iter(|| {
            let posterior = ads_ob
                .update(
                    black_box(&ads_state),
                    black_box(&z),
                    CovarianceUpdateMethod::JosephForm,
                )
                .expect("update");
            black_box(&posterior);
        })
    });
    g.bench_function("adskalman_joseph", |b| {
        b.iter(|| {
            let posterior = ads
                .step_with_options(
                    black_box(&ads_state),
                    black_box(&z),
                    CovarianceUpdateMethod::JosephForm,
                )
                .expect("step");
            black_box(&posterior);
        })
    });
    g.finish();
}

/// The CV models of `kf_step` changed so that neither has the structure the KF exploits:
/// velocities damped by 2 % per step (`F` no longer `I + N`, the dense products and the
/// `L D L^T` check fused with them) and positions measured at twice their scale (`H` not a
/// selection, the products with `H`).
fn general_models() -> (
    LinearTransition<f64, U4>,
    LinearObservation<f64, U4, U2>,
    AdsTransition,
    AdsObservation,
) {
    let cv: LinearTransition<f64, U4> =
        constant_velocity(2, 0.1, 0.5, StateOrder::AxisBlocks).expect("model");
    let mut f = *cv.f();
    f[(1, 1)] = 0.98;
    f[(3, 3)] = 0.98;
    let tr = LinearTransition::new(f, *cv.q()).expect("model");
    let mut h = Matrix2x4::zeros();
    h[(0, 0)] = 2.0;
    h[(1, 2)] = 2.0;
    let ob = LinearObservation::new(h, Matrix2::identity() * 0.3).expect("model");
    let ads_tr = AdsTransition {
        f,
        ft: f.transpose(),
        q: *tr.q(),
    };
    let ads_ob = AdsObservation {
        h,
        ht: h.transpose(),
        r: *ob.r(),
    };
    (tr, ob, ads_tr, ads_ob)
}

fn kf_step_general(c: &mut Criterion) {
    let (tr, ob, ads_tr, ads_ob) = general_models();
    let kf = Kf::new(tr, ob).expect("filter");
    let ads = KalmanFilterNoControl::new(&ads_tr, &ads_ob);
    let mean = Vector4::new(1.0, 0.5, -2.0, 0.3);
    let cov = Matrix4::from_diagonal(&Vector4::new(0.5, 0.2, 0.5, 0.2));
    let state = Gaussian {
        mean,
        covariance: cov,
    };
    let ads_state = StateAndCovariance::new(mean, cov);
    let z = Vector2::new(2.14, -3.9);
    let mut g = c.benchmark_group("kf_step_general_cv4_pos2");
    g.bench_function("trajpred_joseph", |b| {
        b.iter(|| {
            let s = kf
                .step(black_box(&state), Some(black_box(&z)))
                .expect("step");
            black_box(&s);
        })
    });
    g.bench_function("adskalman_joseph", |b| {
        b.iter(|| {
            let posterior = ads
                .step_with_options(
                    black_box(&ads_state),
                    black_box(&z),
                    CovarianceUpdateMethod::JosephForm,
                )
                .expect("step");
            black_box(&posterior);
        })
    });
    g.finish();
}

fn ukf_step(c: &mut Criterion) {
    let ct = CoordinatedTurn::new(0.5, 0.2, 1e-3).expect("model");
    let rb = RangeBearing::new(Vector2::new(-20.0, 15.0), 0, 2, 0.5, 1e-3).expect("model");
    let ukf = Ukf::new(ct, rb, MerweSigmaPoints::new(0.5, 2.0, -2.0)).expect("filter");

    let state = Gaussian {
        mean: Vector5::new(0.5, 7.0, -0.5, 2.5, 0.1),
        covariance: Matrix5::from_diagonal(&Vector5::new(2.0, 1.0, 2.0, 1.0, 0.01)),
    };
    let z = Vector2::new(27.4, -0.586);
    let mut g = c.benchmark_group("ukf_step_ct5_rb2");
    g.bench_function("trajpred", |b| {
        b.iter(|| {
            let s = ukf
                .step(black_box(&state), Some(black_box(&z)))
                .expect("step");
            black_box(&s);
        })
    });
    g.finish();
}

criterion_group!(benches, kf_step, kf_step_general, ukf_step);
criterion_main!(benches);
