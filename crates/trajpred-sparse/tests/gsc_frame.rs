//! Group sparse coding in the frame of each window's last value (`GscParams::relative`): a
//! shifted window gives a forecast shifted by the same amount, the full path is least
//! squares in that frame, and coders rebuilt from their parts keep the frame.

use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use trajpred_sparse::{GroupSparseCoder, Lars};

/// `x_k = keep x_{k-1} + e_k`, `x_0 = 0`, `e_k ~ N(mean, sd^2)` seeded: with `keep = 1` a
/// random walk (with drift `mean`), below 1 a series that wanders about 0.
fn series(n: usize, seed: u64, keep: f64, (mean, sd): (f64, f64)) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let e = Normal::new(mean, sd).expect("normal");
    let mut x = vec![0.0];
    for _ in 1..n {
        let last = x[x.len() - 1];
        x.push(keep * last + e.sample(&mut rng));
    }
    x
}

/// A random walk with drift near 0: x_k = x_{k-1} + 1.5 + N(0, 0.5^2).
fn walk(n: usize, seed: u64) -> Vec<f64> {
    series(n, seed, 1.0, (1.5, 0.5))
}

/// A series that wanders about 0 (x_k = 0.95 x_{k-1} + N(0, 2^2)): fitted in absolute
/// values, the coder learns to pull towards that level.
fn around_zero(n: usize, seed: u64) -> Vec<f64> {
    series(n, seed, 0.95, (0.0, 2.0))
}

#[test]
fn the_relative_frame_moves_with_the_window_and_the_absolute_one_does_not() {
    let x = around_zero(400, 7);
    let stopped = || GroupSparseCoder::params(6, 3).lars(Lars::params().max_steps(2));
    let rel = stopped().relative(true).fit(&x).expect("relative");
    let abs = stopped().fit(&x).expect("absolute");
    assert!(rel.is_relative() && !abs.is_relative());
    let w = &x[200..206];
    let c = 1.0e4;
    let shifted: Vec<f64> = w.iter().map(|v| v + c).collect();
    let (r0, r1) = (
        rel.predict(w).expect("r0"),
        rel.predict(&shifted).expect("r1"),
    );
    let (a0, a1) = (
        abs.predict(w).expect("a0"),
        abs.predict(&shifted).expect("a1"),
    );
    for t in 0..3 {
        // exact up to the rounding of values near 1e4
        assert!((r1[t] - r0[t] - c).abs() < 1e-9 * c, "t={t}");
        // in absolute values the forecast moves by c times the row's sum, which is not 1
        // here (the coder pulls towards the training level): a window 10 km away from the
        // training series is forecast with a bias of c (1 - sum of the row)
        let row_sum: f64 = abs.coefficients().row(t).iter().sum();
        assert!((row_sum - 1.0).abs() > 1e-2, "t={t}: row sum {row_sum}");
        let moved = a1[t] - a0[t];
        assert!((moved - c * row_sum).abs() < 1e-9 * c, "t={t}");
        assert!((moved - c).abs() > 100.0, "t={t}: moved {moved}");
    }
    // the last column of A is 0 in this frame (the row's own last value, 0 after the shift)
    assert!(rel.coefficients().column(5).iter().all(|&v| v == 0.0));
}

#[test]
fn the_full_relative_path_is_least_squares_on_the_shifted_rows() {
    // Reference: nalgebra's SVD solve of [1 | w_1 - w_m, ..., w_{m-1} - w_m] against
    // x_{j+m-1+t} - w_m, built here row by row (independent of the LARS code and of the
    // crate's own shifting). Tolerance 1e-8 relative, as for the absolute frame (tests/gsc.rs).
    let x = walk(300, 11);
    let (m, horizons) = (5, 4);
    let gsc = GroupSparseCoder::params(m, horizons)
        .relative(true)
        .fit(&x)
        .expect("fit");
    for t in 1..=horizons {
        let rows = x.len() - (m - 1) - t;
        let aug = DMatrix::from_fn(rows, m, |i, j| {
            if j == 0 {
                1.0
            } else {
                x[i + j - 1] - x[i + m - 1]
            }
        });
        let target = DVector::from_fn(rows, |i, _| x[i + m - 1 + t] - x[i + m - 1]);
        let ls = aug.svd(true, true).solve(&target, 1e-14).expect("ls");
        let ours = gsc.coefficients().row(t - 1);
        let scale = ls.amax();
        for k in 0..m - 1 {
            let err = (ours[k] - ls[k + 1]).abs();
            assert!(err < 1e-8 * scale, "t={t} k={k}: {err:e}");
        }
        assert_eq!(ours[m - 1], 0.0);
        assert!(
            (gsc.intercepts()[t - 1] - ls[0]).abs() < 1e-8 * scale,
            "t={t}"
        );
        // and a forecast is the last value plus the fitted shift
        let w = &x[100..100 + m];
        let by_hand = w[m - 1]
            + ls[0]
            + (0..m - 1)
                .map(|k| ls[k + 1] * (w[k] - w[m - 1]))
                .sum::<f64>();
        let p = gsc.predict(w).expect("predict")[t - 1];
        assert!((p - by_hand).abs() < 1e-8 * by_hand.abs().max(1.0), "t={t}");
    }
}

#[test]
fn a_coder_rebuilt_from_its_parts_keeps_the_frame_it_is_given() {
    let x = walk(200, 3);
    let gsc = GroupSparseCoder::params(4, 2)
        .relative(true)
        .lars(Lars::params().max_steps(2))
        .fit(&x)
        .expect("fit");
    let parts = || {
        GroupSparseCoder::from_parts(
            gsc.coefficients().clone(),
            gsc.intercepts().clone(),
            gsc.residual_variances().to_vec(),
        )
        .expect("parts")
    };
    let w = &x[50..54];
    let back = parts().in_relative_frame(true);
    assert_eq!(back.predict(w).expect("back"), gsc.predict(w).expect("gsc"));
    // read in absolute values the same coefficients forecast something else
    let wrong = parts();
    assert!(!wrong.is_relative());
    assert_ne!(
        wrong.predict(w).expect("wrong"),
        gsc.predict(w).expect("gsc")
    );
}

#[test]
fn parameters_saved_before_the_frame_existed_read_as_absolute() {
    let params = GroupSparseCoder::params(4, 2);
    let mut json = serde_json::to_value(&params).expect("to json");
    assert_eq!(json["relative"], serde_json::json!(false));
    json.as_object_mut().expect("object").remove("relative");
    let back: trajpred_sparse::GscParams = serde_json::from_value(json).expect("from json");
    assert_eq!(back, params);
}
