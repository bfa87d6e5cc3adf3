//! A soak run of the bootstrap particle filter over long generated tracks (seeded): 2-D
//! constant velocity, position observations (10 % missing), 500 particles, residual
//! resampling every step. Every `check_every` steps the weighted covariance of the estimate
//! must be finite, symmetric and positive semi-definite (the Kalman soak's check,
//! `trajpred-kalman/examples/kalman_soak.rs`, included here); every step's log-likelihood finite and
//! its effective sample size in `[1, n]`. VmRSS is read at the start, after the first track
//! and at the end.
//!
//! ```text
//! cargo run --release -p trajpred-particle --example particle_soak -- <steps> <seed>
//! ```

#[allow(dead_code)]
#[path = "../../trajpred-kalman/examples/kalman_soak.rs"]
mod kalman_soak;

use kalman_soak::{Part, check_cov, vm_rss_kib};
use nalgebra::{Matrix4, U2, U4, Vector2, Vector4};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::time::Instant;
use trajpred_core::Gaussian;
use trajpred_kalman::LinearObservation;
use trajpred_kalman::LinearTransition;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_velocity, position_observation,
};
use trajpred_particle::{ParticleFilter, ParticleFiltering};

const PARTICLES: usize = 500;

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

#[allow(clippy::print_stdout)]
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let total: u64 = args
        .first()
        .map_or(1_000_000, |s| s.parse().expect("steps"));
    let seed: u64 = args.get(1).map_or(0, |s| s.parse().expect("seed"));
    let track_len = 100_000u64;
    let check_every = 1_000u64;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    println!(
        "PF soak: {total} steps, {PARTICLES} particles, seed {seed}, tracks of up to {track_len}, checks every {check_every}"
    );
    println!("VmRSS at start: {:?} KiB", vm_rss_kib());
    let dt = 0.1;
    let (q, r) = (0.5, 0.3);
    let start = Instant::now();
    let mut part = Part::default();
    let (mut min_ess, mut resampled) = (f64::INFINITY, 0u64);
    let mut left = total;
    while left > 0 {
        let n = left.min(track_len);
        left -= n;
        part.tracks += 1;
        let tr: LinearTransition<f64, U4> =
            constant_velocity(2, dt, q, StateOrder::AxisBlocks).expect("model");
        let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks).expect("layout");
        let ob: LinearObservation<f64, U4, U2> = position_observation(layout, r).expect("model");
        let mut x = [
            gauss(&mut rng) * 100.0,
            gauss(&mut rng) * 5.0,
            gauss(&mut rng) * 100.0,
            gauss(&mut rng) * 5.0,
        ];
        let init = Gaussian {
            mean: Vector4::new(x[0], 0.0, x[2], 0.0),
            covariance: Matrix4::from_diagonal(&Vector4::new(1.0, 25.0, 1.0, 25.0)),
        };
        let mut pf =
            ParticleFilter::from_gaussian(tr, ob, &init, PARTICLES, &mut rng).expect("filter");
        for k in 1..=n {
            for o in [0, 2] {
                let a = gauss(&mut rng) * q.sqrt();
                x[o] += x[o + 1] * dt + 0.5 * a * dt * dt;
                x[o + 1] += a * dt;
            }
            let z = (!rng.random_bool(0.1)).then(|| {
                Vector2::new(
                    x[0] + gauss(&mut rng) * r.sqrt(),
                    x[2] + gauss(&mut rng) * r.sqrt(),
                )
            });
            let s = match pf.step(z.as_ref(), &mut rng) {
                Ok(s) => s,
                Err(e) => {
                    part.errors += 1;
                    if part.messages.len() < 5 {
                        part.messages
                            .push(format!("track {} step {k}: {e}", part.tracks));
                    }
                    continue; // the filter is unchanged: skip the observation
                }
            };
            part.steps += 1;
            part.updates += u64::from(z.is_some());
            resampled += u64::from(s.resampled);
            min_ess = min_ess.min(s.ess);
            if !s.log_likelihood.is_finite()
                || !(1.0 - 1e-9..=PARTICLES as f64 + 1e-9).contains(&s.ess)
            {
                part.violations += 1;
                if part.messages.len() < 5 {
                    part.messages.push(format!(
                        "step {k}: log-likelihood {}, ESS {}",
                        s.log_likelihood, s.ess
                    ));
                }
            }
            if k % check_every == 0 || k == n {
                part.checks += 1;
                part.max_trace = part.max_trace.max(s.estimate.covariance.trace());
                let p = &s.estimate.covariance;
                let e = Vector2::new(s.estimate.mean[0] - x[0], s.estimate.mean[2] - x[2]);
                let block = nalgebra::Matrix2::new(p[(0, 0)], p[(0, 2)], p[(2, 0)], p[(2, 2)]);
                if let Some(inv) = block.try_inverse() {
                    part.nees_sum += (e.transpose() * inv * e)[0];
                    part.nees_n += 1;
                }
                if let Err(m) = check_cov(p) {
                    part.violations += 1;
                    if part.messages.len() < 5 {
                        part.messages.push(format!("step {k}: {m}"));
                    }
                }
            }
        }
        if part.tracks == 1 {
            println!("VmRSS after the first track: {:?} KiB", vm_rss_kib());
        }
    }
    part.seconds = start.elapsed().as_secs_f64();
    kalman_soak::print("PF", &part);
    println!("smallest ESS {min_ess:.1}, resampled at {resampled} steps");
    println!("VmRSS at end: {:?} KiB", vm_rss_kib());
    if part.violations + part.errors > 0 || part.steps != total {
        std::process::exit(1);
    }
}
