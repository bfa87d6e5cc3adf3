//! Runs the `examples/` programs as a user would and checks what they produce.

#[path = "../examples/diabetes_path.rs"]
mod diabetes_path;
#[path = "../examples/gsc_forecast.rs"]
#[allow(dead_code)]
mod gsc_forecast;

use trajpred_sparse::PathEvent;

#[test]
fn diabetes_example_gives_the_papers_order_and_draws_the_lasso_path() {
    let svg =
        std::env::temp_dir().join(format!("trajpred_sparse_lasso_{}.svg", std::process::id()));
    let (lar, lasso) =
        diabetes_path::run(&diabetes_path::default_data(), &svg).expect("example runs");
    // Fig. 1 of the LAR paper: bmi, s5, bp, s3 enter first; LAR takes 10 steps, the lasso 12
    // (s3 leaves and comes back)
    assert_eq!(&lar.active[..4], &[2, 8, 3, 6]);
    assert_eq!((lar.n_iter, lasso.n_iter), (10, 12));
    assert!(lasso.fit.events().contains(&PathEvent::Dropped {
        feature: 6,
        step: 10
    }));
    // both end at the least-squares fit
    let (a, b) = (lar.coefs.column(10), lasso.coefs.column(12));
    assert!((a - b).amax() < 1e-9 * a.amax());
    let text = std::fs::read_to_string(&svg).expect("svg written");
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    assert_eq!(text.matches("<polyline").count(), 10);
    std::fs::remove_file(&svg).ok();
}

#[test]
fn gsc_example_beats_the_last_value_at_every_step() {
    let (gsc, last) = gsc_forecast::run().expect("example runs");
    eprintln!("gsc {gsc:?}\nlast {last:?}");
    assert_eq!(gsc.len(), gsc_forecast::HORIZONS);
    for (t, (g, l)) in gsc.iter().zip(&last).enumerate() {
        assert!(
            g < &(0.5 * l),
            "step {}: gsc {g} against last value {l}",
            t + 1
        );
    }
}
