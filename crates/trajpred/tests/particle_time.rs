//! The particle predictors on real time steps: minutes between fixes (as T-Drive's taxis
//! report), irregular, with the noise of each interval. Before they stepped by index with a
//! discrete `Q` plus a jitter of 1e-6, which at 300 s steps was too ill-conditioned for the
//! MKPF's transition density ("Q not positive definite") and gave the bootstrap filter errors
//! of tens of kilometres on T-Drive.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trajpred::harness::{EvalConfig, evaluate};
use trajpred::predictors::{ParticleKind, ParticleParams, ParticlePredictor};
use trajpred::registry::{MethodOptions, build};
use trajpred_core::{Predictor, Trajectory};

/// A taxi at 8 m/s along a gentle curve, fixes 30..300 s apart, 20 m GPS noise.
fn taxi(seed: u64, n: usize) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut t: f64 = 0.0;
    let (mut times, mut x, mut y) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..n {
        times.push(t);
        let heading: f64 = t / 3000.0;
        x.push(8.0 * 3000.0 * heading.sin() + 20.0 * (rng.random::<f64>() - 0.5));
        y.push(8.0 * 3000.0 * (1.0 - heading.cos()) + 20.0 * (rng.random::<f64>() - 0.5));
        t += 30.0 + 270.0 * rng.random::<f64>();
    }
    Trajectory::from_axes(times, vec![x, y]).expect("track")
}

/// The mean distance the targets cover over the forecast offsets of `cfg`: the error of
/// standing still.
fn persistence(tracks: &[Trajectory], cfg: &EvalConfig) -> f64 {
    let mut moved = 0.0;
    let mut count = 0.0;
    for tr in tracks {
        for o in cfg.origins(tr.len()) {
            for k in 1..=cfg.horizon {
                let (a, b) = (tr.point(o), tr.point(o + k));
                moved += ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
                count += 1.0;
            }
        }
    }
    moved / count
}

#[test]
fn particle_filters_run_every_minute_long_step_without_failure() {
    let tracks: Vec<Trajectory> = (0..4).map(|s| taxi(s, 40)).collect();
    let cfg = EvalConfig {
        history: 15,
        horizon: 3,
        stride: 5,
        ..EvalConfig::default()
    };
    let persistence = persistence(&tracks, &cfg);
    for name in ["pf", "mkpf"] {
        let p = build(name, &MethodOptions::default()).expect("method");
        let r = evaluate(p.as_ref(), &tracks, &cfg, None).expect("evaluates");
        assert_eq!(r.failures, 0, "{name}: {:?}", r.first_failure);
        assert!(r.forecasts > 0);
        if name == "mkpf" {
            // a filter that tracks the velocity beats standing still by a wide margin here
            assert!(
                r.mean_euclidean_all < 0.5 * persistence,
                "{name}: {} m against {persistence} m standing still",
                r.mean_euclidean_all
            );
        }
    }
    // the bootstrap filter proposes from the transition alone: with the default noise
    // density (1 m^2/s^3, for 1-5 s phone fixes) a 300 s step spreads its particles over
    // kilometres and a 3 m observation keeps almost none of them (measured: 3.5 km, worse
    // than standing still); with a density that suits minute-long steps it tracks
    let quiet = ParticlePredictor::new(ParticleParams {
        accel_density: 0.01,
        obs_var: 400.0,
        ..ParticleParams::new(ParticleKind::Bootstrap)
    })
    .expect("params");
    let r = evaluate(&quiet, &tracks, &cfg, None).expect("evaluates");
    assert_eq!(r.failures, 0);
    assert!(
        r.mean_euclidean_all < 0.5 * persistence,
        "pf: {} m against {persistence} m standing still",
        r.mean_euclidean_all
    );
}

/// With `fit_noise`, the noise the particle filters fit is the constant-velocity model's
/// maximum-likelihood fit (`kf-cv`'s), and with it the bootstrap filter tracks these
/// simulated minute-long steps that its default density (for 1-5 s phone fixes) could not:
/// fitted on other taxis, it beats standing still.
#[test]
fn particle_filters_fit_their_noise_and_track_minute_long_steps_with_it() {
    let train: Vec<Trajectory> = (10..16).map(|s| taxi(s, 40)).collect();
    let test: Vec<Trajectory> = (0..4).map(|s| taxi(s, 40)).collect();
    let cfg = EvalConfig {
        history: 15,
        horizon: 3,
        stride: 5,
        ..EvalConfig::default()
    };
    let mut kf = build("kf-cv", &MethodOptions::default()).expect("kf-cv");
    kf.fit(&train).expect("kf-cv fits");
    let kf_params = kf.fitted_params().expect("fitted");
    let persistence = persistence(&test, &cfg);
    for kind in [ParticleKind::Bootstrap, ParticleKind::Mkpf] {
        let mut p = ParticlePredictor::new(ParticleParams {
            fit_noise: true,
            ..ParticleParams::new(kind)
        })
        .expect("params");
        let name = p.name().to_string();
        p.fit(&train).expect("fits");
        let saved = p.fitted_params().expect("fitted");
        assert_eq!(
            saved["accel_density"], kf_params["spectral_density"],
            "{name}"
        );
        assert_eq!(saved["obs_var"], kf_params["r"], "{name}");
        let r = evaluate(&p, &test, &cfg, None).expect("evaluates");
        assert_eq!(r.failures, 0, "{name}: {:?}", r.first_failure);
        assert!(
            r.mean_euclidean_all < 0.5 * persistence,
            "{name}: {} m against {persistence} m standing still",
            r.mean_euclidean_all
        );
    }
    // off by default (see docs/particle.md): fit leaves the given noise alone
    let mut p = build("pf", &MethodOptions::default()).expect("pf");
    p.fit(&train).expect("fits");
    let saved = p.fitted_params().expect("params");
    assert_eq!(saved["accel_density"], "1.0");
    assert_eq!(saved["obs_var"], "10.0");
}
