//! `gsc` and `gskf` with `GskfParams::relative`: a history moved by a constant is forecast
//! moved by the same constant, and the frame travels with the saved parameters.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trajpred::predictors::{Gsc, Gskf, GskfParams};
use trajpred_core::{Error, Predictor, Trajectory};

/// A 2-D track wandering about the origin (two damped oscillations driven by seeded uniform
/// noise), 300 points 1 s apart.
fn wander(seed: u64) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut x, mut y) = (vec![0.0, 1.0], vec![0.0, -1.0]);
    for i in 2..300 {
        x.push(1.5 * x[i - 1] - 0.6 * x[i - 2] + rng.random_range(-1.0..1.0));
        y.push(1.4 * y[i - 1] - 0.5 * y[i - 2] + rng.random_range(-1.0..1.0));
    }
    Trajectory::uniform(0.0, 1.0, vec![x, y]).unwrap()
}

fn moved(tr: &Trajectory, c: [f64; 2]) -> Trajectory {
    let x = tr.axis(0).iter().map(|v| v + c[0]).collect();
    let y = tr.axis(1).iter().map(|v| v + c[1]).collect();
    Trajectory::from_axes(tr.times().to_vec(), vec![x, y]).unwrap()
}

/// A fixed frame: `relative`, without the choice.
fn params(relative: bool) -> GskfParams {
    GskfParams {
        relative,
        choose_frame: false,
        ..Default::default()
    }
}

#[test]
fn a_moved_history_is_forecast_moved_in_the_relative_frame_only() {
    let train: Vec<Trajectory> = (1..=4).map(wander).collect();
    let history = wander(9).prefix(100).unwrap();
    let c = [5_000.0, -3_000.0];
    let far = moved(&history, c);
    for relative in [true, false] {
        let mut gsc = Gsc::new(params(relative)).unwrap();
        gsc.fit(&train).unwrap();
        let mut gskf = Gskf::new(params(relative)).unwrap();
        gskf.fit(&train).unwrap();
        for p in [&gsc as &dyn Predictor, &gskf] {
            let (near, away) = (
                p.forecast(&history, 6).unwrap(),
                p.forecast(&far, 6).unwrap(),
            );
            for k in 1..=6 {
                for (d, cd) in c.iter().enumerate() {
                    let shift = away.step(k)[d] - near.step(k)[d];
                    if relative {
                        assert!((shift - cd).abs() < 1e-6, "step {k} axis {d}: {shift}");
                    } else if d == 0 && k == 1 {
                        // the paper's absolute values: the training series' level pulls
                        // the forecast (these series revert to 0), so it does not follow
                        assert!((shift - cd).abs() > 10.0, "step {k}: {shift}");
                    }
                }
            }
        }
    }
}

#[test]
fn the_frame_is_saved_and_a_mismatch_on_loading_is_refused() {
    let train: Vec<Trajectory> = (1..=4).map(wander).collect();
    let history = wander(9).prefix(100).unwrap();
    let mut rel = Gskf::new(params(true)).unwrap();
    rel.fit(&train).unwrap();
    let saved = rel.fitted_params().unwrap();
    assert_eq!(saved["axes"][0]["relative"], serde_json::json!(true));
    let mut back = Gskf::new(params(true)).unwrap();
    back.load_fitted_params(&saved).unwrap();
    assert_eq!(
        back.forecast(&history, 6).unwrap(),
        rel.forecast(&history, 6).unwrap()
    );
    // read in absolute values it would forecast wrongly: refused, naming the frames
    let mut abs = Gskf::new(params(false)).unwrap();
    match abs.load_fitted_params(&saved) {
        Err(Error::InvalidFitted { path, reason, .. }) => {
            assert_eq!(path, "axes[0]");
            assert!(
                reason.contains("fitted in the frame of each window's last value"),
                "{reason}"
            );
        }
        other => panic!("expected InvalidFitted, got {other:?}"),
    }
    // and the other way round: absolute parameters (no `relative` field, as every file
    // saved before the frame existed) into a relative gsc
    let mut plain = Gsc::new(params(false)).unwrap();
    plain.fit(&train).unwrap();
    let saved = plain.fitted_params().unwrap();
    assert!(saved["axes"][0].get("relative").is_none());
    let mut wrong = Gsc::new(params(true)).unwrap();
    assert!(matches!(
        wrong.load_fitted_params(&saved),
        Err(Error::InvalidFitted { .. })
    ));
    let mut right = Gsc::new(params(false)).unwrap();
    right.load_fitted_params(&saved).unwrap();
    assert_eq!(
        right.forecast(&history, 6).unwrap(),
        plain.forecast(&history, 6).unwrap()
    );
}

#[test]
fn by_default_held_out_groups_at_other_places_choose_the_relative_frame() {
    // five groups (users), each wandering about its own place 2 km from the next: fitted in
    // absolute values on four of them, the coder pulls a held-out group's forecast towards
    // the others' places, so the folds choose the relative frame on both axes
    let mut train = Vec::new();
    let mut groups = Vec::new();
    for g in 0..5 {
        for i in 0..2 {
            let offset = 2_000.0 * g as f64;
            train.push(moved(&wander(10 * g + i), [offset, -offset]));
            groups.push(g as usize);
        }
    }
    // the choice is the default
    let choose = GskfParams::default();
    assert!(choose.choose_frame);
    for p in [
        Box::new(Gsc::new(choose.clone()).unwrap()) as Box<dyn Predictor>,
        Box::new(Gskf::new(choose.clone()).unwrap()),
    ] {
        let mut p = p;
        p.fit_grouped(&train, &groups).unwrap();
        let said = p.fitted_summary().unwrap();
        assert!(
            said.contains("frame and LAR steps chosen per axis"),
            "{said}"
        );
        assert_eq!(said.matches("-> relative").count(), 2, "{said}");
        // a user somewhere else is forecast as it would be at the origin, moved
        let history = wander(99).prefix(100).unwrap();
        let c = [7_000.0, 3_000.0];
        let (near, far) = (
            p.forecast(&history, 3).unwrap(),
            p.forecast(&moved(&history, c), 3).unwrap(),
        );
        for k in 1..=3 {
            for (d, cd) in c.iter().enumerate() {
                assert!((far.step(k)[d] - near.step(k)[d] - cd).abs() < 1e-6);
            }
        }
        // the frames travel with the parameters: a predictor that may choose reads them back
        let saved = p.fitted_params().unwrap();
        assert_eq!(saved["axes"][1]["relative"], serde_json::json!(true));
        let mut back: Box<dyn Predictor> = if p.name() == "gsc" {
            Box::new(Gsc::new(choose.clone()).unwrap())
        } else {
            Box::new(Gskf::new(choose.clone()).unwrap())
        };
        back.load_fitted_params(&saved).unwrap();
        assert_eq!(
            back.forecast(&history, 3).unwrap(),
            p.forecast(&history, 3).unwrap()
        );
        // one set to absolute values without the choice refuses them
        let mut fixed = Gsc::new(params(false)).unwrap();
        if p.name() == "gsc" {
            assert!(matches!(
                fixed.load_fitted_params(&saved),
                Err(Error::InvalidFitted { .. })
            ));
        }
    }
    // without the choice the same data keep absolute values
    let mut plain = Gsc::new(GskfParams {
        choose_frame: false,
        ..GskfParams::default()
    })
    .unwrap();
    plain.fit_grouped(&train, &groups).unwrap();
    let said = plain.fitted_summary().unwrap();
    assert!(
        said.starts_with("LAR steps chosen") && !said.contains("relative"),
        "{said}"
    );
}
