//! A constant-velocity Kalman filter tracking a GeoLife track, then the RTS smoother over the
//! whole track: the filter gives the best estimate of each position from the fixes up to it,
//! the smoother from every fix of the track.
//!
//! ```text
//! cargo run --release -p trajpred-kalman --example kf_rts_geolife -- [file.plt]
//! ```
//!
//! The `.plt` file is read by `trajpred-data`'s GeoLife loader (positions in metres around
//! the first fix). Without an argument the example writes a generated GeoLife file (a walk
//! along a bend, a fix every second, 4 m noise per axis) to the temporary folder and reads
//! that; `tests/examples_run.rs` does the same and checks that smoothing beats filtering,
//! which beats the raw fixes, against the generated truth.
#![allow(clippy::print_stdout)]

use nalgebra::{Matrix4, U2, U4, Vector2, Vector4};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use trajpred_core::{Gaussian, Trajectory};
use trajpred_data::geodesy::{Enu, Geodetic, LocalFrame};
use trajpred_data::{LoadOptions, geolife};
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_velocity, position_observation,
};
use trajpred_kalman::{Filter, Kf, LinearObservation, LinearTransition, Smoother};

/// The generated walk's fixes per file.
pub const POINTS: usize = 300;

/// The true east/north positions of the generated walk (1.4 m/s, bending left halfway).
pub fn truth() -> Vec<[f64; 2]> {
    let (mut x, mut y, mut heading) = (0.0, 0.0, 0.3f64);
    (0..POINTS)
        .map(|k| {
            if k > 0 {
                if (100..200).contains(&k) {
                    heading += 0.015;
                }
                x += 1.4 * heading.cos();
                y += 1.4 * heading.sin();
            }
            [x, y]
        })
        .collect()
}

/// Writes the generated walk as a GeoLife `.plt` (the first fix exact, so the loader's frame
/// is the truth's; the others with deterministic pseudo-random noise of 4 m per axis).
pub fn write_generated_plt(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let frame = LocalFrame::new(Geodetic::new(39.98, 116.32, 50.0)?)?;
    let mut state: u64 = 2008;
    let mut normal = || {
        // Box-Muller on a small linear congruential generator
        let mut u = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (-2.0 * u().ln()).sqrt() * (std::f64::consts::TAU * u()).cos()
    };
    let mut text = String::from(
        "Geolife trajectory\r\nWGS 84\r\nAltitude is in Feet\r\nReserved 3\r\n0,2,255,My Track,0,0,2,8421376\r\n0\r\n",
    );
    for (k, [x, y]) in truth().into_iter().enumerate() {
        let (nx, ny) = if k == 0 {
            (0.0, 0.0)
        } else {
            (4.0 * normal(), 4.0 * normal())
        };
        let g = frame.to_geodetic(&Enu {
            east: x + nx,
            north: y + ny,
            up: 0.0,
        });
        let secs = 2 * 3600 + 53 * 60 + k;
        let (h, m, s) = (secs / 3600, secs / 60 % 60, secs % 60);
        let days = 39744.0 + secs as f64 / 86400.0;
        writeln!(
            text,
            "{:.7},{:.7},0,164,{days:.10},2008-10-23,{h:02}:{m:02}:{s:02}\r",
            g.lat_deg, g.lon_deg
        )?;
    }
    std::fs::write(path, text)?;
    Ok(())
}

/// The track, its filtered and its smoothed positions.
pub struct Tracked {
    /// The positions as loaded (metres around the first fix).
    pub track: Trajectory,
    /// Filtered position estimates.
    pub filtered: Vec<[f64; 2]>,
    /// Smoothed position estimates.
    pub smoothed: Vec<[f64; 2]>,
}

/// Loads `plt`, filters it with a constant-velocity KF at its mean interval, and smooths.
pub fn run(plt: &Path) -> Result<Tracked, Box<dyn std::error::Error>> {
    let (tracks, report) = geolife::load_plt(plt, &LoadOptions::geolife())?;
    eprintln!("{report}");
    let track = tracks
        .into_iter()
        .next()
        .ok_or("no track in the file")?
        .trajectory;
    let n = track.len();
    let dt = (track.times()[n - 1] - track.times()[0]) / (n - 1) as f64;
    // white-noise acceleration 0.05 m^2/s^3 (a walker), GPS noise 16 m^2 per axis
    let layout = KinematicLayout::new(2, 2, StateOrder::PositionsFirst)?;
    let tr: LinearTransition<f64, U4> = constant_velocity(2, dt, 0.05, StateOrder::PositionsFirst)?;
    let ob: LinearObservation<f64, U4, U2> = position_observation(layout, 16.0)?;
    let kf = Kf::new(tr, ob)?;
    let zs: Vec<Option<Vector2<f64>>> = (0..n)
        .map(|i| Some(Vector2::new(track.axis(0)[i], track.axis(1)[i])))
        .collect();
    let x0 = Gaussian {
        mean: Vector4::new(
            zs[0].map_or(0.0, |z| z[0]),
            zs[0].map_or(0.0, |z| z[1]),
            0.0,
            0.0,
        ),
        covariance: Matrix4::from_diagonal(&Vector4::new(16.0, 16.0, 25.0, 25.0)),
    };
    let steps = kf.filter(&x0, &zs)?;
    let filtered: Vec<_> = steps.iter().map(|s| s.posterior().clone()).collect();
    let smoothed = kf.smooth(&filtered)?;
    let xy = |g: &Gaussian<f64, U4>| [g.mean[0], g.mean[1]];
    Ok(Tracked {
        filtered: filtered.iter().map(xy).collect(),
        smoothed: smoothed.iter().map(xy).collect(),
        track,
    })
}

/// Root mean square distance between two lists of points.
pub fn rms(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    let s: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2))
        .sum();
    (s / a.len() as f64).sqrt()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (plt, generated) = match std::env::args().nth(1) {
        Some(p) => (PathBuf::from(p), false),
        None => {
            let p = std::env::temp_dir().join("trajpred_example_walk.plt");
            write_generated_plt(&p)?;
            (p, true)
        }
    };
    let t = run(&plt)?;
    let raw: Vec<[f64; 2]> = (0..t.track.len())
        .map(|i| [t.track.axis(0)[i], t.track.axis(1)[i]])
        .collect();
    println!("{}: {} fixes", plt.display(), raw.len());
    if generated {
        let truth = truth();
        println!(
            "RMS error against the truth: fixes {:.2} m, filtered {:.2} m, smoothed {:.2} m",
            rms(&raw, &truth),
            rms(&t.filtered, &truth),
            rms(&t.smoothed, &truth)
        );
    } else {
        println!(
            "RMS distance from the fixes: filtered {:.2} m, smoothed {:.2} m",
            rms(&t.filtered, &raw),
            rms(&t.smoothed, &raw)
        );
    }
    Ok(())
}
