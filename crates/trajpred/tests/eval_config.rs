//! Bad evaluation settings are typed errors naming the setting, before any forecast.

use trajpred::harness::{EvalConfig, evaluate};
use trajpred::registry::{MethodOptions, build};
use trajpred::{Error, Trajectory};

#[test]
fn bad_settings_name_the_setting() {
    let track = Trajectory::uniform(
        0.0,
        1.0,
        vec![(0..30).map(f64::from).collect(), vec![0.0; 30]],
    )
    .expect("finite, increasing");
    let p = build("poly1", &MethodOptions::default()).expect("registered");
    let ok = EvalConfig::default();
    let cases = [
        ("history", EvalConfig { history: 0, ..ok }),
        ("horizon", EvalConfig { horizon: 0, ..ok }),
        ("stride", EvalConfig { stride: 0, ..ok }),
        (
            "threshold",
            EvalConfig {
                threshold: f64::NAN,
                ..ok
            },
        ),
        (
            "threshold",
            EvalConfig {
                threshold: -1.0,
                ..ok
            },
        ),
        (
            "max_origins_per_trajectory",
            EvalConfig {
                max_origins_per_trajectory: Some(0),
                ..ok
            },
        ),
    ];
    for (name, cfg) in cases {
        match evaluate(p.as_ref(), std::slice::from_ref(&track), &cfg, None) {
            Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
            other => panic!("{name}: expected InvalidParameter, got {other:?}"),
        }
    }
    // and the cap itself: 30 points, history 20, horizon 5 -> origins 19..25, capped at 2
    let capped = EvalConfig {
        max_origins_per_trajectory: Some(2),
        ..ok
    };
    let r = evaluate(p.as_ref(), &[track], &capped, None).expect("evaluates");
    assert_eq!(r.forecasts, 2);
}
