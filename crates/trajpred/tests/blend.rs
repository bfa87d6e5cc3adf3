//! `blend` (a weighted mean of methods' forecasts, weights chosen on forecasts held out by
//! group) and the harness's `collect_forecasts` it learns from.

use serde_json::json;
use trajpred::harness::{self, EvalConfig};
use trajpred::predictors::{Blend, BlendParams};
use trajpred::registry::{MethodOptions, build};
use trajpred_core::{Error, Predictor, Trajectory};

/// Track `i`: 80 points at irregular times, a curve of its own with a slowing stretch.
fn track(i: usize) -> Trajectory {
    let f = i as f64;
    let t: Vec<f64> = (0..80)
        .map(|k| k as f64 + 0.4 * ((k * 3 + i) % 4) as f64)
        .collect();
    let x = t
        .iter()
        .map(|t| (1.5 + 0.2 * f) * t + 4.0 * (0.1 * t + f).sin())
        .collect();
    let y = t
        .iter()
        .map(|t| 0.3 * t * (1.0 + (0.05 * t).cos()) + (0.3 * t + f).cos())
        .collect();
    Trajectory::from_axes(t, vec![x, y]).expect("valid track")
}

fn eval() -> EvalConfig {
    EvalConfig {
        history: 10,
        horizon: 3,
        ..EvalConfig::default()
    }
}

fn blend() -> Blend {
    let params = BlendParams {
        candidates: vec!["cv-time".into(), "last-position".into(), "poly1".into()],
        folds: 3,
        eval: eval(),
        ..BlendParams::default()
    };
    Blend::new(params, MethodOptions::default()).expect("valid blend")
}

fn fitted() -> Blend {
    let tracks: Vec<Trajectory> = (0..6).map(track).collect();
    let mut b = blend();
    b.fit_grouped(&tracks, &[0, 0, 1, 1, 2, 2]).expect("fits");
    b
}

#[test]
fn collected_forecasts_are_the_ones_evaluate_scores() {
    let p = build("poly1", &MethodOptions::default()).expect("build");
    let tracks: Vec<Trajectory> = (0..3).map(track).collect();
    let pairs = harness::collect_forecasts(p.as_ref(), &tracks, &eval())
        .expect("valid config")
        .expect("no refused forecast");
    let r = harness::evaluate(p.as_ref(), &tracks, &eval(), None).expect("evaluates");
    assert_eq!(pairs.len(), r.forecasts);
    let mut sum = 0.0;
    for (predicted, truth) in &pairs {
        for (a, b) in predicted.iter().zip(truth) {
            let (a, b) = (a.as_ref(), b.as_ref());
            sum += ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
        }
    }
    let mean = sum / (pairs.len() * 3) as f64;
    assert!(
        (mean - r.mean_euclidean_all).abs() <= 1e-12 * mean,
        "{mean} vs {}",
        r.mean_euclidean_all
    );
}

#[test]
fn a_forecast_is_the_weighted_mean_of_the_members_forecasts() {
    let b = fitted();
    let saved = b.fitted_params().expect("fitted");
    let members = saved["members"].as_array().expect("members");
    assert!(!members.is_empty());
    let whole = track(9);
    let history = whole.prefix(30).expect("prefix");
    let times = &whole.times()[30..33];
    let got = b.forecast_times(&history, times).expect("forecast");
    // the regime: how many edges the last two fixes' speed exceeds
    let n = history.len();
    let (p, q) = (history.point(n - 1), history.point(n - 2));
    let dist = p
        .as_ref()
        .iter()
        .zip(q.as_ref())
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    let speed = dist / (history.times()[n - 1] - history.times()[n - 2]);
    let regime = b.speed_edges().iter().filter(|&&e| speed > e).count();
    let mut want = [[0.0; 2]; 3];
    let mut total = [0.0; 3];
    for m in members {
        let name = m["method"].as_str().expect("name");
        let mut p = build(name, &MethodOptions::default()).expect("build");
        p.load_fitted_params(&m["params"]).expect("loads");
        let f = p.forecast_times(&history, times).expect("member forecast");
        for k in 0..3 {
            let w: f64 = m["weights"][regime][k]
                .as_str()
                .expect("exact")
                .parse()
                .expect("num");
            total[k] += w;
            for (wa, x) in want[k].iter_mut().zip(f.step(k + 1)) {
                *wa += w * x;
            }
        }
    }
    for k in 0..3 {
        assert!(
            (total[k] - 1.0).abs() < 1e-12,
            "weights of step {k} sum to {}",
            total[k]
        );
        for (&g, &w) in got.step(k + 1).iter().zip(&want[k]) {
            assert!((g - w).abs() <= 1e-9 * (1.0 + g.abs()), "{g} vs {w}");
        }
    }
    // the saved blend forecasts as the fitted one, bit for bit
    let mut loaded = blend();
    loaded.load_fitted_params(&saved).expect("loads");
    let again = loaded.forecast_times(&history, times).expect("forecast");
    assert_eq!(format!("{got:?}"), format!("{again:?}"));
    assert!(b.fitted_summary().expect("summary").contains("held-out"));
}

/// Worked by hand: two speed regimes split at 1.5 m/s. Above it, a quarter of the last
/// velocity's forecast and three quarters of the last position's at step 1, the other way
/// round at step 2; below it, the last velocity alone at step 1, the last position alone
/// at step 2.
#[test]
fn a_saved_blend_forecasts_its_hand_computed_mean() {
    let mut b = blend();
    b.load_fitted_params(&json!({"speed_edges": ["1.5"], "members": [
        {"method": "cv-time", "weights": [["1", "0"], ["0.25", "0.75"]], "params": null},
        {"method": "last-position", "weights": [["0", "1"], ["0.75", "0.25"]], "params": null},
    ]}))
    .expect("loads");
    assert_eq!(b.speed_edges(), &[1.5]);
    assert_eq!(b.weights("cv-time", 1), Some(&[0.25, 0.75][..]));
    // last fix (4, 2) at t = 2 after (2, 2) at t = 1: 2 m/s along x
    let h = Trajectory::from_axes(vec![0.0, 1.0, 2.0], vec![vec![0.0, 2.0, 4.0], vec![2.0; 3]])
        .expect("valid");
    let f = b.forecast_times(&h, &[3.0, 4.0, 6.0]).expect("forecast");
    // cv-time: x = 6, 8, 12; last position: x = 4; step 3 keeps step 2's weights
    assert_eq!(f.step(1), &[0.25 * 6.0 + 0.75 * 4.0, 2.0]);
    assert_eq!(f.step(2), &[0.75 * 8.0 + 0.25 * 4.0, 2.0]);
    assert_eq!(f.step(3), &[0.75 * 12.0 + 0.25 * 4.0, 2.0]);
    // last fix (2, 2) at t = 2 after (1, 2) at t = 1: 1 m/s, the slow regime
    let h = Trajectory::from_axes(vec![0.0, 1.0, 2.0], vec![vec![0.0, 1.0, 2.0], vec![2.0; 3]])
        .expect("valid");
    let f = b.forecast_times(&h, &[3.0, 4.0, 6.0]).expect("forecast");
    assert_eq!(f.step(1), &[3.0, 2.0]);
    assert_eq!(f.step(2), &[2.0, 2.0]);
    assert_eq!(f.step(3), &[2.0, 2.0]);
}

#[test]
fn bad_saved_blends_are_typed_errors_at_their_path() {
    let saved = fitted().fitted_params().expect("fitted");
    let first = saved["members"][0]["method"].as_str().unwrap().to_string();
    let check = |edit: &dyn Fn(&mut serde_json::Value), want_path: &str, want: &str| {
        let mut v = saved.clone();
        edit(&mut v);
        match blend().load_fitted_params(&v) {
            Err(Error::InvalidFitted {
                method,
                path,
                reason,
            }) => {
                assert_eq!(method, "blend");
                assert_eq!(path, want_path, "{reason}");
                assert!(reason.contains(want), "{reason}");
            }
            other => panic!("expected InvalidFitted at {want_path}, got {other:?}"),
        }
    };
    check(
        &|v| v["members"][0]["method"] = json!("lstm"),
        "members[0].method",
        "not among",
    );
    check(
        &|v| v["members"][0]["weights"][0][0] = json!("-0.5"),
        "members[0].weights[0][0]",
        ">= 0",
    );
    check(
        &|v| {
            let w = v["members"][0]["weights"][0][1]
                .as_str()
                .unwrap()
                .parse::<f64>()
                .unwrap();
            v["members"][0]["weights"][0][1] = json!(format!("{:?}", w + 0.25));
        },
        "members",
        "regime 0, step 2",
    );
    // edges must increase, and each member needs one weight list per regime
    check(
        &|v| v["speed_edges"] = json!(["2", "1"]),
        "speed_edges[1]",
        "must exceed",
    );
    check(
        &|v| {
            let regimes = v["members"][0]["weights"].as_array().unwrap().len();
            v["speed_edges"] = json!((0..regimes).map(|i| format!("{i}")).collect::<Vec<_>>());
        },
        "members[0].weights",
        "entries",
    );
    check(
        &|v| {
            let m = v["members"][0].clone();
            v["members"].as_array_mut().unwrap().push(m);
        },
        if saved["members"].as_array().unwrap().len() == 3 {
            "members"
        } else {
            "members[1].method"
        },
        if saved["members"].as_array().unwrap().len() == 3 {
            "entries"
        } else {
            "twice"
        },
    );
    check(&|v| v["extra"] = json!(1), "", "unknown field");
    // an error inside a member's own parameters names the path under the blend's
    if first == "poly1" || first == "cv-time" || first == "last-position" {
        check(
            &|v| v["members"][0]["params"] = json!({"a": 1}),
            "members[0].params",
            &first,
        );
    }
}

#[test]
fn bad_settings_and_unfitted_use_are_typed_errors() {
    let opts = MethodOptions::default();
    let with = |f: &dyn Fn(&mut BlendParams)| {
        let mut p = BlendParams::default();
        f(&mut p);
        Blend::new(p, opts.clone())
    };
    for (edit, name) in [
        (
            &(|p: &mut BlendParams| p.candidates.clear()) as &dyn Fn(&mut BlendParams),
            "candidates",
        ),
        (
            &|p: &mut BlendParams| p.candidates.push("auto".into()),
            "candidates",
        ),
        (&|p: &mut BlendParams| p.folds = 1, "folds"),
        (&|p: &mut BlendParams| p.rounds = 0, "rounds"),
        (&|p: &mut BlendParams| p.max_regimes = 0, "max_regimes"),
    ] {
        match with(edit) {
            Err(Error::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("expected InvalidParameter {name}, got {other:?}"),
        }
    }
    let b = blend();
    let h = track(0).prefix(20).expect("prefix");
    assert!(matches!(b.forecast(&h, 3), Err(Error::NotFitted { .. })));
    assert!(matches!(b.fitted_params(), Err(Error::NotFitted { .. })));
    // one trajectory cannot be cross-validated
    let mut b = blend();
    let tracks: Vec<Trajectory> = (0..1).map(track).collect();
    assert!(matches!(
        b.fit_grouped(&tracks, &[4]),
        Err(Error::InvalidParameter { .. })
    ));
}
