//! A protocol's training segmentation ([`Protocol::train_segmentation`], the command line's
//! `--train-max-gap`): the training part is cut from the training users' tracks another way,
//! the test part stays what the protocol's own segmentation and split make it, and a fit
//! records what its methods saw under both cuts.

use trajpred::dataset::{Dataset, Segment, Segmentation};
use trajpred::harness::{self, Split};
use trajpred::params;
use trajpred::protocol::{self, Protocol, Silent};
use trajpred::registry::MethodOptions;
use trajpred_core::{Error, Trajectory};

/// A straight walk of `n` points of user `group`, starting at `t0`.
fn walk(group: &str, id: &str, t0: f64, n: usize) -> Segment {
    let t: Vec<f64> = (0..n).map(|k| t0 + 2.0 * k as f64).collect();
    let x = t.iter().map(|t| 1.5 * t).collect();
    let y = t.iter().map(|t| 0.1 * t * t.sin()).collect();
    Segment {
        group: group.into(),
        id: id.into(),
        frame: trajpred_data::Frame::Cartesian,
        trajectory: Trajectory::from_axes(t, vec![x, y]).expect("valid"),
    }
}

/// Six users, each with two halves of a track (the protocol's cut, split at a pause) and
/// the whole track (the longer gap's cut); user `z` has only a whole track.
fn data() -> (Vec<Segment>, Vec<Segment>) {
    let users = ["a", "b", "c", "d", "e", "f"];
    let mut halves = Vec::new();
    let mut whole = Vec::new();
    for (i, u) in users.iter().enumerate() {
        let t0 = 1000.0 * i as f64;
        halves.push(walk(u, &format!("{u}@0"), t0, 20));
        halves.push(walk(u, &format!("{u}@1"), t0 + 100.0, 20));
        whole.push(walk(u, &format!("{u}-whole"), t0, 45));
    }
    whole.push(walk("z", "z-whole", 9000.0, 45));
    (halves, whole)
}

fn protocol(split: Split, cut: bool) -> Protocol {
    let seg = Segmentation {
        max_gap: Some(5.0),
        min_points: 16,
        ..Segmentation::default()
    };
    let options = MethodOptions::default();
    Protocol {
        train_segmentation: cut.then_some(Segmentation {
            max_gap: Some(120.0),
            ..seg
        }),
        ..protocol::custom(Dataset::Csv, &["cv-time"], &options, seg, split, 10, 3)
    }
}

fn ids(s: &[Segment]) -> Vec<&str> {
    let mut v: Vec<&str> = s.iter().map(|s| s.id.as_str()).collect();
    v.sort_unstable();
    v
}

const BY_USER: Split = Split::ByGroup {
    train_fraction: 0.5,
    seed: 7,
};

#[test]
fn the_training_part_comes_from_the_training_users_other_cut_and_the_test_part_is_unchanged() {
    let (halves, whole) = data();
    let plain = protocol(BY_USER, false);
    let cut = protocol(BY_USER, true);
    cut.validate().expect("valid");
    assert!(
        cut.describe()
            .contains("training tracks cut at: max gap 120 s")
    );
    assert!(!plain.describe().contains("training tracks cut"));
    let (plain_train, plain_test, _) = protocol::split_counted(&plain, &halves).expect("split");
    let (train, test, _) =
        protocol::split_with_pool(&cut, &halves, Some(&whole)).expect("split with the pool");
    assert_eq!(ids(&test), ids(&plain_test));
    // the whole tracks of the training users, and of no one else (not z, who is on
    // neither side of the split)
    let mut users: Vec<&str> = plain_train.iter().map(|s| s.group.as_str()).collect();
    users.sort_unstable();
    users.dedup();
    let expected: Vec<String> = users.iter().map(|u| format!("{u}-whole")).collect();
    assert_eq!(ids(&train), expected);
    assert_eq!(users.len(), 3);
    // with no split, the whole pool trains
    let none = protocol(Split::None, true);
    let (train, _, _) = protocol::split_with_pool(&none, &halves, Some(&whole)).expect("split");
    assert_eq!(train.len(), 7);
}

#[test]
fn a_training_cut_needs_its_segments_and_a_split_by_user() {
    let (halves, whole) = data();
    let cut = protocol(BY_USER, true);
    let refused = |r: Result<_, Error>| {
        matches!(
            r,
            Err(Error::InvalidParameter {
                name: "train_segmentation",
                ..
            })
        )
    };
    assert!(refused(protocol::split_counted(&cut, &halves).map(|_| ())));
    let plain = protocol(BY_USER, false);
    assert!(refused(
        protocol::split_with_pool(&plain, &halves, Some(&whole)).map(|_| ())
    ));
    let by_track = protocol(
        Split::ByTrajectory {
            train_fraction: 0.5,
            seed: 7,
        },
        true,
    );
    assert!(refused(by_track.validate()));
    assert!(refused(
        protocol::run(&by_track, &halves, &Silent).map(|_| ())
    ));
}

#[test]
fn a_fit_on_the_other_cut_records_it_and_every_segment_it_saw_under_both() {
    let (halves, whole) = data();
    let cut = protocol(BY_USER, true);
    let file = params::fit(&cut, "data".as_ref(), &halves, Some(&whole), &Silent).expect("fit");
    assert_eq!(file.fitted_on.train_segmentation, cut.train_segmentation);
    assert_eq!(file.fitted_on.train_segments, 3);
    assert_eq!(file.fitted_on.train_points, 3 * 45);
    // the three whole tracks and the six halves of the same users
    let plain = protocol(BY_USER, false);
    let (plain_train, plain_test, _) = protocol::split_counted(&plain, &halves).expect("split");
    let (train, _, _) = protocol::split_with_pool(&cut, &halves, Some(&whole)).expect("split");
    let mut expected: Vec<u64> = plain_train
        .iter()
        .chain(&train)
        .map(harness::segment_fingerprint)
        .collect();
    expected.sort_unstable();
    assert_eq!(file.fitted_on.train_fingerprints, expected);
    // saved and loaded, it tests on the protocol's test part, whatever the cut
    let bytes = file.to_json().expect("json");
    let file = params::ParamsFile::from_slice(&bytes, "p.json").expect("loads");
    let (run, seen) = file.evaluate(&cut, &halves, &Silent).expect("evaluate");
    assert_eq!(seen, 0);
    assert_eq!(ids(&run.test), ids(&plain_test));
    // and leaves out a training user's half wherever it is found again
    let (run, seen) = file
        .evaluate(&protocol(Split::None, false), &halves, &Silent)
        .expect("evaluate everything");
    assert_eq!(seen, 6);
    assert_eq!(run.test.len(), 6);
}
