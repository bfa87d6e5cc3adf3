//! Segmentation and resampling: hand-worked cases and properties.

use proptest::prelude::*;
use trajpred_core::Error as CoreError;
use trajpred_core::Trajectory;
use trajpred_data::Error;
use trajpred_data::segment::{keep_min_points, resample, split_on_gaps};

#[test]
fn resample_interpolates_linearly_between_neighbours() {
    // x(t) = 0, 10, 10, 40 at t = 0, 1, 2, 5 (seconds)
    let tr = Trajectory::new(
        vec![0.0, 1.0, 2.0, 5.0],
        vec![[0.0, 1.0], [10.0, 1.0], [10.0, 2.0], [40.0, 5.0]],
    )
    .unwrap();
    let u = resample(&tr, 1.5).unwrap();
    assert_eq!(u.times(), &[0.0, 1.5, 3.0, 4.5]);
    // t = 1.5: halfway 10..10 = 10; y halfway 1..2 = 1.5
    // t = 3: a third of 2..5: x = 10 + 30/3 = 20, y = 2 + 3/3 = 3
    // t = 4.5: five sixths: x = 10 + 25 = 35, y = 2 + 2.5 = 4.5
    let want_x = [0.0, 10.0, 20.0, 35.0];
    let want_y = [1.0, 1.5, 3.0, 4.5];
    for i in 0..4 {
        assert!((u.axis(0)[i] - want_x[i]).abs() < 1e-12);
        assert!((u.axis(1)[i] - want_y[i]).abs() < 1e-12);
    }
    // a single point resamples to itself
    let one = Trajectory::new(vec![3.0], vec![[1.0]]).unwrap();
    assert_eq!(resample(&one, 1.0).unwrap(), one);
    assert!(matches!(
        resample(&tr, 0.0),
        Err(Error::Core(CoreError::InvalidParameter { name: "dt", .. }))
    ));
    assert!(matches!(
        resample(&tr, 1e-300),
        Err(Error::Core(CoreError::InvalidParameter { name: "dt", .. }))
    ));
}

#[test]
fn split_and_filter() {
    let tr = Trajectory::new(vec![0.0, 1.0, 11.0, 12.0, 13.0, 30.0], vec![[0.0]; 6]).unwrap();
    let parts = split_on_gaps(&tr, 10.0).unwrap();
    let lens: Vec<usize> = parts.iter().map(Trajectory::len).collect();
    assert_eq!(lens, vec![5, 1]); // a gap of exactly 10 s does not split
    assert_eq!(keep_min_points(parts, 2).len(), 1);
    assert!(matches!(
        split_on_gaps(&tr, -1.0),
        Err(Error::Core(CoreError::InvalidParameter {
            name: "max_gap",
            ..
        }))
    ));
}

fn trajectory() -> impl Strategy<Value = Trajectory> {
    proptest::collection::vec((0.01f64..50.0, -1e4f64..1e4), 1..40).prop_map(|steps| {
        let mut t = 0.0;
        let mut times = Vec::new();
        let mut xs = Vec::new();
        for (dt, x) in steps {
            times.push(t);
            xs.push(x);
            t += dt;
        }
        Trajectory::from_axes(times, vec![xs]).unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn split_pieces_concatenate_to_the_original(tr in trajectory(), gap in 0.5f64..60.0) {
        let parts = split_on_gaps(&tr, gap).unwrap();
        let times: Vec<f64> = parts.iter().flat_map(|p| p.times().to_vec()).collect();
        prop_assert_eq!(&times[..], tr.times());
        for p in &parts {
            prop_assert!(p.times().windows(2).all(|w| w[1] - w[0] <= gap));
        }
        for w in parts.windows(2) {
            prop_assert!(w[1].times()[0] - w[0].times()[w[0].len() - 1] > gap);
        }
    }

    #[test]
    fn resampled_values_stay_within_neighbours(tr in trajectory(), dt in 0.1f64..20.0) {
        let u = resample(&tr, dt).unwrap();
        let t = tr.times();
        prop_assert!(u.times()[0] == t[0]);
        prop_assert!(*u.times().last().unwrap() <= t[t.len() - 1]);
        prop_assert!(t[t.len() - 1] - u.times().last().unwrap() < dt * (1.0 + 1e-9));
        for (s, v) in u.times().iter().zip(u.axis(0)) {
            // the bracketing original points
            let j = t.iter().rposition(|&x| x <= *s).unwrap();
            let k = (j + 1).min(t.len() - 1);
            let (a, b) = (tr.axis(0)[j], tr.axis(0)[k]);
            prop_assert!(*v >= a.min(b) - 1e-9 && *v <= a.max(b) + 1e-9);
        }
    }
}
