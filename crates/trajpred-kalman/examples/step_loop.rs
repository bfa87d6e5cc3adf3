//! A timing loop over the benchmark's inputs, for instruction counts under callgrind
//! (load-independent) and a quick wall-clock figure:
//!
//! ```text
//! cargo build --release -p trajpred-kalman --example step_loop
//! valgrind --tool=callgrind target/release/examples/step_loop kf 10000
//! ```
//!
//! The first argument picks the loop (`kf`, `kf_cheap`, `kf_predict`, `kf_update`, `ads`,
//! `ads_predict`, `ads_update`, `kf_general` and `ads_general` (a damped constant velocity
//! and positions measured at twice their scale: no structure for the KF to exploit), `ukf`, `ukf_corr` (a correlated input state), `ukf_predict`,
//! `ukf_update`, `none`), the second the
//! number of steps. Instructions per step: the difference of two runs with different step
//! counts divided by the difference of the counts (`none` measures the fixed overhead).
#![allow(non_snake_case)]

use adskalman::{
    CovarianceUpdateMethod, KalmanFilterNoControl, ObservationModel, StateAndCovariance,
    TransitionModelLinearNoControl,
};
use nalgebra::{
    Matrix2, Matrix2x4, Matrix4, Matrix4x2, Matrix5, U2, U4, Vector2, Vector4, Vector5,
};
use std::hint::black_box;
use std::time::Instant;
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

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map(String::as_str).unwrap_or("kf");
    let steps: usize = args
        .get(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);

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

    // the general models of the benchmark `kf_step_general_cv4_pos2`
    let mut f = *kf.transition().f();
    f[(1, 1)] = 0.98;
    f[(3, 3)] = 0.98;
    let mut h = Matrix2x4::zeros();
    h[(0, 0)] = 2.0;
    h[(1, 2)] = 2.0;
    let gen_tr = LinearTransition::new(f, *kf.transition().q()).expect("model");
    let gen_ob = LinearObservation::new(h, Matrix2::identity() * 0.3).expect("model");
    let gen_ads_tr = AdsTransition {
        f,
        ft: f.transpose(),
        q: *gen_tr.q(),
    };
    let gen_ads_ob = AdsObservation {
        h,
        ht: h.transpose(),
        r: *gen_ob.r(),
    };
    let kf_general = Kf::new(gen_tr, gen_ob).expect("filter");
    let ads_general = KalmanFilterNoControl::new(&gen_ads_tr, &gen_ads_ob);
    let gz = Vector2::new(2.14, -3.9);

    let ct = CoordinatedTurn::new(0.5, 0.2, 1e-3).expect("model");
    let rb = RangeBearing::new(Vector2::new(-20.0, 15.0), 0, 2, 0.5, 1e-3).expect("model");
    let ukf = Ukf::new(ct, rb, MerweSigmaPoints::new(0.5, 2.0, -2.0)).expect("filter");
    let ustate = Gaussian {
        mean: Vector5::new(0.5, 7.0, -0.5, 2.5, 0.1),
        covariance: Matrix5::from_diagonal(&Vector5::new(2.0, 1.0, 2.0, 1.0, 0.01)),
    };
    let uz = Vector2::new(27.4, -0.586);
    // a state whose turn rate is correlated with the rest (the posterior of one step): every
    // sigma-point pair then moves the turn rate
    let ustate_corr = ukf
        .step(&ustate, Some(&uz))
        .expect("step")
        .posterior()
        .clone();

    let t0 = Instant::now();
    for _ in 0..steps {
        match which {
            "kf" => {
                let s = kf
                    .step(black_box(&state), Some(black_box(&z)))
                    .expect("step");
                black_box(&s);
            }
            "kf_cheap" => {
                let s = kf_cheap
                    .step(black_box(&state), Some(black_box(&z)))
                    .expect("step");
                black_box(&s);
            }
            "kf_predict" => {
                black_box(&kf.predict(black_box(&state)).expect("predict"));
            }
            "kf_update" => {
                black_box(
                    &kf.update_predicted(black_box(&state), black_box(&z))
                        .expect("update"),
                );
            }
            "ads" => {
                black_box(
                    &ads.step_with_options(
                        black_box(&ads_state),
                        black_box(&z),
                        CovarianceUpdateMethod::JosephForm,
                    )
                    .expect("step"),
                );
            }
            "kf_general" => {
                let s = kf_general
                    .step(black_box(&state), Some(black_box(&gz)))
                    .expect("step");
                black_box(&s);
            }
            "ads_general" => {
                black_box(
                    &ads_general
                        .step_with_options(
                            black_box(&ads_state),
                            black_box(&gz),
                            CovarianceUpdateMethod::JosephForm,
                        )
                        .expect("step"),
                );
            }
            "ads_predict" => {
                black_box(&ads_tr.predict(black_box(&ads_state)));
            }
            "ads_update" => {
                black_box(
                    &ads_ob
                        .update(
                            black_box(&ads_state),
                            black_box(&z),
                            CovarianceUpdateMethod::JosephForm,
                        )
                        .expect("update"),
                );
            }
            "ukf" => {
                let s = ukf
                    .step(black_box(&ustate), Some(black_box(&uz)))
                    .expect("step");
                black_box(&s);
            }
            "ukf_corr" => {
                let s = ukf
                    .step(black_box(&ustate_corr), Some(black_box(&uz)))
                    .expect("step");
                black_box(&s);
            }
            "ukf_predict" => {
                black_box(&ukf.predict(black_box(&ustate)).expect("predict"));
            }
            "ukf_update" => {
                black_box(
                    &ukf.update_predicted(black_box(&ustate), black_box(&uz))
                        .expect("update"),
                );
            }
            "none" => {
                black_box(&state);
            }
            other => panic!("unknown loop {other}"),
        }
    }
    let el = t0.elapsed();
    eprintln!(
        "{which}: {steps} steps, {:.1} ns/step",
        el.as_secs_f64() * 1e9 / steps as f64
    );
}
