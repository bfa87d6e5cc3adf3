//! The crate's user example: a predictor written against the public interface.

#[path = "../examples/own_predictor.rs"]
#[allow(dead_code)]
mod own_predictor;

use own_predictor::MeanVelocity;
use trajpred_core::{Error, Predictor, Trajectory};

#[test]
fn the_example_predictor_extrapolates_a_straight_track_exactly() {
    // 2 m/s east, 1 m/s north, a fix every 2 s: step k is 2k s after the last fix
    let times: Vec<f64> = (0..10).map(|i| 2.0 * f64::from(i)).collect();
    let points: Vec<[f64; 2]> = times.iter().map(|t| [2.0 * t, *t]).collect();
    let track = Trajectory::new(times, points).expect("valid track");
    let f = MeanVelocity { points: 4 }
        .forecast(&track, 3)
        .expect("forecast");
    for k in 1..=3 {
        let t = 18.0 + 2.0 * k as f64;
        let p = f.step(k);
        assert!(
            (p[0] - 2.0 * t).abs() < 1e-12 && (p[1] - t).abs() < 1e-12,
            "{p:?}"
        );
    }
    // too short a history is a typed error, not a panic
    let short = track.slice(0..3).expect("slice");
    assert!(matches!(
        MeanVelocity { points: 4 }.forecast(&short, 3),
        Err(Error::TooShort { .. })
    ));
}

#[test]
fn timestamps_that_go_backwards_are_refused_when_the_track_is_built() {
    let err = Trajectory::new(vec![0.0, 2.0, 1.0], vec![[0.0], [1.0], [2.0]]);
    assert!(
        matches!(err, Err(Error::NonIncreasingTime { .. })),
        "{err:?}"
    );
}
