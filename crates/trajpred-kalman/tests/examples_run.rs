//! The crate's user examples run, and what they show holds.

#[path = "../examples/kf_rts_geolife.rs"]
#[allow(dead_code)]
mod kf_rts_geolife;
#[path = "../examples/ukf_range_bearing.rs"]
#[allow(dead_code)]
mod ukf_range_bearing;

#[test]
fn on_a_generated_geolife_walk_smoothing_beats_filtering_which_beats_the_fixes() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let plt = dir.path().join("walk.plt");
    kf_rts_geolife::write_generated_plt(&plt).expect("write the .plt");
    let t = kf_rts_geolife::run(&plt).expect("the example runs");
    assert_eq!(t.track.len(), kf_rts_geolife::POINTS);
    let truth = kf_rts_geolife::truth();
    let raw: Vec<[f64; 2]> = (0..t.track.len())
        .map(|i| [t.track.axis(0)[i], t.track.axis(1)[i]])
        .collect();
    let (e_raw, e_f, e_s) = (
        kf_rts_geolife::rms(&raw, &truth),
        kf_rts_geolife::rms(&t.filtered, &truth),
        kf_rts_geolife::rms(&t.smoothed, &truth),
    );
    eprintln!("fixes {e_raw:.3} filtered {e_f:.3} smoothed {e_s:.3}");
    // 4 m per axis: about 5.7 m RMS for the fixes
    assert!((e_raw - 4.0 * 2f64.sqrt()).abs() < 0.8, "{e_raw}");
    assert!(e_f < 0.8 * e_raw && e_s < 0.8 * e_f, "{e_raw} {e_f} {e_s}");
}

#[test]
fn the_ukf_tracks_a_turning_aircraft_from_range_and_bearing_better_than_the_readings() {
    let mut nees = 0.0;
    for seed in 0..8 {
        let s = ukf_range_bearing::run(seed).expect("the example runs");
        eprintln!("{seed}: {s:?}");
        // 10 m in range and 2 mrad at 8 km (16 m across): about 19 m RMS for the readings
        assert!(s.readings > 14.0 && s.readings < 24.0, "{s:?}");
        assert!(s.ukf < 0.75 * s.readings, "{s:?}");
        nees += s.mean_nees / 8.0;
    }
    // an honest covariance: the mean NEES near 2 (loose bounds: 8 runs of 139 steps)
    assert!(nees > 1.0 && nees < 4.0, "{nees}");
}
