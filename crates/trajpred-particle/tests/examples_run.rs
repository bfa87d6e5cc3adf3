//! The crate's user examples run, and what they show holds.

#[path = "../examples/aircraft_pf_mkpf.rs"]
#[allow(dead_code)]
mod aircraft_pf_mkpf;
#[path = "../examples/residual_resampling.rs"]
#[allow(dead_code)]
mod residual_resampling;

#[test]
fn the_bootstrap_filter_beats_the_raw_observations_and_the_mkpf_stays_bounded() {
    let s = aircraft_pf_mkpf::run(7).expect("the example runs");
    eprintln!("{s:?}");
    assert!(s.observations > 20.0 && s.observations < 40.0, "{s:?}");
    assert!(s.bootstrap < 0.8 * s.observations, "{s:?}");
    // the MKPF with the paper's settings does worse than the observations here (an open
    // finding, docs/particle.md); this guards against it diverging
    assert!(s.mkpf.is_finite() && s.mkpf < 5.0 * s.observations, "{s:?}");
    // ten steps of 200 m/s ahead, the forecasts stay within a few hundred metres
    assert!(s.bootstrap_ahead < 500.0 && s.mkpf_ahead < 1000.0, "{s:?}");
}

#[test]
fn residual_resampling_keeps_the_floors_and_draws_the_rest() {
    for seed in 0..20 {
        let copies = residual_resampling::run(seed, 20).expect("the example runs");
        let floors = residual_resampling::floors(20);
        assert_eq!(copies.iter().sum::<usize>(), 20);
        // floors 1, 8, 0, 5, 3, 2 (19 places) and one place drawn from the remainders
        assert_eq!(floors, [1, 8, 0, 5, 3, 2]);
        assert!(
            copies.iter().zip(&floors).all(|(c, f)| c >= f),
            "{copies:?}"
        );
        assert!(
            copies.iter().zip(&floors).all(|(c, f)| *c <= f + 1),
            "{copies:?}"
        );
    }
}
