//! The single-precision screen of a wide LAR path (`LarsParams::screen`, `src/lars/screen.rs`)
//! changes the speed only: on wide designs (`p > n`, where it is on) the screened and the
//! unscreened path add the same variables at the same steps and agree to rounding.
//!
//! Tolerance: 1e-10 relative (to the largest alpha and coefficient) on every knot, or, on the
//! last knots of a path that nears `n` variables (where the unscreened paths with and without
//! the Gram matrix differ by up to 1e-9 relative), twice that difference. The two paths take
//! the correlations of some columns by different roundings (the screen recomputes them from
//! the residual, the unscreened path carries them by updates); a screen that used its
//! single-precision products anywhere but to rule columns out would differ by ~1e-7 from the
//! first knots on.

use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use trajpred_sparse::{Gram, Lars, LarsParams, Method};

/// A wide design: `n x p` Gaussian columns, with `shared` of a common factor in every column
/// (correlated columns give close step lengths), and a target of `k` true columns plus noise.
fn design(n: usize, p: usize, shared: f64, k: usize, seed: u64) -> (DMatrix<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut g = || -> f64 { StandardNormal.sample(&mut rng) };
    let factor: Vec<f64> = (0..n).map(|_| g()).collect();
    let mut x = DMatrix::zeros(n, p);
    for j in 0..p {
        for i in 0..n {
            x[(i, j)] = shared * factor[i] + g();
        }
    }
    let y: Vec<f64> = (0..n)
        .map(|i| {
            (0..k)
                .map(|j| x[(i, j * 7 % p)] * (1.0 + j as f64))
                .sum::<f64>()
                + g()
        })
        .collect();
    (x, y)
}

fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.map(f64::abs).fold(0.0, f64::max)
}

/// The knots up to the first whose alpha is at most `1e-8` of the first (the fit is then
/// exact: on a wide design with an intercept, after `n - 1` variables), or all of them.
fn substantive(fit: &Lars) -> usize {
    let a0 = fit.alphas()[0];
    fit.alphas()
        .iter()
        .position(|&a| a <= 1e-8 * a0)
        .map_or(fit.n_knots(), |k| k + 1)
}

/// Largest |a - b| over row `k` of two coefficient paths.
fn knot_diff(a: &Lars, b: &Lars, k: usize) -> f64 {
    max_abs(
        a.coef_path()
            .row(k)
            .iter()
            .zip(b.coef_path().row(k).iter())
            .map(|(x, y)| x - y),
    )
}

/// The same variables added at the same steps and the same knots up to where the fit is
/// exact (the knots after it, if any, have alphas of rounding size in both paths and columns
/// excluded as collinear by rounding, so they are not compared). Each knot's coefficients
/// agree to 1e-10 of the largest, or, where the active set nears `n` and the path's own
/// rounding grows, to twice what the unscreened path with the Gram matrix (`reference`: other
/// roundings, the same arithmetic) differs from the unscreened one without it.
fn assert_same_path(a: &Lars, b: &Lars, reference: &Lars, what: &str) {
    let m = substantive(b);
    assert_eq!(substantive(a), m, "{what}: knots to an exact fit");
    let added = |f: &Lars| -> Vec<trajpred_sparse::PathEvent> {
        f.events()
            .iter()
            .filter(|e| matches!(e, trajpred_sparse::PathEvent::Added { step, .. } if *step < m))
            .cloned()
            .collect()
    };
    assert_eq!(added(a), added(b), "{what}: variables added");
    if m == b.n_knots() {
        assert_eq!(a.n_knots(), m, "{what}: knots");
        assert_eq!(a.events(), b.events(), "{what}: events");
        assert_eq!(a.stop_reason(), b.stop_reason(), "{what}: stop reason");
    }
    let scale = b.alphas()[0];
    for k in 0..m {
        let (x, y) = (a.alphas()[k], b.alphas()[k]);
        assert!(
            (x - y).abs() <= 1e-10 * scale,
            "{what}: alpha {k}: {x} against {y}"
        );
    }
    let scale = max_abs(b.coef_path().rows(0, m).iter().copied());
    for k in 0..m {
        let diff = knot_diff(a, b, k);
        let tol = (1e-10 * scale).max(2.0 * knot_diff(reference, b, k));
        assert!(
            diff <= tol,
            "{what}: knot {k}: coefficients differ by {diff:e} (tolerance {tol:e})"
        );
    }
}

fn both(params: LarsParams, x: &DMatrix<f64>, y: &[f64]) -> (Lars, Lars) {
    let screened = params.clone().screen(true).fit(x, y).expect("screened fit");
    let plain = params.screen(false).fit(x, y).expect("plain fit");
    (screened, plain)
}

/// The unscreened path with the Gram matrix.
fn with_gram(params: LarsParams, x: &DMatrix<f64>, y: &[f64]) -> Lars {
    params
        .screen(false)
        .gram(Gram::Precompute)
        .fit(x, y)
        .expect("fit with the Gram matrix")
}

#[test]
fn screened_wide_paths_are_the_unscreened_ones() {
    for (n, p, shared, k, seed) in [
        (40, 200, 0.0, 5, 1),
        (40, 200, 3.0, 5, 2),
        (100, 400, 1.0, 20, 3),
        (200, 1000, 0.0, 10, 4),
        (200, 1000, 2.0, 50, 5),
        (64, 65, 0.5, 3, 6),
    ] {
        let (x, y) = design(n, p, shared, k, seed);
        for params in [
            Lars::params(),
            Lars::params().fit_intercept(false).normalize(false),
            Lars::params().max_steps(n / 3),
        ] {
            let reference = with_gram(params.clone(), &x, &y);
            let (a, b) = both(params, &x, &y);
            assert_same_path(
                &a,
                &b,
                &reference,
                &format!("{n} x {p}, shared {shared}, seed {seed}"),
            );
        }
    }
}

#[test]
fn the_lasso_and_tall_designs_are_not_screened_and_unchanged() {
    // the screen applies to wide LAR paths only: elsewhere the switch changes nothing
    let (x, y) = design(120, 60, 1.0, 5, 7);
    let (a, b) = both(Lars::params(), &x, &y);
    assert_eq!(a.coef_path(), b.coef_path());
    let (x, y) = design(40, 120, 1.0, 5, 8);
    let (a, b) = both(Lars::params().method(Method::Lasso), &x, &y);
    assert_eq!(a.coef_path(), b.coef_path());
    assert_eq!(a.events(), b.events());
}

#[test]
fn extreme_scales_keep_the_unscreened_path() {
    // unscaled columns of 1e-40 to 1e35: single precision underflows or overflows at the
    // ends (beyond 1e30 the screen is not used); every path must stay the plain one
    let (x, y) = design(40, 200, 1.0, 5, 9);
    for s in [1e-40, 1e-30, 1e-15, 1e15, 1e29, 1e35] {
        let xs = &x * s;
        let params = Lars::params().fit_intercept(false).normalize(false);
        let reference = with_gram(params.clone(), &xs, &y);
        let (a, b) = both(params, &xs, &y);
        assert_same_path(&a, &b, &reference, &format!("scale {s:e}"));
    }
}
