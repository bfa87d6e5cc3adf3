//! The synthetic trajectories against values worked out by hand from the equations, and the
//! noise generator against its definition (`docs/papers.md` E).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;
use trajpred_data::noise::{add_noise_snr, noise_sigma};
use trajpred_data::synthetic::{PatentCurve, gskf_eq20};

#[test]
fn eq20_has_1000_points_at_hundredth_pi_steps() {
    let tr = gskf_eq20();
    assert_eq!((tr.len(), tr.dim()), (1000, 3));
    assert_eq!(tr.times()[0], 0.0);
    assert!((tr.times()[999] - 9.99 * PI).abs() < 1e-12);
    // i = 0: the origin
    assert_eq!(&tr.point(0)[..], &[0.0, 0.0, 0.0]);
    // i = 50, t = π/2: x = 2 sin(π/20), y = cos(π/20), z = 2 cos(π) = -2
    let p = tr.point(50);
    assert!((p[0] - 2.0 * (PI / 20.0).sin()).abs() < 1e-12);
    assert!((p[1] - (PI / 20.0).cos()).abs() < 1e-12);
    assert!((p[2] + 2.0).abs() < 1e-12);
    // i = 500, t = 5π: x = 2 sin(π/2) = 2, y = 0, z = 0
    let p = tr.point(500);
    assert!((p[0] - 2.0).abs() < 1e-12 && p[1].abs() < 1e-12 && p[2].abs() < 1e-12);
}

#[test]
fn patent_curves_follow_their_equations() {
    let h = PatentCurve::Helix.generate(1000, 0.1).unwrap();
    assert_eq!((h.len(), h.dim()), (1000, 3));
    // t = 5π (i such that 0.2 t = π is not on the grid; check t = 10: 0.2 t = 2)
    let p = h.point(100);
    assert!((p[0] - 10.0 * 2f64.cos()).abs() < 1e-12 && (p[2] - 5.0).abs() < 1e-12);
    // every helix point is 10 m from the axis
    for q in h.points() {
        assert!((q[0].hypot(q[1]) - 10.0).abs() < 1e-9);
    }
    // the figure-eight crosses itself at the origin at t = 0 and t = 50
    let f = PatentCurve::FigureEight.generate(1000, 0.1).unwrap();
    for i in [0, 500] {
        assert!(
            f.point(i).iter().all(|v| v.abs() < 1e-9),
            "{:?}",
            f.point(i)
        );
    }
    // climbing turn: radius 20 m about (0, 20) while climbing at 1 m/s, then level
    let c = PatentCurve::ClimbingTurn.generate(1000, 0.1).unwrap();
    for i in 0..600 {
        let q = c.point(i);
        assert!((q[0].hypot(q[1] - 20.0) - 20.0).abs() < 1e-9);
        assert!((q[2] - 0.1 * i as f64).abs() < 1e-9);
    }
    for i in 600..1000 {
        assert!((c.point(i)[2] - 60.0).abs() < 1e-9);
    }
    // constant ground speed R ω = 5 m/s on both sides of the roll-out
    for i in [100, 598, 600, 900] {
        let (a, b) = (c.point(i), c.point(i + 1));
        let v = (b[0] - a[0]).hypot(b[1] - a[1]) / 0.1;
        assert!((v - 5.0).abs() < 0.01, "{v} at {i}");
    }
    assert!(matches!(
        PatentCurve::Helix.generate(10, 0.0),
        Err(trajpred_data::Error::Core(
            trajpred_core::Error::InvalidParameter { name: "dt", .. }
        ))
    ));
    assert!(PatentCurve::Helix.generate(0, 0.1).is_err());
}

#[test]
fn noise_sigma_is_signal_power_over_snr() {
    // mean(x²) = (9 + 16) / 2 = 12.5; at 0 dB σ² = 12.5, at 10 dB σ² = 1.25
    assert!((noise_sigma(&[3.0, 4.0], 0.0).unwrap() - 12.5f64.sqrt()).abs() < 1e-12);
    assert!((noise_sigma(&[3.0, -4.0], 10.0).unwrap() - 1.25f64.sqrt()).abs() < 1e-12);
    assert_eq!(noise_sigma(&[0.0; 5], 10.0).unwrap(), 0.0);
    assert!(matches!(
        noise_sigma(&[1.0], f64::NAN),
        Err(trajpred_data::Error::Core(
            trajpred_core::Error::InvalidParameter { name: "snr_db", .. }
        ))
    ));
    assert!(matches!(
        noise_sigma(&[1.0, f64::INFINITY], 3.0),
        Err(trajpred_data::Error::Core(
            trajpred_core::Error::InvalidParameter { name: "signal", .. }
        ))
    ));
}

#[test]
fn measured_snr_matches_the_requested_one() {
    let n = 20_000;
    let clean = PatentCurve::Helix.generate(n, 0.01).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    for snr in [1.0, 20.0, 40.0] {
        let noisy = add_noise_snr(&clean, snr, &mut rng).unwrap();
        for k in 0..3 {
            let s = clean.axis(k);
            let ps = s.iter().map(|v| v * v).sum::<f64>() / n as f64;
            let r: Vec<f64> = noisy.axis(k).iter().zip(s).map(|(a, b)| a - b).collect();
            let mean = r.iter().sum::<f64>() / n as f64;
            let pn = r.iter().map(|v| v * v).sum::<f64>() / n as f64;
            let measured = 10.0 * (ps / pn).log10();
            // σ² estimated from 20 000 draws: relative sd sqrt(2/n) = 1%, i.e. 0.043 dB
            assert!(
                (measured - snr).abs() < 0.2,
                "axis {k}: {measured} dB vs {snr}"
            );
            assert!(mean.abs() < 5.0 * (pn / n as f64).sqrt());
        }
    }
}

#[test]
fn noise_is_reproducible_from_a_seed() {
    let clean = gskf_eq20();
    let a = add_noise_snr(&clean, 10.0, &mut ChaCha8Rng::seed_from_u64(1)).unwrap();
    let b = add_noise_snr(&clean, 10.0, &mut ChaCha8Rng::seed_from_u64(1)).unwrap();
    let c = add_noise_snr(&clean, 10.0, &mut ChaCha8Rng::seed_from_u64(2)).unwrap();
    assert_eq!(a, b);
    assert_ne!(a, c);
    assert_eq!(a.times(), clean.times());
}
