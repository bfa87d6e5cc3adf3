//! `aligned-gbm`: what it learns, that its fit does not depend on the threads, and its typed
//! errors.

use trajpred::predictors::{
    AlignedGbm, AlignedGbmParams, AlignedRidge, AlignedRidgeParams, CvTime,
};
use trajpred_core::{Error, Predictor, Trajectory};

/// Tracks that brake along a heading of their own: speed `10 - 0.2 t` m/s, heading `k`
/// radians, irregular times.
fn braking(k: usize) -> Trajectory {
    let n = 45;
    let t: Vec<f64> = (0..n)
        .map(|i| i as f64 + 0.3 * ((i * 7 + k) % 4) as f64)
        .collect();
    let s: Vec<f64> = t.iter().map(|&t| 10.0 * t - 0.1 * t * t).collect();
    let (c, sn) = ((k as f64).cos(), (k as f64).sin());
    let x = s.iter().map(|s| 50.0 * k as f64 + c * s).collect();
    let y = s.iter().map(|s| -20.0 * k as f64 + sn * s).collect();
    Trajectory::from_axes(t, vec![x, y]).expect("finite, increasing")
}

fn params() -> AlignedGbmParams {
    AlignedGbmParams {
        horizons: 5,
        min_leaf_samples: 5.0,
        iterations: 100,
        ..Default::default()
    }
}

fn fitted(threads: usize) -> AlignedGbm {
    let train: Vec<Trajectory> = (0..30).map(braking).collect();
    let mut m = AlignedGbm::new(params()).expect("valid");
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
        .install(|| m.fit(&train))
        .expect("fits");
    m
}

fn mean_error(p: &dyn Predictor, tracks: &[Trajectory]) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for tr in tracks {
        for o in [20, 25, 30] {
            let h = tr.prefix(o + 1).expect("prefix");
            let times = &tr.times()[o + 1..o + 6];
            let f = p.forecast_times(&h, times).expect("forecast");
            for (k, at) in (o + 1..o + 6).enumerate() {
                let (a, b) = (f.step(k + 1), tr.point(at));
                sum += (a[0] - b[0]).hypot(a[1] - b[1]);
                n += 1;
            }
        }
    }
    sum / n as f64
}

#[test]
fn learns_braking_that_the_last_velocity_misses_on_new_headings() {
    let m = fitted(2);
    // headings and offsets it was not trained on
    let test: Vec<Trajectory> = (40..46).map(braking).collect();
    let (gbm, cv) = (mean_error(&m, &test), mean_error(&CvTime::new(), &test));
    assert!(cv > 1.0, "cv-time {cv}");
    assert!(gbm < 0.3 * cv, "aligned-gbm {gbm} against cv-time {cv}");
}

#[test]
fn one_and_two_threads_fit_the_same_trees() {
    let (a, b) = (fitted(1), fitted(2));
    assert_eq!(
        a.fitted_params().expect("fitted"),
        b.fitted_params().expect("fitted")
    );
}

#[test]
fn bad_parameters_and_misuse_are_typed_errors() {
    let bad = |p: AlignedGbmParams, name: &str| {
        assert!(
            matches!(AlignedGbm::new(p), Err(Error::InvalidParameter { name: n, .. }) if n == name),
            "{name}"
        );
    };
    bad(
        AlignedGbmParams {
            lags: 0,
            ..params()
        },
        "lags",
    );
    bad(
        AlignedGbmParams {
            window: 1,
            ..params()
        },
        "window",
    );
    bad(
        AlignedGbmParams {
            horizons: 0,
            ..params()
        },
        "horizons",
    );
    bad(
        AlignedGbmParams {
            learning_rate: f64::NAN,
            ..params()
        },
        "learning_rate",
    );
    bad(
        AlignedGbmParams {
            max_leaves: 1,
            ..params()
        },
        "max_leaves",
    );
    bad(
        AlignedGbmParams {
            min_leaf_samples: -1.0,
            ..params()
        },
        "min_leaf_samples",
    );
    bad(
        AlignedGbmParams {
            clip_quantile: 0.4,
            ..params()
        },
        "clip_quantile",
    );
    bad(
        AlignedGbmParams {
            max_samples: 0,
            ..params()
        },
        "max_samples",
    );
    bad(
        AlignedGbmParams {
            robust_floor: 0.0,
            ..params()
        },
        "robust_floor",
    );

    let tr = braking(1);
    let h = tr.prefix(21).expect("prefix");
    let unfitted = AlignedGbm::new(params()).expect("valid");
    assert!(matches!(
        unfitted.forecast(&h, 3),
        Err(Error::NotFitted { .. })
    ));
    assert!(matches!(
        unfitted.fitted_params(),
        Err(Error::NotFitted { .. })
    ));

    let m = fitted(2);
    assert!(matches!(
        m.forecast(&h, 6),
        Err(Error::InvalidParameter {
            name: "horizon",
            ..
        })
    ));
    assert!(matches!(
        m.forecast_times(&h, &[h.times()[20]]),
        Err(Error::InvalidParameter { name: "times", .. })
    ));
    assert!(matches!(
        m.forecast(&tr.prefix(5).expect("prefix"), 2),
        Err(Error::TooShort { .. })
    ));
    // too little to train on: one short track has no origin with 8 legs behind it
    let mut short = AlignedGbm::new(params()).expect("valid");
    let tiny = tr.prefix(9).expect("prefix");
    assert!(matches!(short.fit(&[tiny]), Err(Error::TooShort { .. })));

    // saved parameters of another shape are refused, naming the field
    let saved = m.fitted_params().expect("fitted");
    let mut other = AlignedGbm::new(AlignedGbmParams {
        lags: 4,
        ..params()
    })
    .expect("valid");
    assert!(matches!(
        other.load_fitted_params(&saved),
        Err(Error::InvalidFitted { path, .. }) if path == "lags"
    ));
    let mut plain = AlignedGbm::new(AlignedGbmParams {
        shape_features: false,
        ..params()
    })
    .expect("valid");
    assert!(matches!(
        plain.load_fitted_params(&saved),
        Err(Error::InvalidFitted { path, .. }) if path == "shape_features"
    ));
    let mut broken = saved.clone();
    broken["models"] = serde_json::json!([1, 2]);
    let mut same = AlignedGbm::new(params()).expect("valid");
    assert!(matches!(
        same.load_fitted_params(&broken),
        Err(Error::InvalidFitted { path, .. }) if path == "models"
    ));
    same.load_fitted_params(&saved).expect("loads");
    assert_eq!(
        same.forecast(&h, 5).expect("forecast"),
        m.forecast(&h, 5).expect("forecast")
    );
    // the fitted one counts its training origins; the loaded one says where it came from
    let said = |p: &AlignedGbm| p.fitted_summary().expect("a summary");
    assert!(
        said(&m).contains("training origins per step ["),
        "{}",
        said(&m)
    );
    assert!(
        said(&same).contains("; loaded from saved parameters"),
        "{}",
        said(&same)
    );
}

/// Straight tracks of 10 points at 10 m/s along x on a 1 s grid (one origin with 8 legs
/// behind it, at index 8); in every fourth the last fix is 50 m ahead of where it should be
/// (a jump the history cannot foretell: the same history leads to both outcomes).
fn straight_with_jumps(k: usize) -> Trajectory {
    let n = 10;
    let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let x = t
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            10.0 * t
                + if k.is_multiple_of(4) && i == 9 {
                    50.0
                } else {
                    0.0
                }
        })
        .collect();
    Trajectory::from_axes(t, vec![x, vec![0.0; n]]).expect("finite, increasing")
}

#[test]
fn reweighted_passes_move_the_fit_from_the_mean_to_the_median() {
    // one step ahead: a quarter of the targets jump 50 m, so least squares predicts
    // 12.5 m ahead of the straight line, the median (what the mean distance wants) on it;
    // by hand, Weiszfeld's passes give 5.0, 1.79 and 0.61 m
    let train: Vec<Trajectory> = (0..40).map(straight_with_jumps).collect();
    let fit = |robust_passes: usize| {
        let mut m = AlignedGbm::new(AlignedGbmParams {
            horizons: 1,
            iterations: 50,
            min_leaf_samples: 1.0,
            clip_quantile: 1.0,
            robust_passes,
            ..Default::default()
        })
        .expect("valid");
        m.fit(&train).expect("fits");
        let h = straight_with_jumps(1).prefix(9).expect("prefix");
        m.forecast_times(&h, &[9.0]).expect("forecast").step(1)[0] - 90.0
    };
    let (mean, once, thrice) = (fit(0), fit(1), fit(3));
    assert!((mean - 12.5).abs() < 0.5, "least squares: {mean} m ahead");
    assert!(once < 10.0, "one reweighted pass: {once} m ahead");
    assert!(thrice < 0.5 * once, "three passes: {thrice} m ahead");
}

/// Tracks that turn at a constant rate, left (`side = 1`) or right (`side = -1`): 8 m/s,
/// turning 0.1 rad/s, starting on heading `k` radians, irregular times.
fn turning(k: usize, side: f64) -> Trajectory {
    let n = 45;
    let t: Vec<f64> = (0..n)
        .map(|i| i as f64 + 0.3 * ((i * 5 + k) % 4) as f64)
        .collect();
    let (v, w, h0) = (8.0, 0.1 * side, k as f64);
    let x = t
        .iter()
        .map(|&t| 40.0 * k as f64 + v / w * ((h0 + w * t).sin() - h0.sin()))
        .collect();
    let y = t
        .iter()
        .map(|&t| -30.0 * k as f64 - v / w * ((h0 + w * t).cos() - h0.cos()))
        .collect();
    Trajectory::from_axes(t, vec![x, y]).expect("finite, increasing")
}

#[test]
fn mirrored_origins_teach_the_turns_the_training_tracks_never_made() {
    // trained on left turns only; tested on right turns at new headings
    let train: Vec<Trajectory> = (0..30).map(|k| turning(k, 1.0)).collect();
    let right: Vec<Trajectory> = (40..46).map(|k| turning(k, -1.0)).collect();
    let left: Vec<Trajectory> = (40..46).map(|k| turning(k, 1.0)).collect();
    let fit = |mirror: bool| {
        let mut m = AlignedGbm::new(AlignedGbmParams { mirror, ..params() }).expect("valid");
        m.fit(&train).expect("fits");
        m
    };
    let (plain, mirrored) = (fit(false), fit(true));
    let cv = mean_error(&CvTime::new(), &right);
    let (on_plain, on_mirrored) = (mean_error(&plain, &right), mean_error(&mirrored, &right));
    assert!(cv > 1.0, "cv-time {cv}");
    // without the mirror the right turns are forecast as left turns: worse than no model
    assert!(on_plain > cv, "plain {on_plain} against cv-time {cv}");
    assert!(
        on_mirrored < 0.3 * cv,
        "mirrored {on_mirrored} against cv-time {cv}"
    );
    // and the left turns it was trained on stay learned
    let on_left = mean_error(&mirrored, &left);
    assert!(on_left < 0.3 * cv, "left turns {on_left}");
    // the mirror doubles the training origins
    let said = |m: &AlignedGbm| m.fitted_summary().expect("fitted");
    assert_ne!(said(&plain), said(&mirrored));
}

/// Tracks whose last leg misleads, as T-Drive's minutes between fixes do: a vehicle that
/// waits, then jumps a random distance back or forth along its street, at irregular times.
fn dithering(k: usize) -> Trajectory {
    let n = 45;
    let t: Vec<f64> = (0..n)
        .map(|i| 60.0 * i as f64 + 7.0 * ((i * 5 + k) % 3) as f64)
        .collect();
    let mut s = 0.0;
    let along: Vec<f64> = (0..n)
        .map(|i| {
            // a deterministic jumble of steps of -300..300 m
            s += 300.0 * (((i * 37 + k * 11) % 13) as f64 / 6.0 - 1.0);
            s
        })
        .collect();
    let (c, sn) = ((k as f64).cos(), (k as f64).sin());
    let x = along.iter().map(|s| c * s).collect();
    let y = along.iter().map(|s| sn * s).collect();
    Trajectory::from_axes(t, vec![x, y]).expect("finite, increasing")
}

/// Where the last position forecasts the training tracks better than the last velocity, the
/// corrections are added to it: it says so, beats `cv-time` by far, saves `"base":
/// "position"` and loads back to the bit; the braking tracks keep the last velocity and
/// save no `base` (files as before).
#[test]
fn the_base_follows_the_training_tracks_and_is_saved() {
    let train: Vec<Trajectory> = (0..30).map(dithering).collect();
    let test: Vec<Trajectory> = (30..36).map(dithering).collect();
    let mut m = AlignedGbm::new(params()).expect("valid");
    m.fit(&train).expect("fits");
    let said = m.fitted_summary().expect("fitted");
    assert!(said.contains("added to the last position"), "{said}");
    let mut cv = CvTime::new();
    cv.fit(&train).expect("fits");
    let (ours, theirs) = (mean_error(&m, &test), mean_error(&cv, &test));
    assert!(
        ours < 0.6 * theirs,
        "aligned-gbm {ours} m, cv-time {theirs} m"
    );
    let saved = m.fitted_params().expect("fitted");
    assert_eq!(saved["base"], "position");
    let mut loaded = AlignedGbm::new(params()).expect("valid");
    loaded.load_fitted_params(&saved).expect("loads");
    let h = test[0].prefix(30).expect("prefix");
    let times = &test[0].times()[30..35];
    let (a, b) = (
        m.forecast_times(&h, times).expect("forecast"),
        loaded.forecast_times(&h, times).expect("forecast"),
    );
    for k in 1..=5 {
        assert_eq!(a.step(k), b.step(k), "step {k}");
    }
    let mut bad = saved.clone();
    bad["base"] = "acceleration".into();
    assert!(matches!(
        loaded.load_fitted_params(&bad),
        Err(Error::InvalidFitted { path, .. }) if path == "base"
    ));
    let braking = fitted(1);
    assert!(
        braking
            .fitted_params()
            .expect("fitted")
            .get("base")
            .is_none()
    );
    let said = braking.fitted_summary().expect("fitted");
    assert!(said.contains("added to the last velocity"), "{said}");
}

/// `aligned-ridge` chooses its base by the same rule: on the dithering tracks it adds its
/// corrections to the last position, beats `cv-time`, and saves and loads the choice.
#[test]
fn aligned_ridge_chooses_its_base_the_same_way() {
    let train: Vec<Trajectory> = (0..30).map(dithering).collect();
    let test: Vec<Trajectory> = (30..36).map(dithering).collect();
    let p = AlignedRidgeParams {
        horizons: 5,
        ..Default::default()
    };
    let mut m = AlignedRidge::new(p.clone()).expect("valid");
    m.fit(&train).expect("fits");
    let said = m.fitted_summary().expect("fitted");
    assert!(said.contains("added to the last position"), "{said}");
    let (ours, theirs) = (mean_error(&m, &test), mean_error(&CvTime::new(), &test));
    assert!(
        ours < 0.6 * theirs,
        "aligned-ridge {ours} m, cv-time {theirs} m"
    );
    let saved = m.fitted_params().expect("fitted");
    assert_eq!(saved["base"], "position");
    let mut loaded = AlignedRidge::new(p).expect("valid");
    loaded.load_fitted_params(&saved).expect("loads");
    assert_eq!(mean_error(&loaded, &test), ours);
    let mut bad = saved.clone();
    bad["base"] = 3.into();
    assert!(matches!(
        loaded.load_fitted_params(&bad),
        Err(Error::InvalidFitted { path, .. }) if path == "base"
    ));
}
