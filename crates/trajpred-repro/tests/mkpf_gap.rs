//! The decomposition of the gap to the paper's figure (`papers::mkpf::gap`, Tables 3-5): the
//! relocated relative error, the relative error by coordinate, and the smoother, on the
//! synthetic flight (no data needed); the tables themselves when the ADS-B data is present.

use std::path::PathBuf;
use trajpred_repro::papers::mkpf::experiment::{
    Method, Motion, Setup, choose_noise, run_method, synthetic_flight,
};
use trajpred_repro::papers::mkpf::gap::{Forward, measures, run_smoother};
use trajpred_repro::{Context, Paper, reproduce_into};

#[path = "../../../testing/skip.rs"]
mod skip;

fn data_dir() -> Option<PathBuf> {
    skip::shared_data("trajpred-repro/tests/mkpf_gap.rs", "adsb-traffic")
}

fn rmse(run: &trajpred_repro::papers::mkpf::experiment::Run) -> f64 {
    let e = run.errors_m();
    (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt()
}

#[test]
fn measures_split_by_coordinate_and_move_with_the_location() {
    let setup = Setup::paper().expect("the spec's settings");
    let flight = synthetic_flight(7, true, &setup).expect("flight");
    let noise = choose_noise(&flight, &setup, Motion::Cv).expect("noise");
    let run = run_method(&flight, &setup, Motion::Cv, &noise, Method::Ukf, 0).expect("ukf");
    // placed at the flight's own origin (its first observed point), nothing changes
    let m = measures(&run, flight.observed[0]).expect("measures");
    assert!((m.moved - m.rel).abs() <= 1e-9 * m.rel, "{m:?}");
    // both coordinates: the mean of the two squared relative errors
    let both = ((m.rel_lat.powi(2) + m.rel_lon.powi(2)) / 2.0).sqrt();
    assert!((both - m.rel).abs() <= 1e-12 * m.rel);
    // near Paris the longitude (about 2 degrees) dominates; at the paper's location it does not
    assert!(m.rel_lon > 5.0 * m.rel_lat);
    let there = measures(&run, setup.paper_location).expect("measures");
    assert!(there.moved < m.rel / 5.0, "{there:?}");
    assert_eq!(there.rmse, m.rmse);
}

#[test]
fn the_smoother_uses_both_sides_of_each_gap() {
    let setup = Setup::paper().expect("the spec's settings");
    let flight = synthetic_flight(7, true, &setup).expect("flight");
    let noise = choose_noise(&flight, &setup, Motion::Cv).expect("noise");
    let fc = run_method(&flight, &setup, Motion::Cv, &noise, Method::Ukf, 0).expect("ukf");
    let kf = run_smoother(&flight, &setup, Motion::Cv, &noise, Forward::Kf, &fc.frames)
        .expect("kf smoother");
    assert_eq!(kf.frames, fc.frames);
    assert_eq!(kf.truth, fc.truth);
    assert!(
        rmse(&kf) < 0.5 * rmse(&fc),
        "{} vs {}",
        rmse(&kf),
        rmse(&fc)
    );
    // the CV model is linear: the UKF's and the EKF's smoothers are the KF's, to rounding (the
    // UKF's sigma points with alpha 1e-3 have weights of about 1e6: about 1e-6 m apart here)
    for fwd in [Forward::Ukf, Forward::Ekf] {
        let other =
            run_smoother(&flight, &setup, Motion::Cv, &noise, fwd, &fc.frames).expect("smoother");
        for (a, b) in other.predicted_enu.iter().zip(&kf.predicted_enu) {
            assert!(
                (a[0] - b[0]).abs() < 1e-4 && (a[1] - b[1]).abs() < 1e-4,
                "{fwd:?} {a:?} {b:?}"
            );
        }
    }
    // no linear KF for the coordinated turn
    let ct = choose_noise(&flight, &setup, Motion::Ct).expect("noise");
    assert!(run_smoother(&flight, &setup, Motion::Ct, &ct, Forward::Kf, &fc.frames).is_err());
    let ukf = run_smoother(&flight, &setup, Motion::Ct, &ct, Forward::Ukf, &fc.frames)
        .expect("ukf smoother");
    assert!(rmse(&ukf) < rmse(&fc));
}

#[test]
fn the_decomposition_tables_come_with_the_data() {
    let Some(d) = data_dir() else { return };
    let ctx = Context {
        quick: true,
        data_dir: Some(d),
        ..Context::default()
    };
    let dir = tempfile::tempdir().expect("tempdir");
    reproduce_into(Paper::Mkpf, &ctx, dir.path(), "test").expect("run");
    for t in ["table3", "table4", "table5"] {
        assert!(
            dir.path().join("mkpf").join(format!("{t}.csv")).is_file(),
            "{t}"
        );
    }
}
