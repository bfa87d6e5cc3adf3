//! Where the gap between our relative error and the paper's 0.03% comes from (issue #27, item
//! 6), on the real flight: the measure (the same metre errors placed at the paper's location,
//! latitude and longitude apart), a fixed-interval RTS smoother that also uses the kept frame
//! after each gap, the MKPF's particle count, and the observation noise the filters assume.

use super::experiment::{
    Flight, Method, Motion, Noise, Run, Setup, choose_noise, ct_model, cv_model, experiment_err,
    run_method, to_geodetic,
};
use super::models::{Prepared, initial, observation, prepare};
use super::{FlightResult, find, mean_sd};
use crate::Result;
use crate::runner::{Computed, Row};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, DimName, U2, U4, U5, Vector2};
use std::time::Instant;
use trajpred_data::geodesy::{Geodetic, LocalFrame};
use trajpred_kalman::smoother::filter_smooth_steps;
use trajpred_kalman::{Ekf, FilterAllocator, Kf, MerweSigmaPoints, Smoother, Ukf};

/// The filter run forward before the backward pass of the smoother.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Forward {
    /// The linear Kalman filter (constant-velocity model only).
    Kf,
    /// The unscented Kalman filter.
    Ukf,
    /// The extended Kalman filter.
    Ekf,
}

/// The paper's relative error of a run, at the flight and with the same metre errors placed at
/// another location, on both coordinates and on each alone (fractions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measures {
    /// Latitude and longitude at the flight (the paper's measure, as in Tables 1 and 2).
    pub rel: f64,
    /// Latitude alone, at the flight.
    pub rel_lat: f64,
    /// Longitude alone, at the flight.
    pub rel_lon: f64,
    /// Latitude and longitude with the east-north errors placed at the other location.
    pub moved: f64,
    /// Latitude alone, at the other location.
    pub moved_lat: f64,
    /// Longitude alone, at the other location.
    pub moved_lon: f64,
    /// Root mean square horizontal error, metres.
    pub rmse: f64,
}

/// Relative errors of `predicted` against `truth` (`[lat, lon]` degrees): both coordinates,
/// latitude alone and longitude alone.
fn relative(predicted: &[[f64; 2]], truth: &[[f64; 2]]) -> Result<[f64; 3]> {
    let axis = |a: usize| -> Result<f64> {
        let p: Vec<[f64; 1]> = predicted.iter().map(|x| [x[a]]).collect();
        let t: Vec<[f64; 1]> = truth.iter().map(|x| [x[a]]).collect();
        Ok(trajpred_metrics::relative_rmse(&p, &t)?)
    };
    Ok([
        trajpred_metrics::relative_rmse(predicted, truth)?,
        axis(0)?,
        axis(1)?,
    ])
}

/// The measures of `run`, with its east-north errors also placed on the tangent plane at
/// `location` (`[lat, lon]` degrees, height 0): the same true and predicted east-north metres,
/// converted to latitude and longitude there.
pub fn measures(run: &Run, location: [f64; 2]) -> Result<Measures> {
    let [rel, rel_lat, rel_lon] = relative(&run.predicted, &run.truth)?;
    let frame = LocalFrame::new(Geodetic::new(location[0], location[1], 0.0)?)?;
    let to =
        |v: &[[f64; 2]]| -> Vec<[f64; 2]> { v.iter().map(|p| to_geodetic(&frame, *p)).collect() };
    let [moved, moved_lat, moved_lon] = relative(&to(&run.predicted_enu), &to(&run.truth_enu))?;
    let e = run.errors_m();
    let rmse = (e.iter().map(|x| x * x).sum::<f64>() / e.len().max(1) as f64).sqrt();
    Ok(Measures {
        rel,
        rel_lat,
        rel_lon,
        moved,
        moved_lat,
        moved_lon,
        rmse,
    })
}

/// Filters forward through every frame from the first kept one to the last (updating at the
/// kept frames only, each step's model built for its interval), smooths backward, and returns
/// the smoothed positions of `frames`.
fn smooth<D, F>(
    prep: &Prepared,
    times: &[f64],
    start: &trajpred_core::Gaussian<f64, D>,
    make: &dyn Fn(f64) -> trajpred_kalman::Result<F>,
    frames: &[usize],
) -> Result<Vec<[f64; 2]>>
where
    D: DimName,
    F: Smoother<f64, D, U2>,
    DefaultAllocator: FilterAllocator<D, U2> + Allocator<D>,
{
    let (first, last) = match prep.kept.as_slice() {
        [first, .., last] => (*first, *last),
        _ => return Err(experiment_err("smoother: fewer than two kept frames")),
    };
    let mut is_kept = vec![false; last + 1];
    for &k in &prep.kept {
        is_kept[k] = true;
    }
    let filters = (first..last)
        .map(|j| make(times[j + 1] - times[j]))
        .collect::<trajpred_kalman::Result<Vec<F>>>()?;
    let observations: Vec<Option<Vector2<f64>>> = (first + 1..=last)
        .map(|j| is_kept[j].then(|| Vector2::new(prep.observed[j][0], prep.observed[j][1])))
        .collect();
    let fb = filter_smooth_steps(&filters, start, &observations)?;
    frames
        .iter()
        .map(
            |&j| match j.checked_sub(first).and_then(|i| fb.smoothed.states.get(i)) {
                Some(s) => Ok([s.mean[0], s.mean[2]]),
                None => Err(experiment_err(format!(
                    "smoother: frame {j} outside the kept span"
                ))),
            },
        )
        .collect()
}

/// The smoother's run over the flight: forward `forward` filter, backward pass, the positions
/// of `frames` (the frames the forecasting runs are evaluated on) from the smoothed states.
pub fn run_smoother(
    flight: &Flight,
    setup: &Setup,
    motion: Motion,
    noise: &Noise,
    forward: Forward,
    frames: &[usize],
) -> Result<Run> {
    let clock = Instant::now();
    let prep = prepare(flight, setup)?;
    let times = &flight.times;
    let z0 = prep.observed[prep.kept[0]];
    let merwe = MerweSigmaPoints::default;
    // the forward filter of every step, built by `$make(dt, observation)`, then smoothed
    macro_rules! smoothed {
        ($d:ty, $make:expr) => {{
            let obs = observation::<$d>(setup.position_sd)?;
            let make = |dt: f64| $make(dt, obs.clone());
            let start = initial::<$d>(z0, setup, noise);
            smooth(&prep, times, &start, &make, frames)?
        }};
    }
    let predicted_enu = match (motion, forward) {
        (Motion::Cv, Forward::Kf) => {
            smoothed!(U4, |dt, obs| Kf::new(cv_model(noise, dt)?, obs))
        }
        (Motion::Cv, Forward::Ukf) => {
            smoothed!(U4, |dt, obs| Ukf::new::<U4, U2>(
                cv_model(noise, dt)?,
                obs,
                merwe()
            ))
        }
        (Motion::Cv, Forward::Ekf) => {
            smoothed!(U4, |dt, obs| Ekf::new::<f64, U4, U2>(
                cv_model(noise, dt)?,
                obs
            ))
        }
        (Motion::Ct, Forward::Ukf) => {
            smoothed!(U5, |dt, obs| Ukf::new::<U5, U2>(
                ct_model(noise, dt)?,
                obs,
                merwe()
            ))
        }
        (Motion::Ct, Forward::Ekf) => {
            smoothed!(U5, |dt, obs| Ekf::new::<f64, U5, U2>(
                ct_model(noise, dt)?,
                obs
            ))
        }
        (Motion::Ct, Forward::Kf) => {
            return Err(experiment_err(
                "the linear KF has no coordinated-turn model",
            ));
        }
    };
    let seconds = clock.elapsed().as_secs_f64();
    Ok(Run {
        truth: frames.iter().map(|&j| flight.truth[j]).collect(),
        truth_enu: frames.iter().map(|&j| prep.truth[j]).collect(),
        predicted: predicted_enu
            .iter()
            .map(|p| to_geodetic(&prep.frame, *p))
            .collect(),
        frames: frames.to_vec(),
        predicted_enu,
        seconds,
    })
}

/// The seeds' runs of a method (one run for a Kalman filter).
pub fn seeded_runs(
    flight: &Flight,
    setup: &Setup,
    motion: Motion,
    noise: &Noise,
    method: Method,
    seeds: &[u64],
) -> Result<Vec<Run>> {
    let seeds = if method.particles().is_some() {
        seeds
    } else {
        &seeds[..seeds.len().min(1)]
    };
    seeds
        .iter()
        .map(|&s| run_method(flight, setup, motion, noise, method, s))
        .collect()
}

/// Mean of each measure over runs, in percent (RMSE in metres), with the sample sd over runs of
/// the relative error and of the RMSE, and the mean wall time.
fn summary(key: String, runs: &[Run], location: [f64; 2], paper: f64) -> Result<Row> {
    let m = runs
        .iter()
        .map(|r| measures(r, location))
        .collect::<Result<Vec<_>>>()?;
    let col = |f: fn(&Measures) -> f64, scale: f64| -> Vec<f64> {
        m.iter().map(|x| scale * f(x)).collect()
    };
    let secs: Vec<f64> = runs.iter().map(|r| r.seconds).collect();
    let (rel, rel_sd) = mean_sd(&col(|x| x.rel, 100.0));
    let (rmse, rmse_sd) = mean_sd(&col(|x| x.rmse, 1.0));
    Ok(Row::new(key)
        .set("runs", runs.len())
        .set("rel", rel)
        .set("rel_sd", rel_sd)
        .set("rel_lat", mean_sd(&col(|x| x.rel_lat, 100.0)).0)
        .set("rel_lon", mean_sd(&col(|x| x.rel_lon, 100.0)).0)
        .set("moved", mean_sd(&col(|x| x.moved, 100.0)).0)
        .set("moved_lat", mean_sd(&col(|x| x.moved_lat, 100.0)).0)
        .set("moved_lon", mean_sd(&col(|x| x.moved_lon, 100.0)).0)
        .set("rmse", rmse)
        .set("rmse_sd", rmse_sd)
        .set(
            "rmse_at_paper_here",
            mean_sd(&col(|x| x.rmse / x.rel, paper / 100.0)).0,
        )
        .set(
            "rmse_at_paper_there",
            mean_sd(&col(|x| x.rmse / x.moved, paper / 100.0)).0,
        )
        .set("seconds", mean_sd(&secs).0))
}

fn lower(m: Motion) -> String {
    m.name().to_lowercase()
}

/// The decomposition tables of the real flight: Table 3 (measure and smoother), Table 4
/// (particle count), Table 5 (observation noise). `paper` is the paper's relative error, in
/// percent.
pub(super) fn tables(
    out: &mut Computed,
    real: &FlightResult,
    setup: &Setup,
    seeds: &[u64],
    paper: f64,
) -> Result<()> {
    let flight = &real.flight;
    let here = setup.paper_location;
    let noise_of = |m: Motion| {
        real.noise
            .iter()
            .find(|(x, _)| *x == m)
            .map(|(_, q)| *q)
            .ok_or_else(|| experiment_err("no chosen noise"))
    };
    let forecast = |m: Motion, method: Method| -> Result<&[Run]> {
        find(real, m, method)
            .map(|r| r.runs.as_slice())
            .ok_or_else(|| experiment_err(format!("no {} {} run", m.name(), method.name())))
    };
    // Table 3: the forecasting runs of Table 1 and the smoothers, every measure
    let mut rows = Vec::new();
    for (m, fwd) in [
        (Motion::Cv, Forward::Kf),
        (Motion::Ct, Forward::Ukf),
        (Motion::Ct, Forward::Ekf),
    ] {
        let q = noise_of(m)?;
        let kalman = if fwd == Forward::Ekf {
            Method::Ekf
        } else {
            Method::Ukf
        };
        let fc = forecast(m, kalman)?;
        let frames = fc.first().map(|r| r.frames.clone()).unwrap_or_default();
        let name = if fwd == Forward::Ekf { "ekf" } else { "ukf" };
        rows.push(summary(
            format!("{}-{name}-forecast", lower(m)),
            fc,
            here,
            paper,
        )?);
        let sm = run_smoother(flight, setup, m, &q, fwd, &frames)?;
        let name = if fwd == Forward::Kf { "kf" } else { name };
        rows.push(summary(
            format!("{}-{name}-smoother", lower(m)),
            &[sm],
            here,
            paper,
        )?);
    }
    for m in [Motion::Cv, Motion::Ct] {
        let fc = forecast(m, Method::Mkpf(setup.particles))?;
        rows.push(summary(
            format!("{}-mkpf-forecast", lower(m)),
            fc,
            here,
            paper,
        )?);
    }
    out.table("table3").rows = rows;
    // Table 4: the MKPF's particle count
    let mut rows = Vec::new();
    for m in [Motion::Cv, Motion::Ct] {
        let q = noise_of(m)?;
        for &n in &setup.particle_counts {
            let runs = seeded_runs(flight, setup, m, &q, Method::Mkpf(n), seeds)?;
            rows.push(
                summary(format!("{}-{n}", lower(m)), &runs, here, paper)?
                    .set("model", m.name())
                    .set("particles", n),
            );
        }
    }
    out.table("table4").rows = rows;
    // Table 5: the observation noise the filters assume (the process noise chosen again)
    let mut rows = Vec::new();
    for &sd in &setup.observation_sds {
        let s = Setup {
            position_sd: sd,
            ..setup.clone()
        };
        for (m, fwd) in [(Motion::Cv, Forward::Kf), (Motion::Ct, Forward::Ukf)] {
            let q = choose_noise(flight, &s, m)?;
            let fc = seeded_runs(flight, &s, m, &q, Method::Ukf, seeds)?;
            let frames = fc.first().map(|r| r.frames.clone()).unwrap_or_default();
            let sm = run_smoother(flight, &s, m, &q, fwd, &frames)?;
            let mk = seeded_runs(flight, &s, m, &q, Method::Mkpf(setup.particles), seeds)?;
            let smoother = if fwd == Forward::Kf {
                "KF smoother"
            } else {
                "UKF smoother"
            };
            for (what, label, runs) in [
                ("ukf", "UKF", fc),
                ("smoother", smoother, vec![sm]),
                ("mkpf", "MKPF", mk),
            ] {
                rows.push(
                    summary(format!("{}-{what}-{sd}", lower(m)), &runs, here, paper)?
                        .set("model", m.name())
                        .set("method", label)
                        .set("sd", sd)
                        .set("accel", q.accel),
                );
            }
        }
    }
    out.table("table5").rows = rows;
    Ok(())
}
