//! A timing loop over the benchmark's inputs, for instruction counts under callgrind
//! (load-independent) and a quick wall-clock figure:
//!
//! ```text
//! cargo build --release -p trajpred-kalman --example profile_step_loop
//! valgrind --tool=callgrind target/release/examples/profile_step_loop kf 10000
//! ```
//!
//! The first argument picks the loop (`kf`, `kf_cheap`, `kf_predict`, `kf_update`, `ads`,
//! `ads_predict`, `ads_update`, `kf_general` and `ads_general` (a damped constant velocity
//! and positions measured at twice their scale: no structure for the KF to exploit), `ukf`,
//! `ukf_corr` (a correlated input state), `ukf_predict`, `ukf_update`, `none`), the second
//! the number of steps. The inputs are the benchmark's (`benches/common/mod.rs`). Instructions per step: the difference of two runs with different step
//! counts divided by the difference of the counts (`none` measures the fixed overhead).
#[path = "../benches/common/mod.rs"]
mod common;

use adskalman::{
    CovarianceUpdateMethod, KalmanFilterNoControl, ObservationModel, TransitionModelLinearNoControl,
};
use common::{KfCase, cv_case, general_case, ukf_case};
use std::hint::black_box;
use std::time::Instant;
use trajpred_kalman::{Filter, InputChecks};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map(String::as_str).unwrap_or("kf");
    let steps: usize = args
        .get(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);

    // the benchmark's problems (`benches/common/mod.rs`)
    let KfCase {
        kf,
        ads_tr,
        ads_ob,
        state,
        ads_state,
        z,
    } = cv_case();
    let kf_cheap = kf.clone().with_input_checks(InputChecks::Cheap);
    let ads = KalmanFilterNoControl::new(&ads_tr, &ads_ob);
    let KfCase {
        kf: kf_general,
        ads_tr: general_ads_tr,
        ads_ob: general_ads_ob,
        state: general_state,
        ads_state: general_ads_state,
        z: general_z,
    } = general_case();
    let ads_general = KalmanFilterNoControl::new(&general_ads_tr, &general_ads_ob);

    let (ukf, ustate, uz) = ukf_case();
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
                    .step(black_box(&general_state), Some(black_box(&general_z)))
                    .expect("step");
                black_box(&s);
            }
            "ads_general" => {
                black_box(
                    &ads_general
                        .step_with_options(
                            black_box(&general_ads_state),
                            black_box(&general_z),
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
