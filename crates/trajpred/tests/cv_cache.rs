//! The held-out forecasts `auto` and `blend` share through `MethodOptions::held_out`: the
//! same choices and weights as without it, each candidate fitted once per fold between
//! them, and `auto`'s fold scores equal to the leaderboard's own mean error.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::sync::Arc;
use trajpred::harness::{self, EvalConfig, group_folds};
use trajpred::predictors::{Auto, AutoParams, Blend, BlendParams, HeldOutCache};
use trajpred::registry::{self, MethodOptions};
use trajpred_core::{Predictor, Trajectory};

const EVAL: EvalConfig = EvalConfig {
    history: 10,
    horizon: 3,
    stride: 1,
    threshold: 25.0,
    max_origins_per_trajectory: None,
};

const CANDIDATES: &[&str] = &["cv-time", "last-position", "poly1", "kf-cv"];

/// Tracks that walk, turn and stand, with noisy fixes at irregular times.
fn tracks(seed: u64, n: usize) -> Vec<Trajectory> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let (mut t, mut x, mut y) = (0.0, 0.0, 0.0);
            let (mut v, mut h): (f64, f64) = (
                rng.random_range(0.0..3.0),
                rng.random_range(0.0..std::f64::consts::TAU),
            );
            let (mut times, mut xs, mut ys) = (Vec::new(), Vec::new(), Vec::new());
            for _ in 0..40 {
                times.push(t);
                xs.push(x + rng.random_range(-2.0..2.0));
                ys.push(y + rng.random_range(-2.0..2.0));
                let dt = rng.random_range(1.0..3.0);
                h += rng.random_range(-0.3..0.3);
                v = (v + rng.random_range(-0.5..0.5)).max(0.0);
                x += v * h.cos() * dt;
                y += v * h.sin() * dt;
                t += dt;
            }
            Trajectory::from_axes(times, vec![xs, ys]).unwrap()
        })
        .collect()
}

fn options(cache: Option<Arc<HeldOutCache>>) -> MethodOptions {
    MethodOptions {
        eval: EVAL,
        held_out: cache,
        ..Default::default()
    }
}

fn auto(o: &MethodOptions) -> Auto {
    let params = AutoParams {
        candidates: CANDIDATES.iter().map(|s| s.to_string()).collect(),
        eval: EVAL,
        ..Default::default()
    };
    Auto::new(params, o.clone()).unwrap()
}

fn blend(o: &MethodOptions) -> Blend {
    let params = BlendParams {
        candidates: CANDIDATES.iter().map(|s| s.to_string()).collect(),
        eval: EVAL,
        ..Default::default()
    };
    Blend::new(params, o.clone()).unwrap()
}

#[test]
fn auto_and_blend_share_their_folds_and_choose_as_without() {
    let train = tracks(3, 20);
    let groups: Vec<usize> = (0..20).map(|i| i / 3).collect();
    // without a cache
    let mut a0 = auto(&options(None));
    a0.fit_grouped(&train, &groups).unwrap();
    let mut b0 = blend(&options(None));
    b0.fit_grouped(&train, &groups).unwrap();
    // with one cache for both
    let cache = Arc::new(HeldOutCache::new());
    let shared = options(Some(cache.clone()));
    let mut a1 = auto(&shared);
    a1.fit_grouped(&train, &groups).unwrap();
    let entries = cache.len();
    assert_eq!(
        entries,
        CANDIDATES.len() * 5,
        "every candidate on every fold"
    );
    assert_eq!(cache.hits(), 0);
    let mut b1 = blend(&shared);
    b1.fit_grouped(&train, &groups).unwrap();
    // the blend read every fold of every candidate from the cache
    assert_eq!(cache.hits(), entries);
    assert_eq!(cache.len(), entries);
    assert_eq!(a1.chosen(), a0.chosen());
    assert_eq!(a1.scores(), a0.scores());
    assert_eq!(b1.fitted_params().unwrap(), b0.fitted_params().unwrap());
    // other training data replace the entries instead of reading them
    let other = tracks(4, 20);
    let mut a2 = auto(&shared);
    a2.fit_grouped(&other, &groups).unwrap();
    assert_eq!(cache.hits(), entries, "no stale entry is read");
    assert_eq!(cache.len(), entries, "the old set was dropped");
    let mut a3 = auto(&options(None));
    a3.fit_grouped(&other, &groups).unwrap();
    assert_eq!(a2.scores(), a3.scores());
}

#[test]
fn a_fold_score_is_the_leaderboards_mean_error_of_that_fold() {
    let train = tracks(5, 15);
    let groups: Vec<usize> = (0..15).map(|i| i / 3).collect();
    let mut a = auto(&options(None));
    a.fit_grouped(&train, &groups).unwrap();
    // the same folds by hand: fitted on four, `harness::evaluate` on the fifth
    // groups are labelled 0..5, so a trajectory's fold is its label's
    let of_label = group_folds(5, 5, 0).unwrap();
    let fold: Vec<usize> = groups.iter().map(|&g| of_label[g]).collect();
    for s in a.scores() {
        for (f, &score) in s.fold_errors.iter().enumerate() {
            let (mut fit, mut fit_groups, mut held) = (Vec::new(), Vec::new(), Vec::new());
            for (i, tr) in train.iter().enumerate() {
                if fold[i] == f {
                    held.push(tr.clone());
                } else {
                    fit.push(tr.clone());
                    fit_groups.push(groups[i]);
                }
            }
            let mut p = registry::build(&s.method, &options(None)).unwrap();
            p.fit_grouped(&fit, &fit_groups).unwrap();
            let r = harness::evaluate(p.as_ref(), &held, &EVAL, None).unwrap();
            assert_eq!(r.forecasts, s.fold_forecasts[f], "{} fold {f}", s.method);
            let tol = 1e-12 * r.mean_euclidean_all;
            assert!(
                (r.mean_euclidean_all - score).abs() <= tol,
                "{} fold {f}: {score} against the harness's {}",
                s.method,
                r.mean_euclidean_all
            );
        }
    }
}
