//! `auto` (choice by cross-validation by group on the training part), the folds it and
//! `evaluate --folds` deal users into, and the held-out forecasts `auto` and `blend` share
//! through `MethodOptions::held_out` (the same choices and weights as without it, each
//! candidate fitted once per fold between them, fold scores equal to the leaderboard's
//! mean error).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::sync::Arc;
use trajpred::dataset::{Dataset, Segment, Segmentation};
use trajpred::harness::{self, EvalConfig, Split, group_folds, group_ids};
use trajpred::predictors::{Auto, AutoParams, Blend, BlendParams, HeldOutCache};
use trajpred::protocol::{self, MethodSpec, Protocol, Silent};
use trajpred::registry::{self, MethodOptions};
use trajpred_core::{Predictor, Trajectory};

const EVAL: EvalConfig = EvalConfig {
    history: 10,
    horizon: 3,
    stride: 1,
    threshold: 25.0,
    max_origins_per_trajectory: None,
};

/// A straight track at a random constant velocity, with irregular 1-3 s intervals: the last
/// velocity over the actual times (`cv-time`) is exact.
fn straight(rng: &mut ChaCha8Rng) -> Trajectory {
    let (vx, vy) = (rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0));
    let mut t = 0.0;
    let (mut times, mut x, mut y) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..40 {
        times.push(t);
        x.push(vx * t);
        y.push(vy * t);
        t += rng.random_range(1.0..3.0);
    }
    Trajectory::from_axes(times, vec![x, y]).unwrap()
}

/// A standing user whose fixes jump by up to 30 m: the last velocity is pure noise there, and
/// methods that stay near the last fix win by far.
fn jittery(rng: &mut ChaCha8Rng) -> Trajectory {
    let x = (0..40).map(|_| rng.random_range(-30.0..30.0)).collect();
    let y = (0..40).map(|_| rng.random_range(-30.0..30.0)).collect();
    Trajectory::uniform(0.0, 1.0, vec![x, y]).unwrap()
}

fn segment(group: &str, i: usize, trajectory: Trajectory) -> Segment {
    Segment {
        group: group.to_string(),
        id: format!("{group}-{i}"),
        frame: trajpred_data::Frame::Cartesian,
        trajectory,
    }
}

fn options() -> MethodOptions {
    MethodOptions {
        eval: EVAL,
        ..Default::default()
    }
}

fn auto_over(candidates: &[&str]) -> Auto {
    let params = AutoParams {
        candidates: candidates.iter().map(|s| s.to_string()).collect(),
        eval: EVAL,
        ..Default::default()
    };
    Auto::new(params, options()).unwrap()
}

const CANDIDATES: &[&str] = &["kf-dynamic-literal", "cv-time", "poly2"];

#[test]
fn auto_picks_the_clearly_best_candidate_and_reports_the_folds() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let train: Vec<Trajectory> = (0..12).map(|_| straight(&mut rng)).collect();
    let groups: Vec<usize> = (0..12).map(|i| i / 2).collect();
    let mut auto = auto_over(CANDIDATES);
    auto.fit_grouped(&train, &groups).unwrap();
    assert_eq!(auto.chosen(), Some("cv-time"));
    let scores = auto.scores();
    assert_eq!(scores.len(), 3);
    for s in scores {
        assert_eq!(s.fold_errors.len(), 5, "{}", s.method);
        assert!(s.failure.is_none(), "{}: {:?}", s.method, s.failure);
    }
    assert!(scores[1].pooled_error < 1e-6);
    assert!(scores[0].pooled_error > 1.0 && scores[2].pooled_error > 1e-6);
    let summary = auto.fitted_summary().unwrap();
    assert!(summary.starts_with("chose cv-time by 5-fold"), "{summary}");
    // the chosen method answers: exact on a new straight track
    let test = straight(&mut rng);
    let f = auto
        .forecast_times(&test.prefix(20).unwrap(), &test.times()[20..23])
        .unwrap();
    for (k, p) in f.points().enumerate() {
        let truth = test.point(20 + k);
        assert!((p[0] - truth[0]).abs() < 1e-6 && (p[1] - truth[1]).abs() < 1e-6);
    }
    // the same seed and data give the same choice and scores
    let mut again = auto_over(CANDIDATES);
    again.fit_grouped(&train, &groups).unwrap();
    assert_eq!(again.scores(), auto.scores());
}

#[test]
fn auto_refuses_bad_settings_and_forecasts_only_once_fitted() {
    let tr = Trajectory::uniform(0.0, 1.0, vec![vec![0.0, 1.0, 2.0]]).unwrap();
    assert!(auto_over(CANDIDATES).forecast(&tr, 1).is_err());
    for bad in [vec![], vec!["auto".to_string()], vec!["nope".to_string()]] {
        let p = AutoParams {
            candidates: bad,
            ..Default::default()
        };
        assert!(Auto::new(p, options()).is_err());
    }
    let p = AutoParams {
        folds: 1,
        ..Default::default()
    };
    assert!(Auto::new(p, options()).is_err());
    // one trajectory cannot be cross-validated; groups must match the trajectories
    let mut a = auto_over(CANDIDATES);
    assert!(matches!(
        a.fit_grouped(std::slice::from_ref(&tr), &[3]),
        Err(trajpred_core::Error::InvalidParameter { name, .. }) if name == "train"
    ));
    assert!(a.fit_grouped(&[tr], &[0, 1]).is_err());
}

#[test]
fn one_training_group_is_cross_validated_by_trajectory_and_says_so() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let train: Vec<Trajectory> = (0..6).map(|_| straight(&mut rng)).collect();
    // one user: the folds deal the trajectories themselves (before: an error)
    let mut auto = auto_over(CANDIDATES);
    auto.fit_grouped(&train, &[7; 6]).unwrap();
    assert_eq!(auto.chosen(), Some("cv-time"));
    assert!(auto.scores().iter().all(|s| s.fold_errors.len() == 5));
    let summary = auto.fitted_summary().unwrap();
    assert!(
        summary.starts_with(
            "chose cv-time by 5-fold cross-validation by trajectory (one training group)"
        ),
        "{summary}"
    );
    // several users: by group, as before
    let mut auto = auto_over(CANDIDATES);
    auto.fit_grouped(&train, &[0, 0, 1, 1, 2, 2]).unwrap();
    let summary = auto.fitted_summary().unwrap();
    assert!(
        summary.starts_with("chose cv-time by 3-fold cross-validation by group"),
        "{summary}"
    );
    // a candidate that cross-validates inside each of auto's folds (aligned-ridge), with two
    // users: each fold trains on one user, which it now folds by trajectory instead of failing
    let mut two = Vec::new();
    for _ in 0..8 {
        two.push(straight(&mut rng));
    }
    let mut auto = auto_over(&["cv-time", "aligned-ridge"]);
    auto.fit_grouped(&two, &[0, 0, 0, 0, 1, 1, 1, 1]).unwrap();
    for s in auto.scores() {
        assert!(s.failure.is_none(), "{}: {:?}", s.method, s.failure);
    }
}

fn custom_protocol(methods: &[&str]) -> Protocol {
    Protocol {
        name: "test".into(),
        description: String::new(),
        dataset: Dataset::Csv,
        load_options: Dataset::Csv.options(),
        max_units: None,
        segmentation: Segmentation {
            min_points: 13,
            ..Default::default()
        },
        train_segmentation: None,
        split: Split::ByGroup {
            train_fraction: 0.3,
            seed: 4,
        },
        max_train: None,
        max_test: None,
        histories: vec![EVAL.history],
        horizon: EVAL.horizon,
        stride: 1,
        max_origins: None,
        threshold: 25.0,
        same_origins: false,
        methods: methods
            .iter()
            .map(|m| MethodSpec {
                label: m.to_string(),
                name: m.to_string(),
                options: options(),
            })
            .collect(),
    }
}

#[test]
fn auto_in_the_evaluation_path_never_reads_the_test_users() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let segments: Vec<Segment> = (0..10)
        .flat_map(|u| (0..3).map(move |i| (u, i)))
        .map(|(u, i)| segment(&format!("user{u}"), i, straight(&mut rng)))
        .collect();
    let p = custom_protocol(&["auto"]);
    let clean = protocol::run(&p, &segments, &Silent).unwrap();
    let test_users: Vec<String> = clean.test.iter().map(|s| s.group.clone()).collect();
    assert!(test_users.len() >= 12, "most users test (30 % train)");
    // poison the test users: standing, jumping fixes, where the last velocity is the worst
    let poisoned: Vec<Segment> = segments
        .iter()
        .map(|s| match test_users.contains(&s.group) {
            true => segment(&s.group, 0, jittery(&mut rng)),
            false => s.clone(),
        })
        .collect();
    let run = protocol::run(&p, &poisoned, &Silent).unwrap();
    let summary = |r: &protocol::ProtocolRun| r.predictors[0].fitted_summary().unwrap();
    assert!(
        summary(&clean).starts_with("chose cv-time"),
        "{}",
        summary(&clean)
    );
    assert_eq!(summary(&run), summary(&clean));
    // the poison has power: fitted on every user, auto would choose another method
    let all: Vec<Trajectory> = poisoned.iter().map(|s| s.trajectory.clone()).collect();
    let mut peeking = trajpred::registry::build("auto", &options()).unwrap();
    peeking.fit_grouped(&all, &group_ids(&poisoned)).unwrap();
    let s = peeking.fitted_summary().unwrap();
    assert!(!s.starts_with("chose cv-time"), "{s}");
}

#[test]
fn folds_deal_every_user_into_exactly_one_test_part() {
    let fold = group_folds(7, 3, 9).unwrap();
    assert_eq!(fold, group_folds(7, 3, 9).unwrap());
    let sizes: Vec<usize> = (0..3)
        .map(|f| fold.iter().filter(|&&g| g == f).count())
        .collect();
    assert_eq!(sizes.iter().sum::<usize>(), 7);
    assert!(sizes.iter().all(|&n| n == 2 || n == 3), "{sizes:?}");
    assert!(group_folds(7, 1, 0).is_err() && group_folds(2, 3, 0).is_err());

    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let segments: Vec<Segment> = (0..6)
        .flat_map(|u| (0..2).map(move |i| (u, i)))
        .map(|(u, i)| segment(&format!("u{u}"), i, straight(&mut rng)))
        .collect();
    let runs =
        protocol::cross_validate(&custom_protocol(&["cv-time"]), &segments, 3, 5, &Silent).unwrap();
    assert_eq!(runs.len(), 3);
    let mut tested: Vec<String> = Vec::new();
    for r in &runs {
        assert_eq!(r.train.len() + r.test.len(), segments.len());
        for s in &r.test {
            assert!(
                r.train.iter().all(|t| t.group != s.group),
                "{} on both sides",
                s.group
            );
            tested.push(s.id.clone());
        }
    }
    tested.sort();
    let mut all: Vec<String> = segments.iter().map(|s| s.id.clone()).collect();
    all.sort();
    assert_eq!(tested, all);
}

#[test]
fn no_fold_tests_a_copy_of_one_of_its_training_segments() {
    // user "copy" holds u0's two tracks again, as GeoLife's user 059 holds files of 058
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut segments: Vec<Segment> = (0..6)
        .flat_map(|u| (0..2).map(move |i| (u, i)))
        .map(|(u, i)| segment(&format!("u{u}"), i, straight(&mut rng)))
        .collect();
    let copies: Vec<Segment> = segments[..2]
        .iter()
        .enumerate()
        .map(|(i, s)| segment("copy", i, s.trajectory.clone()))
        .collect();
    segments.extend(copies);
    let (mut straddled, mut seeds) = (0, 0);
    for seed in 0..8 {
        let runs =
            protocol::cross_validate(&custom_protocol(&["cv-time"]), &segments, 3, seed, &Silent)
                .unwrap();
        for r in &runs {
            for s in &r.test {
                assert!(
                    r.train.iter().all(|t| t.trajectory != s.trajectory),
                    "seed {seed}: {} tests a copy of a training segment",
                    s.id
                );
            }
            let r2 = r.repeats;
            assert_eq!(r.train.len() + r.test.len() + r2.total(), segments.len());
            straddled += r2.test_of_train;
        }
        seeds += 1;
    }
    // u0 and the copy fell into different folds under some seeds: then the copy on the
    // test side was left out (the copy on the training side stays)
    assert!(
        straddled > 0,
        "no seed of {seeds} put the copies in different folds"
    );
}

const SHARED_CANDIDATES: &[&str] = &["cv-time", "last-position", "poly1", "kf-cv"];

/// Tracks that walk, turn and stand, with noisy fixes at irregular times.
fn wandering(seed: u64, n: usize) -> Vec<Trajectory> {
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

fn options_with(cache: Option<Arc<HeldOutCache>>) -> MethodOptions {
    MethodOptions {
        eval: EVAL,
        held_out: cache,
        ..Default::default()
    }
}

fn shared_auto(o: &MethodOptions) -> Auto {
    let params = AutoParams {
        candidates: SHARED_CANDIDATES.iter().map(|s| s.to_string()).collect(),
        eval: EVAL,
        ..Default::default()
    };
    Auto::new(params, o.clone()).unwrap()
}

fn shared_blend(o: &MethodOptions) -> Blend {
    let params = BlendParams {
        candidates: SHARED_CANDIDATES.iter().map(|s| s.to_string()).collect(),
        eval: EVAL,
        ..Default::default()
    };
    Blend::new(params, o.clone()).unwrap()
}

#[test]
fn auto_and_blend_share_their_folds_and_choose_as_without() {
    let train = wandering(3, 20);
    let groups: Vec<usize> = (0..20).map(|i| i / 3).collect();
    // without a cache
    let mut a0 = shared_auto(&options_with(None));
    a0.fit_grouped(&train, &groups).unwrap();
    let mut b0 = shared_blend(&options_with(None));
    b0.fit_grouped(&train, &groups).unwrap();
    // with one cache for both
    let cache = Arc::new(HeldOutCache::new());
    let shared = options_with(Some(cache.clone()));
    let mut a1 = shared_auto(&shared);
    a1.fit_grouped(&train, &groups).unwrap();
    let entries = cache.len();
    assert_eq!(
        entries,
        SHARED_CANDIDATES.len() * 5,
        "every candidate on every fold"
    );
    assert_eq!(cache.hits(), 0);
    let mut b1 = shared_blend(&shared);
    b1.fit_grouped(&train, &groups).unwrap();
    // the blend read every fold of every candidate from the cache
    assert_eq!(cache.hits(), entries);
    assert_eq!(cache.len(), entries);
    assert_eq!(a1.chosen(), a0.chosen());
    assert_eq!(a1.scores(), a0.scores());
    assert_eq!(b1.fitted_params().unwrap(), b0.fitted_params().unwrap());
    // other training data replace the entries instead of reading them
    let other = wandering(4, 20);
    let mut a2 = shared_auto(&shared);
    a2.fit_grouped(&other, &groups).unwrap();
    assert_eq!(cache.hits(), entries, "no stale entry is read");
    assert_eq!(cache.len(), entries, "the old set was dropped");
    let mut a3 = shared_auto(&options_with(None));
    a3.fit_grouped(&other, &groups).unwrap();
    assert_eq!(a2.scores(), a3.scores());
}

#[test]
fn a_fold_score_is_the_leaderboards_mean_error_of_that_fold() {
    let train = wandering(5, 15);
    let groups: Vec<usize> = (0..15).map(|i| i / 3).collect();
    let mut a = shared_auto(&options_with(None));
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
            let mut p = registry::build(&s.method, &options_with(None)).unwrap();
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
