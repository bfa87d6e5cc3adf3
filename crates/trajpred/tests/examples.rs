//! The crate's user examples run, and what they show holds.

#[path = "../examples/evaluate_csv.rs"]
#[allow(dead_code)]
mod evaluate_csv;

#[test]
fn evaluating_a_csv_of_tracks_scores_every_method_on_the_held_out_tracks() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let csv = dir.path().join("tracks.csv");
    evaluate_csv::write_example_csv(&csv).expect("write the example file");
    let reports = evaluate_csv::run(&csv).expect("the example runs");
    assert_eq!(reports.len(), evaluate_csv::METHODS.len());
    // 12 tracks split at the 2-minute pause: 24 segments of 75 points, 70 % (17) tested,
    // 75 - 20 - 5 + 1 = 51 origins each
    for r in &reports {
        eprintln!(
            "{} {:.3} {:.3}",
            r.method, r.mean_euclidean_all, r.hit_rate_all
        );
        assert_eq!(
            (r.trajectories, r.forecasts, r.failures),
            (17, 17 * 51, 0),
            "{}",
            r.method
        );
        // a walker at 1.4 m/s, 1-3 s fixes, 2 m noise: within a few metres
        assert!(
            r.mean_euclidean_all < 6.0,
            "{}: {}",
            r.method,
            r.mean_euclidean_all
        );
    }
    // errors grow with the step
    let cv = &reports[0];
    assert!(
        cv.mean_euclidean.windows(2).all(|w| w[0] < w[1]),
        "{:?}",
        cv.mean_euclidean
    );
}
