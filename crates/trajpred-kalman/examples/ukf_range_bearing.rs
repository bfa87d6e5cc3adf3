//! A radar tracking a turning aircraft with the unscented Kalman filter: the radar at the
//! origin measures range (10 m standard deviation) and bearing (2 mrad), the target flies a
//! coordinated turn at 150 m/s around the radar, 8 km away, a report every 2 s, every tenth
//! report lost.
//! The UKF estimates position, velocity and turn rate from those polar readings.
//!
//! ```text
//! cargo run --release -p trajpred-kalman --example ukf_range_bearing -- [seed]
//! ```
//!
//! Prints the position error of the raw readings (converted to x, y) and of the UKF, and the
//! mean NEES of the position (2 for a filter whose covariance is honest).
//! `tests/examples_run.rs` runs it over several seeds.
#![allow(clippy::print_stdout)]

// everything but the noise generator comes through trajpred-kalman's re-exports
use rand_distr::{Distribution, StandardNormal};
use trajpred_kalman::nalgebra::{Matrix2, Matrix5, Vector2, Vector5};
use trajpred_kalman::rand::SeedableRng;
use trajpred_kalman::{
    CoordinatedTurn, Filter, Gaussian, MerweSigmaPoints, RangeBearing, Transition, Ukf,
};

/// What one run measured.
#[derive(Debug, Clone, Copy)]
pub struct Summary {
    /// RMS position error of the readings converted to Cartesian coordinates, metres.
    pub readings: f64,
    /// RMS position error of the UKF's estimates, metres.
    pub ukf: f64,
    /// Mean position NEES of the UKF (2 degrees of freedom).
    pub mean_nees: f64,
}

/// Steps tracked; the first `SETTLE` are not scored.
pub const STEPS: usize = 150;
const SETTLE: usize = 10;

/// Simulates, tracks and scores one run; every draw from `seed`.
pub fn run(seed: u64) -> Result<Summary, Box<dyn std::error::Error>> {
    // state [x, vx, y, vy, turn rate]; 2 s steps
    let ct = CoordinatedTurn::<f64>::new(2.0, 0.05, 1e-7)?;
    let (range_sd, bearing_sd) = (10.0, 2e-3);
    let radar = RangeBearing::new(
        Vector2::new(0.0, 0.0),
        0,
        2,
        range_sd * range_sd,
        bearing_sd * bearing_sd,
    )?;
    let ukf = Ukf::new(&ct, &radar, MerweSigmaPoints::new(1e-3, 2.0, 0.0))?;

    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut noise = || -> f64 { StandardNormal.sample(&mut rng) };
    // a circle around the radar: range stays 8 km
    let mut x = Vector5::new(8000.0, 0.0, 0.0, 150.0, 150.0 / 8000.0);
    let (mut truth, mut zs) = (Vec::new(), Vec::new());
    for k in 0..STEPS {
        x = ct.transition(&x)?;
        truth.push(x);
        let range = (x[0] * x[0] + x[2] * x[2]).sqrt() + range_sd * noise();
        let bearing = x[2].atan2(x[0]) + bearing_sd * noise();
        zs.push((k % 10 != 9).then_some(Vector2::new(range, bearing)));
    }

    // start from the first reading, with a wide velocity and turn-rate prior
    let z0 = zs[0].ok_or("the first reading is present")?;
    let x0 = Gaussian {
        mean: Vector5::new(z0[0] * z0[1].cos(), 0.0, z0[0] * z0[1].sin(), 0.0, 0.0),
        covariance: Matrix5::from_diagonal(&Vector5::new(
            400.0,
            200.0f64.powi(2),
            400.0,
            200.0f64.powi(2),
            1e-3,
        )),
    };
    let steps = ukf.filter(&x0, &zs[1..])?;

    let (mut e_ukf, mut e_obs, mut nees, mut n_obs) = (0.0, 0.0, 0.0, 0.0);
    for (k, s) in steps.iter().enumerate().skip(SETTLE) {
        let (t, g) = (&truth[k + 1], s.posterior());
        let d = Vector2::new(g.mean[0] - t[0], g.mean[2] - t[2]);
        e_ukf += d.norm_squared();
        let p = Matrix2::new(
            g.covariance[(0, 0)],
            g.covariance[(0, 2)],
            g.covariance[(2, 0)],
            g.covariance[(2, 2)],
        );
        nees += d.dot(&(p.try_inverse().ok_or("singular position covariance")? * d));
        if let Some(z) = zs[k + 1] {
            e_obs += (z[0] * z[1].cos() - t[0]).powi(2) + (z[0] * z[1].sin() - t[2]).powi(2);
            n_obs += 1.0;
        }
    }
    let n = (steps.len() - SETTLE) as f64;
    Ok(Summary {
        readings: (e_obs / n_obs).sqrt(),
        ukf: (e_ukf / n).sqrt(),
        mean_nees: nees / n,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let seed = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(3);
    let s = run(seed)?;
    println!(
        "seed {seed}: readings {:.1} m, UKF {:.1} m, mean position NEES {:.2}",
        s.readings, s.ukf, s.mean_nees
    );
    Ok(())
}
