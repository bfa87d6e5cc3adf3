//! What one forecast of each Kalman-family method costs, beside the static filter step it is
//! made of, on tracks read through the GeoLife loader.
//!
//! ```text
//! cargo bench -p trajpred --bench forecast_cost
//! ```
//!
//! The fixture: 12 seeded walks (1.2-1.6 m/s, turning slowly, 5 m GPS noise, a fix every
//! 2-6 s) written as GeoLife `.plt` files into a temporary `Data/` folder and read back with
//! `dataset::load` (segments split at gaps over 60 s, which these walks never have, and of
//! at least 25 points). A forecast is history 20, horizon 5: 20 filter steps and 5 predictions for the
//! KF-dynamic forms. `kf_step/static_cv4_pos2` times one predict + update of the static
//! constant-velocity filter (`Kf` on `U4`/`U2`), so the ratio of a forecast's median to
//! 25 x that step is the forecast's overhead (issue target: at most 3x);
//! `static_ca_step_x25_per_forecast` is the same for the 6-state constant-acceleration
//! filter (`U6`/`U2`, positions first), the step kf-ca's forecasts are made of.

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{DefaultAllocator, DimName, OMatrix, OVector, U2, U4, U6, Vector2};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::Path;
use trajpred::dataset::{Dataset, Segmentation, load};
use trajpred::registry::{MethodOptions, build};
use trajpred_core::{Gaussian, Predictor, Trajectory};
use trajpred_kalman::motion::{KinematicLayout, StateOrder, kinematic, position_observation};
use trajpred_kalman::{Filter, FilterAllocator, Kf};

const HISTORY: usize = 20;
const HORIZON: usize = 5;

/// One walk as a GeoLife `.plt` file: header, then `lat,lon,0,alt,days,date,time`.
fn plt(rng: &mut ChaCha8Rng) -> String {
    let unit = |rng: &mut ChaCha8Rng| rand::RngExt::random::<f64>(rng);
    let noise = Normal::new(0.0, 5.0).expect("valid sd");
    let speed = 1.2 + 0.4 * unit(rng);
    let mut heading = std::f64::consts::TAU * unit(rng);
    let (mut x, mut y, mut t) = (0.0f64, 0.0f64, 0.0f64);
    let mut s = String::from(
        "Geolife trajectory\nWGS 84\nAltitude is in Feet\nReserved 3\n0,2,255,My Track,0,0,2,8421376\n0\n",
    );
    for _ in 0..200 {
        let dt = (2.0 + 4.0 * unit(rng)).round();
        heading += (unit(rng) - 0.5) * 0.2;
        x += speed * dt * heading.cos();
        y += speed * dt * heading.sin();
        t += dt;
        let lat = 39.98 + (y + noise.sample(rng)) / 111_320.0;
        let lon = 116.32 + (x + noise.sample(rng)) / (111_320.0 * 39.98f64.to_radians().cos());
        let days = 39744.0 + t / 86_400.0;
        let secs = t as u64 + 2 * 3600;
        let _ = writeln!(
            s,
            "{lat:.6},{lon:.6},0,492,{days:.10},2008-10-23,{:02}:{:02}:{:02}",
            secs / 3600,
            secs / 60 % 60,
            secs % 60
        );
    }
    s
}

/// The fixture's segments, loaded through the GeoLife loader.
fn fixture(dir: &Path) -> Vec<Trajectory> {
    let mut rng = ChaCha8Rng::seed_from_u64(20261203);
    let folder = dir.join("Data/000/Trajectory");
    std::fs::create_dir_all(&folder).expect("temporary folder");
    for k in 0..12 {
        std::fs::write(folder.join(format!("2008102300{k:04}.plt")), plt(&mut rng))
            .expect("fixture file");
    }
    let seg = Segmentation {
        max_gap: Some(60.0),
        min_points: HISTORY + HORIZON,
        ..Default::default()
    };
    let loaded = load(
        Dataset::Geolife,
        dir,
        &Dataset::Geolife.options(),
        &seg,
        None,
    )
    .expect("the fixture loads");
    loaded.segments.into_iter().map(|s| s.trajectory).collect()
}

/// Every history of `HISTORY` points, one per 10 points.
fn histories(tracks: &[Trajectory]) -> Vec<Trajectory> {
    tracks
        .iter()
        .flat_map(|t| {
            (HISTORY..t.len().saturating_sub(HORIZON))
                .step_by(10)
                .map(|end| t.slice(end - HISTORY..end).expect("in range"))
        })
        .collect()
}

fn cost(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let histories = histories(&fixture(dir.path()));
    let mut g = c.benchmark_group("forecast_cost");
    g.throughput(Throughput::Elements(histories.len() as u64));
    for name in [
        "kf-dynamic",
        "naive-kf",
        "kf-dynamic-literal",
        "kf-cv",
        "kf-ca",
    ] {
        let mut p = build(name, &MethodOptions::default()).expect("registered");
        p.fit(&histories[..8]).expect("fits");
        g.bench_function(name, |b| {
            b.iter(|| {
                for h in &histories {
                    black_box(p.forecast(black_box(h), HORIZON).expect("forecasts"));
                }
            })
        });
    }
    // the static steps the forecasts are made of, 25 per forecast: constant velocity for
    // the KF-dynamic forms and kf-cv, constant acceleration (6 states) for kf-ca
    g.throughput(Throughput::Elements((25 * histories.len()) as u64));
    static_steps::<U4>(&mut g, "static_step_x25_per_forecast", 2, histories.len());
    static_steps::<U6>(
        &mut g,
        "static_ca_step_x25_per_forecast",
        3,
        histories.len(),
    );
    g.finish();
}

/// 25 predict + update steps of the static 2-D kinematic filter with `derivatives` per axis
/// (positions first, positions observed with `R = 10 I`, discrete white noise 10, 3 s),
/// from a vague state, for each of `histories` forecasts.
fn static_steps<N: DimName>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    derivatives: usize,
    histories: usize,
) where
    DefaultAllocator: FilterAllocator<N, U2>,
{
    let layout = KinematicLayout::new(2, derivatives, StateOrder::PositionsFirst).expect("layout");
    let tr = kinematic::<f64, N>(layout, 3.0, 10.0).expect("transition");
    let obs = position_observation::<f64, N, U2>(layout, 10.0).expect("observation");
    let kf = Kf::new(tr, obs).expect("kf");
    let mut mean = OVector::<f64, N>::zeros();
    (mean[2], mean[3]) = (1.0, 0.5);
    let x0 = Gaussian::new(mean, OMatrix::<f64, N, N>::identity() * 100.0).expect("state");
    let z = Vector2::new(1.0, 2.0);
    g.bench_function(name, |b| {
        b.iter(|| {
            for _ in 0..histories {
                let mut s = x0.clone();
                for _ in 0..25 {
                    s = kf
                        .step(&s, Some(black_box(&z)))
                        .expect("step")
                        .into_posterior();
                }
                black_box(&s);
            }
        })
    });
}

criterion_group!(benches, cost);
criterion_main!(benches);
