//! Criterion benchmarks of the hot paths, each beside a peer measured in the same run:
//!
//! - `kf_step_cv4_pos2`: one KF predict + update (Joseph form), 2-D constant velocity
//!   (4 states) with a 2-D position observation, trajpred vs adskalman 0.18 (Joseph form);
//! - `kf_step_general_cv4_pos2`: the same step with models that have neither structure the
//!   KF exploits (a damped constant velocity, positions measured at twice their scale), so
//!   both filters take their general products;
//! - `kf_step_dense6_obs3`: the same step on a general dense model (a random stable 6-state
//!   transition, a dense 3 x 6 observation, random `Q`, `R`; `common::dense_case`);
//! - `ukf_step_ct5_rb2`: one UKF predict + update on the 5-state coordinated turn with a
//!   range-bearing observation (filterpy's figure for the same step comes from
//!   `benches/filterpy_ukf_step.py`).
//!
//! The inputs are in `benches/common/mod.rs`, shared with `examples/profile_step_loop.rs`.

mod common;

use adskalman::{
    CovarianceUpdateMethod, KalmanFilterNoControl, ObservationModel, TransitionModelLinearNoControl,
};
use common::{Dims, KfCase, cv_case, dense_case, general_case, ukf_case};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, criterion_group, criterion_main};
use nalgebra::{DefaultAllocator, DimMin, DimName};
use std::hint::black_box;
use trajpred_kalman::{Filter, InputChecks};

/// The full step of both filters on `case`: `trajpred_joseph` and `adskalman_joseph`.
fn bench_steps<N: DimName, M: DimName + DimMin<M, Output = M>>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    case: &KfCase<N, M>,
) where
    DefaultAllocator: Dims<N, M>,
{
    let ads = KalmanFilterNoControl::new(&case.ads_tr, &case.ads_ob);
    g.bench_function("trajpred_joseph", |b| {
        b.iter(|| {
            let s = case
                .kf
                .step(black_box(&case.state), Some(black_box(&case.z)))
                .expect("step");
            black_box(&s);
        })
    });
    g.bench_function("adskalman_joseph", |b| {
        b.iter(|| {
            let posterior = ads
                .step_with_options(
                    black_box(&case.ads_state),
                    black_box(&case.z),
                    CovarianceUpdateMethod::JosephForm,
                )
                .expect("step");
            black_box(&posterior);
        })
    });
}

fn kf_step(c: &mut Criterion) {
    let case = cv_case();
    let kf_cheap = case.kf.clone().with_input_checks(InputChecks::Cheap);

    let mut g = c.benchmark_group("kf_step_cv4_pos2");
    bench_steps(&mut g, &case);
    g.bench_function("trajpred_joseph_cheap_input_checks", |b| {
        b.iter(|| {
            let s = kf_cheap
                .step(black_box(&case.state), Some(black_box(&case.z)))
                .expect("step");
            black_box(&s);
        })
    });
    g.bench_function("trajpred_predict_only", |b| {
        b.iter(|| {
            let prior = case.kf.predict(black_box(&case.state)).expect("predict");
            black_box(&prior);
        })
    });
    g.bench_function("trajpred_update_only", |b| {
        b.iter(|| {
            let update = case
                .kf
                .update_predicted(black_box(&case.state), black_box(&case.z))
                .expect("update");
            black_box(&update);
        })
    });
    g.bench_function("adskalman_predict_only", |b| {
        b.iter(|| {
            let prior = case.ads_tr.predict(black_box(&case.ads_state));
            black_box(&prior);
        })
    });
    g.bench_function("adskalman_update_only", |b| {
        b.iter(|| {
            let posterior = case
                .ads_ob
                .update(
                    black_box(&case.ads_state),
                    black_box(&case.z),
                    CovarianceUpdateMethod::JosephForm,
                )
                .expect("update");
            black_box(&posterior);
        })
    });
    g.finish();
}

fn kf_step_general(c: &mut Criterion) {
    let mut g = c.benchmark_group("kf_step_general_cv4_pos2");
    bench_steps(&mut g, &general_case());
    g.finish();
}

fn kf_step_dense(c: &mut Criterion) {
    let mut g = c.benchmark_group("kf_step_dense6_obs3");
    bench_steps(&mut g, &dense_case());
    g.finish();
}

fn ukf_step(c: &mut Criterion) {
    let (ukf, state, z) = ukf_case();
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

criterion_group!(benches, kf_step, kf_step_general, kf_step_dense, ukf_step);
criterion_main!(benches);
