//! The flights of the MKPF experiment: the synthetic coordinated-turn flight, the real ADS-B
//! flight chosen by a fixed rule, and the local east-north frame both are filtered in.

use super::experiment::{Setup, experiment_err};
use crate::Result;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::path::Path;
use trajpred_data::geodesy::{Enu, Geodetic, LocalFrame};
use trajpred_data::{LoadOptions, Projection, adsb};

/// A flight: per frame the time, the observed position and the true position, both as
/// geodetic `[latitude, longitude]` in degrees. For real data the two are the same reports;
/// the synthetic flight observes the truth with noise.
#[derive(Debug, Clone, PartialEq)]
pub struct Flight {
    /// What it is (file and flight, or the synthetic scenario).
    pub name: String,
    /// Seconds (from the first frame for synthetic data, Unix time for real data).
    pub times: Vec<f64>,
    /// Observed `[lat, lon]`, degrees.
    pub observed: Vec<[f64; 2]>,
    /// True `[lat, lon]`, degrees (what the predictions are compared with).
    pub truth: Vec<[f64; 2]>,
}

/// The flight's local frame: east-north-up at the first observed point, height 0.
pub fn local_frame(flight: &Flight) -> Result<LocalFrame> {
    let first = flight
        .observed
        .first()
        .ok_or_else(|| experiment_err("empty flight"))?;
    Ok(LocalFrame::new(Geodetic::new(first[0], first[1], 0.0)?)?)
}

/// `[lat, lon]` at height 0 to local `[east, north]` metres.
pub fn to_local(frame: &LocalFrame, p: [f64; 2]) -> Result<[f64; 2]> {
    let e = frame.to_enu(&Geodetic::new(p[0], p[1], 0.0)?);
    Ok([e.east, e.north])
}

/// Local `[east, north]` metres back to `[lat, lon]` at height 0: the `up` coordinate of the
/// point at height 0 is found by fixed-point iteration (the tangent plane drops below the
/// ellipsoid with distance), so a round trip through [`to_local`] returns the input.
pub fn to_geodetic(frame: &LocalFrame, p: [f64; 2]) -> [f64; 2] {
    let mut up = 0.0;
    let mut g = frame.to_geodetic(&Enu {
        east: p[0],
        north: p[1],
        up,
    });
    for _ in 0..4 {
        let on_ellipsoid = Geodetic { alt_m: 0.0, ..g };
        up = frame.to_enu(&on_ellipsoid).up;
        g = frame.to_geodetic(&Enu {
            east: p[0],
            north: p[1],
            up,
        });
    }
    [g.lat_deg, g.lon_deg]
}

/// The best piece so far: length, flight id, times, positions, repeated reports dropped.
type Piece = (usize, String, Vec<f64>, Vec<[f64; 2]>, usize);

/// The synthetic flight: a coordinated-turn target at `speed` m/s, 1 s frames, straight legs
/// and turns of both signs, observed with Gaussian noise of `sd` metres per axis, placed at
/// `setup.synthetic_origin`, with noise sd `setup.position_sd`. `quick` halves its length.
pub fn synthetic_flight(seed: u64, quick: bool, setup: &Setup) -> Result<Flight> {
    let sd = setup.position_sd;
    // (duration s, turn rate deg/s)
    let legs: &[(usize, f64)] = &[
        (200, 0.0),
        (60, 3.0),
        (150, 0.0),
        (120, -1.5),
        (100, 0.0),
        (90, 2.0),
        (180, 0.0),
        (45, -3.0),
        (106, 0.0),
    ];
    let speed = 120.0;
    let total: usize = legs.iter().map(|l| l.0).sum();
    let len = if quick { total / 2 + 1 } else { total + 1 };
    let origin = Geodetic::new(setup.synthetic_origin[0], setup.synthetic_origin[1], 0.0)?;
    let frame = LocalFrame::new(origin)?;
    let noise = Normal::new(0.0, sd).map_err(|e| experiment_err(e.to_string()))?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed_f11e);
    let (mut x, mut y, mut heading) = (-20_000.0f64, -5_000.0f64, 0.3f64);
    let mut rates = legs
        .iter()
        .flat_map(|&(n, r)| std::iter::repeat_n(r.to_radians(), n));
    let mut flight = Flight {
        name: format!(
            "synthetic coordinated-turn flight, {speed} m/s, 1 s frames, noise sd {sd} m"
        ),
        times: Vec::with_capacity(len),
        observed: Vec::with_capacity(len),
        truth: Vec::with_capacity(len),
    };
    for k in 0..len {
        let obs = [x + noise.sample(&mut rng), y + noise.sample(&mut rng)];
        flight.times.push(k as f64);
        flight.truth.push(to_geodetic(&frame, [x, y]));
        flight.observed.push(to_geodetic(&frame, obs));
        let w = rates.next().unwrap_or(0.0);
        // exact coordinated turn over 1 s
        let (vx, vy) = (speed * heading.cos(), speed * heading.sin());
        if w.abs() < 1e-12 {
            x += vx;
            y += vy;
        } else {
            let (s, c) = w.sin_cos();
            x += s / w * vx - (1.0 - c) / w * vy;
            y += (1.0 - c) / w * vx + s / w * vy;
        }
        heading += w;
    }
    Ok(flight)
}

/// How the real flight was chosen, for the results.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightChoice {
    /// The flight.
    pub flight: Flight,
    /// File, flight id, counts and times, in words.
    pub description: String,
}

/// Loads `setup.adsb_file` and picks the flight by a fixed rule: in every `(icao24, callsign)`
/// flight, drop reports that repeat the previous position (OpenSky re-sends the last
/// position when no new one came), split where fresh reports are more than `setup.max_gap_s`
/// apart, and take the longest piece (ties: the smallest id). `max_frames` cuts it (quick
/// runs).
pub fn load_flight(dir: &Path, setup: &Setup, max_frames: Option<usize>) -> Result<FlightChoice> {
    let path = dir.join(&setup.adsb_file);
    let opts = LoadOptions {
        projection: Projection::Geodetic,
        altitude: false,
        ..LoadOptions::default()
    };
    let (tracks, _report) = adsb::load_file(&path, &opts)?;
    let mut best: Option<Piece> = None;
    for track in &tracks {
        let t = track.trajectory.times();
        let (lat, lon) = (track.trajectory.axis(0), track.trajectory.axis(1));
        let mut pieces: Vec<(Vec<f64>, Vec<[f64; 2]>)> = vec![(Vec::new(), Vec::new())];
        let mut repeated = 0usize;
        for i in 0..t.len() {
            let p = [lat[i], lon[i]];
            let Some(cur) = pieces.last_mut() else {
                continue;
            };
            if let (Some(lt), Some(lp)) = (cur.0.last(), cur.1.last()) {
                if *lp == p {
                    repeated += 1;
                    continue;
                }
                if t[i] - lt > setup.max_gap_s {
                    pieces.push((Vec::new(), Vec::new()));
                }
            }
            if let Some(cur) = pieces.last_mut() {
                cur.0.push(t[i]);
                cur.1.push(p);
            }
        }
        for (times, pts) in pieces {
            let better = match &best {
                None => true,
                Some((n, id, ..)) => pts.len() > *n || (pts.len() == *n && track.id < *id),
            };
            if better && !pts.is_empty() {
                best = Some((pts.len(), track.id.clone(), times, pts, repeated));
            }
        }
    }
    let (_, id, mut times, mut pts, repeated) =
        best.ok_or_else(|| experiment_err(format!("{}: no flight", path.display())))?;
    let full = pts.len();
    if let Some(m) = max_frames {
        times.truncate(m);
        pts.truncate(m);
    }
    let description = format!(
        "{} (adsb-traffic, OpenSky Network via the traffic package; not redistributed): flight \
         {id}, the longest run of fresh position reports in the file ({full} reports, gaps at \
         most {} s; {repeated} repeated positions of that flight dropped); {} frames \
         used, Unix time {:.0} to {:.0}",
        path.display(),
        setup.max_gap_s,
        pts.len(),
        times.first().copied().unwrap_or(f64::NAN),
        times.last().copied().unwrap_or(f64::NAN),
    );
    Ok(FlightChoice {
        flight: Flight {
            name: format!("ADS-B flight {id}"),
            times,
            truth: pts.clone(),
            observed: pts,
        },
        description,
    })
}
