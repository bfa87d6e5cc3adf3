//! The Kalman filter over actual time (`kf-cv`, `kf-ca`): forecasts at requested times, and
//! the maximum-likelihood fit of its noise recovering the noise a track was simulated with.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, Uniform};
use trajpred::predictors::{KfTime, KfTimeParams};
use trajpred_core::{Error, Predictor, Trajectory};

/// A 2-D constant-velocity track driven by continuous white-noise acceleration of density
/// `q`, observed with noise of variance `r`, at irregular intervals of 0.5..3 s. The state is
/// propagated exactly over each interval (the discretised process noise of that interval).
fn simulate(seed: u64, n: usize, q: f64, r: f64) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let gap = Uniform::new(0.5, 3.0).expect("range");
    let unit = Normal::new(0.0, 1.0).expect("normal");
    let (mut t, mut times) = (0.0, Vec::with_capacity(n));
    let mut axes = vec![Vec::with_capacity(n), Vec::with_capacity(n)];
    let mut state = [[0.0, 5.0], [0.0, -2.0]]; // per axis [position, velocity]
    for k in 0..n {
        if k > 0 {
            let dt: f64 = gap.sample(&mut rng);
            t += dt;
            // exact discretisation: Q = q [[dt^3/3, dt^2/2], [dt^2/2, dt]] via its Cholesky
            let (a, b, c) = (q * dt.powi(3) / 3.0, q * dt * dt / 2.0, q * dt);
            let l11 = a.sqrt();
            let l21 = b / l11;
            let l22 = (c - l21 * l21).sqrt();
            for s in &mut state {
                let (e1, e2): (f64, f64) = (unit.sample(&mut rng), unit.sample(&mut rng));
                s[0] += dt * s[1] + l11 * e1;
                s[1] += l21 * e1 + l22 * e2;
            }
        }
        times.push(t);
        for (a, s) in axes.iter_mut().zip(&state) {
            a.push(s[0] + r.sqrt() * unit.sample(&mut rng));
        }
    }
    Trajectory::from_axes(times, axes).expect("track")
}

#[test]
fn forecasts_at_the_requested_times() {
    // noise-free uniform motion at (3, -1) m/s, sampled irregularly
    let t = vec![0.0, 0.7, 2.0, 2.4, 4.0, 6.5, 7.0, 9.0, 9.5, 12.0];
    let x: Vec<f64> = t.iter().map(|t| 3.0 * t).collect();
    let y: Vec<f64> = t.iter().map(|t| 10.0 - t).collect();
    let tr = Trajectory::from_axes(t, vec![x, y]).expect("track");
    let p = KfTime::new(KfTimeParams {
        fit_noise: false,
        spectral_density: 0.01,
        r: 0.01,
        ..Default::default()
    })
    .expect("params");
    let f = p.forecast_times(&tr, &[13.0, 20.0]).expect("forecast");
    // the filter has converged to the velocity: 2 cm at 8 s ahead is rounding of the prior
    assert!((f.step(1)[0] - 39.0).abs() < 0.02, "{:?}", f.step(1));
    assert!((f.step(2)[0] - 60.0).abs() < 0.05, "{:?}", f.step(2));
    assert!((f.step(2)[1] + 10.0).abs() < 0.05, "{:?}", f.step(2));
    // the uncertainty grows with the time ahead
    let (c1, c2) = (f.covariance(1).expect("cov"), f.covariance(2).expect("cov"));
    assert!(c2[(0, 0)] > c1[(0, 0)]);
    // `forecast` steps by the history's mean interval: 12 s over 9 intervals
    let g = p.forecast(&tr, 3).expect("forecast");
    let dt = 12.0 / 9.0;
    assert!((g.step(3)[0] - 3.0 * (12.0 + 3.0 * dt)).abs() < 0.05);
}

#[test]
fn the_noise_fit_recovers_the_simulated_noise() {
    let (q, r) = (0.5, 16.0);
    let train: Vec<Trajectory> = (0..30).map(|s| simulate(s, 150, q, r)).collect();
    let mut p = KfTime::new(KfTimeParams::default()).expect("params");
    p.fit(&train).expect("fit");
    let (fq, fr) = (p.params().spectral_density, p.params().r);
    // 4500 fixes: the maximum-likelihood estimates are within tens of percent of the truth,
    // and the grid's last round has steps of 10^(7/486) (3 %) in q and 10^(5/486) in r
    assert!(
        (fq / q).ln().abs() < 0.4f64.ln_1p(),
        "q fitted {fq}, simulated {q}"
    );
    assert!(
        (fr / r).ln().abs() < 0.2f64.ln_1p(),
        "r fitted {fr}, simulated {r}"
    );
    // a tenfold density gives a tenfold fit
    let train: Vec<Trajectory> = (0..30)
        .map(|s| simulate(100 + s, 150, 10.0 * q, r))
        .collect();
    let mut p10 = KfTime::new(KfTimeParams::default()).expect("params");
    p10.fit(&train).expect("fit");
    let ratio = p10.params().spectral_density / fq;
    assert!((5.0..20.0).contains(&ratio), "ratio {ratio}");
}

#[test]
fn bad_settings_and_inputs_are_typed_errors() {
    for (bad, name) in [
        (
            KfTimeParams {
                derivatives: 4,
                ..Default::default()
            },
            "derivatives",
        ),
        (
            KfTimeParams {
                r: 0.0,
                ..Default::default()
            },
            "r",
        ),
        (
            KfTimeParams {
                spectral_density: f64::NAN,
                ..Default::default()
            },
            "spectral_density",
        ),
    ] {
        assert!(
            matches!(KfTime::new(bad), Err(Error::InvalidParameter { name: n, .. }) if n == name),
            "{name}"
        );
    }
    let mut p = KfTime::new(KfTimeParams::default()).expect("params");
    let one = Trajectory::uniform(0.0, 1.0, vec![vec![1.0, 2.0]]).expect("track");
    assert!(matches!(
        p.fit(std::slice::from_ref(&one)),
        Err(Error::Empty { .. })
    ));
    // a requested time before the history's end is refused, not extrapolated backwards
    assert!(p.forecast_times(&one, &[0.5]).is_err());
}

/// The predictor rebuilds its filter in place for each interval (and for each forecast
/// offset); the forecast must be, to the bit, the one of a filter built anew for every
/// interval through the driver: the same mean and covariance at every requested time.
#[test]
fn in_place_rebuilds_forecast_what_fresh_filters_forecast() {
    use nalgebra::{Matrix4, U2, U4, Vector2, Vector4};
    use trajpred_core::Gaussian;
    use trajpred_kalman::driver::{Timed, drive_each};
    use trajpred_kalman::motion::{
        KinematicLayout, StateOrder, kinematic_continuous, position_observation,
    };
    use trajpred_kalman::{Filter, KalmanError, Kf};
    let tr = simulate(7, 60, 0.8, 4.0);
    let (q, r, v0) = (0.8, 4.0, 100.0);
    let p = KfTime::new(KfTimeParams {
        fit_noise: false,
        spectral_density: q,
        r,
        initial_rate_variance: v0,
        ..Default::default()
    })
    .expect("params");
    let end = tr.times()[tr.len() - 1];
    let at = [end + 0.5, end + 2.0, end + 2.0 + 1e-9, end + 7.25];
    let ours = p.forecast_times(&tr, &at).expect("forecast");
    // by hand: a new filter for every interval, a new one for every offset
    let layout = KinematicLayout::new(2, 2, StateOrder::PositionsFirst).expect("layout");
    let make = |dt: f64| -> Result<_, KalmanError> {
        Kf::new(
            kinematic_continuous::<f64, U4>(layout, dt, q)?,
            position_observation::<f64, U4, U2>(layout, r)?,
        )
    };
    let first = tr.point(0);
    let start = Gaussian::new(
        Vector4::new(first[0], first[1], 0.0, 0.0),
        Matrix4::from_diagonal(&Vector4::new(r, r, v0, v0)),
    )
    .expect("start");
    let mut f = Timed::new(make, start);
    let z: Vec<Option<Vector2<f64>>> = (0..tr.len())
        .map(|k| Some(Vector2::new(tr.point(k)[0], tr.point(k)[1])))
        .collect();
    drive_each(&mut f, tr.times(), &z, |_, _| Ok(())).expect("runs");
    // each offset predicted by a filter of its own, from the last estimate
    let fresh: Vec<Gaussian<f64, U4>> = at
        .iter()
        .map(|t| make(t - end).and_then(|kf| kf.predict(f.state())))
        .collect::<Result<_, _>>()
        .expect("forecast");
    for (j, g) in fresh.iter().enumerate() {
        assert_eq!(ours.step(j + 1), &[g.mean[0], g.mean[1]][..], "mean {j}");
        let c = ours.covariance(j + 1).expect("covariance");
        for (a, b) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            assert_eq!(c[(a, b)], g.covariance[(a, b)], "P {j} [{a},{b}]");
        }
    }
}
