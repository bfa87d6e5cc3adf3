//! The crate's user example runs, and its figures are the ones worked by hand.

#[path = "../examples/score_forecasts.rs"]
#[allow(dead_code)]
mod score_forecasts;

#[test]
fn the_scoring_example_gives_the_hand_worked_figures() {
    let s = score_forecasts::run().expect("the example runs");
    // step 1: errors 5 and 0; step 2: 10 and 5
    assert_eq!(s.per_step, vec![2.5, 7.5]);
    assert_eq!((s.ade, s.fde), (5.0, 7.5));
    // 5, 10, 0, 5 m: three of four within 6 m
    assert_eq!(s.within_6m, 0.75);
    // x errors 3, 6, 0, 0: sqrt(45 / 4); y errors 4, 8, 0, 5: sqrt(105 / 4)
    assert!((s.rmse[0] - (45.0f64 / 4.0).sqrt()).abs() < 1e-12);
    assert!((s.rmse[1] - (105.0f64 / 4.0).sqrt()).abs() < 1e-12);
    // |e|^2 / 25: 1, 4, 0, 1
    assert!((s.mean_nees - 1.5).abs() < 1e-12);
}
