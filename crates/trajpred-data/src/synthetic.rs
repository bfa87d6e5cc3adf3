//! The synthetic trajectories of the papers, in metres, noise-free (add noise with
//! [`crate::noise`]).
//!
//! - [`gskf_eq20`]: eq. (20) of the MSTPM-GSKF paper, 1000 points at `t_i = 0.01 π i`;
//! - [`PatentCurve`]: the three simulated 3-D curves of the KFU-LSTM-Net patent, whose
//!   equations the patent does not give; the project's choice (`docs/papers.md` D.2) is written
//!   on each variant and in `docs/data.md`.
//!
//! ```
//! use trajpred_data::synthetic::{gskf_eq20, PatentCurve};
//! let tr = gskf_eq20();
//! assert_eq!((tr.len(), tr.dim()), (1000, 3));
//! let helix = PatentCurve::Helix.generate(500, 0.1)?;
//! assert_eq!(helix.len(), 500);
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::{Error, Result};
use std::f64::consts::PI;
use trajpred_core::Trajectory;

/// Number of points of eq. (20) in the GSKF paper.
pub const GSKF_POINTS: usize = 1000;
/// Parameter step of eq. (20): `t_i = i * 0.01 π`.
pub const GSKF_STEP: f64 = 0.01 * PI;

/// The point of eq. (20) at parameter `t`:
/// `x = 2 sin(0.1 t)`, `y = sin(t) cos(0.1 t)`, `z = 2 sin(t) cos(2 t)`.
pub fn gskf_eq20_point(t: f64) -> [f64; 3] {
    [
        2.0 * (0.1 * t).sin(),
        t.sin() * (0.1 * t).cos(),
        2.0 * t.sin() * (2.0 * t).cos(),
    ]
}

/// Eq. (20) of the GSKF paper with `n` points, `t_i = i * 0.01 π`, `i = 0..n`; the
/// trajectory's timestamps are the `t_i`. An error for `n == 0`.
pub fn gskf_eq20_n(n: usize) -> Result<Trajectory> {
    let times: Vec<f64> = (0..n).map(|i| i as f64 * GSKF_STEP).collect();
    let mut axes: Vec<Vec<f64>> = (0..3).map(|_| Vec::with_capacity(n)).collect();
    for &t in &times {
        for (a, v) in axes.iter_mut().zip(gskf_eq20_point(t)) {
            a.push(v);
        }
    }
    Ok(Trajectory::from_axes(times, axes)?)
}

/// Eq. (20) of the GSKF paper exactly as `docs/papers.md` A.5: 1000 points, `t_i = i * 0.01 π`,
/// `i = 0..=999`, metres. Train on the first 800, test on the last 200.
pub fn gskf_eq20() -> Trajectory {
    match gskf_eq20_n(GSKF_POINTS) {
        Ok(t) => t,
        // 1000 finite, strictly increasing samples: cannot fail
        Err(_) => unreachable!("eq. 20 with 1000 points is a valid trajectory"),
    }
}

/// The three simulated 3-D curves of the KFU-LSTM-Net patent (`docs/papers.md` D.2: the patent's
/// table of equations is missing; these are the project's choice). Time `t` in seconds, metres.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PatentCurve {
    /// A helix: `x = 10 cos(0.2 t)`, `y = 10 sin(0.2 t)`, `z = 0.5 t`.
    Helix,
    /// A 3-D Lissajous figure-eight with `ω = 2π/100`:
    /// `x = 20 sin(ω t)`, `y = 10 sin(2 ω t)`, `z = 5 sin(3 ω t)`.
    FigureEight,
    /// A climbing spiral that rolls out into a level straight leg at `t1 = 60 s`:
    /// for `t < t1`, `x = R sin(ω t)`, `y = R (1 - cos(ω t))`, `z = c t` with `R = 20 m`,
    /// `ω = 0.25 rad/s`, `c = 1 m/s`; for `t ≥ t1` the horizontal velocity stays that of
    /// `t1` (`v = R ω` along heading `ω t1`) and `z = c t1` (level flight). Position and
    /// horizontal velocity are continuous.
    ClimbingTurn,
}

impl PatentCurve {
    /// All three curves, in the order of the patent's description.
    pub const ALL: [PatentCurve; 3] = [
        PatentCurve::Helix,
        PatentCurve::FigureEight,
        PatentCurve::ClimbingTurn,
    ];

    /// A short lowercase name (`helix`, `figure-eight`, `climbing-turn`).
    pub fn name(self) -> &'static str {
        match self {
            PatentCurve::Helix => "helix",
            PatentCurve::FigureEight => "figure-eight",
            PatentCurve::ClimbingTurn => "climbing-turn",
        }
    }

    /// The curve's point at time `t` (seconds).
    pub fn point(self, t: f64) -> [f64; 3] {
        match self {
            PatentCurve::Helix => [10.0 * (0.2 * t).cos(), 10.0 * (0.2 * t).sin(), 0.5 * t],
            PatentCurve::FigureEight => {
                let w = 2.0 * PI / 100.0;
                [
                    20.0 * (w * t).sin(),
                    10.0 * (2.0 * w * t).sin(),
                    5.0 * (3.0 * w * t).sin(),
                ]
            }
            PatentCurve::ClimbingTurn => {
                const R: f64 = 20.0;
                const W: f64 = 0.25;
                const C: f64 = 1.0;
                const T1: f64 = 60.0;
                if t < T1 {
                    [R * (W * t).sin(), R * (1.0 - (W * t).cos()), C * t]
                } else {
                    let (s, c) = (W * T1).sin_cos();
                    let v = R * W;
                    let dt = t - T1;
                    [R * s + v * c * dt, R * (1.0 - c) + v * s * dt, C * T1]
                }
            }
        }
    }

    /// `n` points at `t_i = i dt`, `i = 0..n`. Errors for `n == 0` or a `dt` that is not
    /// finite and positive. The patent's experiments use `n = 1000`, `dt = 0.1`.
    pub fn generate(self, n: usize, dt: f64) -> Result<Trajectory> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::param(
                "dt",
                format!("must be finite and positive, got {dt}"),
            ));
        }
        let mut axes: Vec<Vec<f64>> = (0..3).map(|_| Vec::with_capacity(n)).collect();
        for i in 0..n {
            for (a, v) in axes.iter_mut().zip(self.point(i as f64 * dt)) {
                a.push(v);
            }
        }
        Ok(Trajectory::uniform(0.0, dt, axes)?)
    }
}
