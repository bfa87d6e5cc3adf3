//! The IMM predictor (`imm`): on a turning track its forecast follows the turn, where the
//! constant-velocity Kalman filter (`kf-cv`) runs straight on; forecasts at requested times;
//! typed errors for tracks it cannot handle.

use trajpred::predictors::{ImmParams, ImmPredictor, KfTime, KfTimeParams};
use trajpred_core::{Error, Predictor, Trajectory};

/// A target at 10 m/s turning at 0.1 rad/s, sampled at irregular times (1, 2 or 3 s apart).
fn turning(n: usize) -> Trajectory {
    let mut t = vec![0.0];
    for k in 1..n {
        t.push(t[k - 1] + [1.0, 2.0, 3.0][k % 3]);
    }
    let x = t.iter().map(|t: &f64| 100.0 * (0.1 * t).sin()).collect();
    let y = t
        .iter()
        .map(|t: &f64| 100.0 * (1.0 - (0.1 * t).cos()))
        .collect();
    Trajectory::from_axes(t, vec![x, y]).expect("track")
}

#[test]
fn on_a_turn_the_imm_forecast_follows_it_and_the_cv_filter_does_not() {
    let track = turning(40);
    let last = track.times()[39];
    let times = [last + 5.0, last + 10.0];
    let truth = |t: f64| [100.0 * (0.1 * t).sin(), 100.0 * (1.0 - (0.1 * t).cos())];
    let params = ImmParams {
        fit_noise: false,
        r: 0.01,
        spectral_density: 0.01,
        ..Default::default()
    };
    let imm = ImmPredictor::new(params).expect("imm");
    let kf = KfTime::new(KfTimeParams {
        fit_noise: false,
        r: 0.01,
        spectral_density: 0.01,
        ..Default::default()
    })
    .expect("kf");
    let err = |p: &dyn Predictor| {
        let f = p.forecast_times(&track, &times).expect("forecast");
        let (a, b) = (f.step(2), truth(times[1]));
        (a[0] - b[0]).hypot(a[1] - b[1])
    };
    // the forecast is the mixture's mean: over 10 s with a mean sojourn of 20 s about a third
    // of the weight moves to the CV mode, which runs straight; with rare switching (mean
    // sojourn 10^4 s) the turn mode alone follows the turn
    let rare = ImmPredictor::new(ImmParams {
        mean_sojourn: 1e4,
        ..params
    })
    .expect("imm");
    let (e_imm, e_rare, e_kf) = (err(&imm), err(&rare), err(&kf));
    eprintln!(
        "10 s ahead on a 0.1 rad/s turn: imm {e_imm:.2} m, imm with rare switching {e_rare:.2} m, kf-cv {e_kf:.2} m"
    );
    assert!(e_imm < 0.5 * e_kf, "imm error {e_imm} vs kf-cv {e_kf}");
    assert!(e_rare < 2.0, "imm with rare switching: error {e_rare}");
    assert!(e_kf > 30.0, "kf-cv error {e_kf}");
    let f = imm.forecast_times(&track, &times).expect("forecast");
    let (c1, c2) = (f.covariance(1).expect("cov"), f.covariance(2).expect("cov"));
    assert!(c2[(0, 0)] + c2[(1, 1)] > c1[(0, 0)] + c1[(1, 1)]);
}

#[test]
fn bad_settings_and_tracks_give_typed_errors() {
    assert!(matches!(
        ImmPredictor::new(ImmParams {
            mean_sojourn: 0.0,
            ..Default::default()
        }),
        Err(Error::InvalidParameter {
            name: "mean_sojourn",
            ..
        })
    ));
    let p = ImmPredictor::new(ImmParams {
        fit_noise: false,
        ..Default::default()
    })
    .expect("imm");
    let t3 = Trajectory::from_axes(vec![0.0, 1.0, 2.0], vec![vec![0.0; 3]; 3]).expect("3-D");
    assert!(matches!(
        p.forecast(&t3, 2),
        Err(Error::InvalidParameter { name: "dim", .. })
    ));
}
