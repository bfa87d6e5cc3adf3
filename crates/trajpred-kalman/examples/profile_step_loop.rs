//! A timing loop over the benchmark's inputs, for instruction counts under callgrind
//! (load-independent) and a quick wall-clock figure:
//!
//! ```text
//! cargo build --release -p trajpred-kalman --example profile_step_loop
//! valgrind --tool=callgrind target/release/examples/profile_step_loop kf 10000
//! ```
//!
//! The first argument picks the loop: `<problem>` for a full step, `<problem>_predict` or
//! `<problem>_update` for one half, where the problem is `kf` (2-D constant velocity),
//! `kf_cheap` (the same with cheap input checks), `kf_general` (a damped constant velocity
//! and positions measured at twice their scale: no structure for the KF to exploit),
//! `kf_dense` (a random stable 6-state model with a dense 3-D observation), `kf_dense_cheap`, their adskalman
//! twins `ads`, `ads_general`, `ads_dense`, `ukf`, or `ukf_corr` (the UKF from a correlated
//! input state); `none` measures the fixed overhead. The second argument is the number of
//! steps. The inputs are the benchmark's (`benches/common/mod.rs`). Instructions per step:
//! the difference of two runs with different step counts divided by the difference of the
//! counts.
#[path = "../benches/common/mod.rs"]
mod common;

use adskalman::{
    CovarianceUpdateMethod, KalmanFilterNoControl, ObservationModel, TransitionModelLinearNoControl,
};
use common::{Dims, KfCase, cv_case, dense_case, general_case, ukf_case};
use nalgebra::{DefaultAllocator, Dim, DimMin, DimName, OVector};
use std::hint::black_box;
use std::time::{Duration, Instant};
use trajpred_core::Gaussian;
use trajpred_kalman::{Filter, FilterAllocator, InputChecks};

/// Runs `body` `steps` times and returns the elapsed time.
fn time_loop(steps: usize, mut body: impl FnMut()) -> Duration {
    let t0 = Instant::now();
    for _ in 0..steps {
        body();
    }
    t0.elapsed()
}

/// One of our filters: the full step, the prediction or the update (`part`).
fn filter_loop<D: Dim, M: Dim>(
    steps: usize,
    part: &str,
    filter: &impl Filter<f64, D, M>,
    state: &Gaussian<f64, D>,
    z: &OVector<f64, M>,
) -> Option<Duration>
where
    DefaultAllocator: FilterAllocator<D, M>,
{
    Some(match part {
        "" => time_loop(steps, || {
            black_box(
                filter
                    .step(black_box(state), Some(black_box(z)))
                    .expect("step"),
            );
        }),
        "_predict" => time_loop(steps, || {
            black_box(filter.predict(black_box(state)).expect("predict"));
        }),
        "_update" => time_loop(steps, || {
            black_box(
                filter
                    .update_predicted(black_box(state), black_box(z))
                    .expect("update"),
            );
        }),
        _ => return None,
    })
}

/// adskalman on one of the KF problems: the full step (Joseph form), the prediction or the
/// update (`part`).
fn ads_loop<N: DimName, M: DimName + DimMin<M, Output = M>>(
    steps: usize,
    part: &str,
    case: &KfCase<N, M>,
) -> Option<Duration>
where
    DefaultAllocator: Dims<N, M>,
{
    let ads = KalmanFilterNoControl::new(&case.ads_tr, &case.ads_ob);
    let (state, z) = (&case.ads_state, &case.z);
    Some(match part {
        "" => time_loop(steps, || {
            black_box(
                ads.step_with_options(
                    black_box(state),
                    black_box(z),
                    CovarianceUpdateMethod::JosephForm,
                )
                .expect("step"),
            );
        }),
        "_predict" => time_loop(steps, || {
            black_box(case.ads_tr.predict(black_box(state)));
        }),
        "_update" => time_loop(steps, || {
            black_box(
                case.ads_ob
                    .update(
                        black_box(state),
                        black_box(z),
                        CovarianceUpdateMethod::JosephForm,
                    )
                    .expect("update"),
            );
        }),
        _ => return None,
    })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map(String::as_str).unwrap_or("kf");
    let steps: usize = args
        .get(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let (problem, part) = match which.find("_predict").or_else(|| which.find("_update")) {
        Some(at) => which.split_at(at),
        None => (which, ""),
    };

    // the benchmark's problems (`benches/common/mod.rs`)
    let elapsed = match problem {
        "kf" | "kf_cheap" => {
            let case = cv_case();
            let kf = match problem {
                "kf_cheap" => case.kf.clone().with_input_checks(InputChecks::Cheap),
                _ => case.kf.clone(),
            };
            filter_loop(steps, part, &kf, &case.state, &case.z)
        }
        "kf_general" => {
            let case = general_case();
            filter_loop(steps, part, &case.kf, &case.state, &case.z)
        }
        "kf_dense" | "kf_dense_cheap" => {
            let case = dense_case();
            let kf = match problem {
                "kf_dense_cheap" => case.kf.clone().with_input_checks(InputChecks::Cheap),
                _ => case.kf.clone(),
            };
            filter_loop(steps, part, &kf, &case.state, &case.z)
        }
        "ads" => ads_loop(steps, part, &cv_case()),
        "ads_general" => ads_loop(steps, part, &general_case()),
        "ads_dense" => ads_loop(steps, part, &dense_case()),
        "ukf" | "ukf_corr" => {
            let (ukf, state, z) = ukf_case();
            // a state whose turn rate is correlated with the rest (the posterior of one
            // step): every sigma-point pair then moves the turn rate
            let state = match problem {
                "ukf_corr" => ukf
                    .step(&state, Some(&z))
                    .expect("step")
                    .posterior()
                    .clone(),
                _ => state,
            };
            filter_loop(steps, part, &ukf, &state, &z)
        }
        "none" => {
            let state = cv_case().state;
            Some(time_loop(steps, || {
                black_box(&state);
            }))
        }
        _ => None,
    };
    let Some(el) = elapsed else {
        eprintln!("unknown loop {which}");
        std::process::exit(2);
    };
    eprintln!(
        "{which}: {steps} steps, {:.1} ns/step",
        el.as_secs_f64() * 1e9 / steps as f64
    );
}
