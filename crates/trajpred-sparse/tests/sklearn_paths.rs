//! LARS paths against scikit-learn's `lars_path` (fixtures/sparse/make_fixtures.py, scikit-learn
//! 1.9.1), and where scikit-learn leaves the textbook path, against the LAR conditions.
//!
//! Tolerance for agreement with scikit-learn: 1e-9 relative (the requirement).
//! Both implementations solve the same well-conditioned systems with different but backward
//! stable arithmetic; on these inputs the paths agree to ~1e-12, so 1e-9 leaves margin for
//! rounding and still catches any algorithmic difference (those are O(1)).

#![allow(clippy::needless_range_loop)] // index loops mirror the knot/feature indices of the formulas

use nalgebra::DMatrix;
use serde_json::Value;
use trajpred_sparse::{ExclusionReason, Gram, Lars, LarsParams, Method, PathEvent, StopReason};

const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/sparse/lars_sklearn.json"
);

fn fixture() -> Value {
    let text = std::fs::read_to_string(FIXTURE).expect("fixture present");
    serde_json::from_str(&text).expect("fixture is JSON")
}

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).expect("matrix");
    let (n, p) = (rows.len(), rows[0].len());
    DMatrix::from_fn(n, p, |i, j| rows[i][j])
}

fn vector(v: &Value) -> Vec<f64> {
    serde_json::from_value(v.clone()).expect("vector")
}

fn case<'a>(f: &'a Value, name: &str) -> &'a Value {
    f["cases"]
        .as_array()
        .expect("cases")
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("case {name}"))
}

fn method(c: &Value) -> Method {
    if c["method"] == "lasso" {
        Method::Lasso
    } else {
        Method::Lar
    }
}

/// Largest |a - b| / max(|b|, floor) over the entries.
fn rel_err(a: &[f64], b: &[f64], floor: f64) -> f64 {
    assert_eq!(a.len(), b.len(), "lengths differ");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / y.abs().max(floor))
        .fold(0.0, f64::max)
}

/// Compares our path with scikit-learn's for the first `knots` knots.
fn assert_path_matches(fit: &Lars, c: &Value, knots: usize, scale: f64) {
    let alphas = vector(&c["alphas"]);
    let coefs = matrix(&c["coefs"]);
    let a_max = alphas[0];
    let ours: Vec<f64> = fit.alphas()[..knots].to_vec();
    let err = rel_err(&ours, &alphas[..knots], a_max * 1e-3);
    assert!(err < 1e-9, "{}: alphas differ by {err:e}", c["name"]);
    let ours = fit.standardized_coef_path();
    let c_max = coefs.amax();
    for k in 0..knots {
        let a: Vec<f64> = ours.row(k).iter().map(|v| v * scale).collect();
        let b: Vec<f64> = coefs.row(k).iter().copied().collect();
        let err = rel_err(&a, &b, c_max * 1e-3);
        assert!(
            err < 1e-9,
            "{}: knot {k} coefficients differ by {err:e}",
            c["name"]
        );
    }
}

fn fit_plain(c: &Value, gram: Gram) -> Lars {
    let x = matrix(&c["x"]);
    let y = vector(&c["y"]);
    let mut params: LarsParams = Lars::params()
        .method(method(c))
        .fit_intercept(false)
        .normalize(false)
        .gram(gram);
    if let Some(m) = c["kwargs"]["max_iter"].as_u64() {
        params = params.max_steps(m as usize);
    }
    if let Some(a) = c["kwargs"]["alpha_min"].as_f64() {
        params = params.alpha_min(a);
    }
    params.fit(&x, &y).expect("fit")
}

/// The fixture's cases named `names`, each with its name.
fn cases<'a>(f: &'a Value, names: &'a [&'a str]) -> impl Iterator<Item = (&'a str, &'a Value)> {
    names.iter().map(move |&name| (name, case(f, name)))
}

/// scikit-learn's active set of case `c`, in order of entry.
fn active(c: &Value) -> Vec<usize> {
    serde_json::from_value(c["active"].clone()).expect("active")
}

/// Our path has as many knots as scikit-learn's for case `name` (`c`) and the same
/// standardized path ([`assert_path_matches`]); returns the number of knots.
fn assert_knots_match(fit: &Lars, c: &Value, name: &str) -> usize {
    let knots = vector(&c["alphas"]).len();
    assert_eq!(fit.n_knots(), knots, "{name}: number of knots");
    assert_path_matches(fit, c, knots, 1.0);
    knots
}

fn active_sequence(fit: &Lars) -> Vec<usize> {
    fit.active().to_vec()
}

#[test]
fn diabetes_paths_match_sklearn_with_and_without_gram() {
    let f = fixture();
    for (name, c) in cases(
        &f,
        &[
            "diabetes_lar",
            "diabetes_lasso",
            "diabetes_lasso_alpha_min",
            "diabetes_lar_max_iter",
        ],
    ) {
        for gram in [Gram::Precompute, Gram::Never] {
            let fit = fit_plain(c, gram);
            assert_knots_match(&fit, c, name);
            assert_eq!(active_sequence(&fit), active(c), "{name}: active set");
        }
    }
}

#[test]
fn diabetes_lasso_drops_and_readds_variable_6_like_the_lars_paper() {
    // Efron et al. (2004), section 3.1: on the diabetes data the lasso path drops hdl
    // (column 6) and adds it back; LAR has 10 steps, lasso 12.
    let f = fixture();
    let c = case(&f, "diabetes_lasso");
    let fit = fit_plain(c, Gram::Auto);
    let drops: Vec<usize> = fit
        .events()
        .iter()
        .filter_map(|e| match e {
            PathEvent::Dropped { feature, .. } => Some(*feature),
            _ => None,
        })
        .collect();
    assert_eq!(drops, vec![6]);
    assert_eq!(fit.n_knots(), 13);
    assert_eq!(fit.stop_reason(), StopReason::Complete);
}

#[test]
fn diabetes_raw_with_intercept_and_normalisation_matches_sklearn_on_original_scale() {
    let f = fixture();
    let x_raw = matrix(&f["diabetes"]["x_raw"]);
    let y = vector(&f["diabetes"]["target"]);
    for (name, c) in cases(&f, &["diabetes_lar", "diabetes_lasso"]) {
        let fit = Lars::params()
            .method(method(c))
            .fit(&x_raw, &y)
            .expect("fit");
        // our standardisation of the raw data is the fixture's: same standardised path
        let knots = assert_knots_match(&fit, c, name);
        let orig = matrix(&c["coefs_original"]);
        let intercepts = vector(&c["intercepts"]);
        let cmax = orig.amax();
        for k in 0..knots {
            let a: Vec<f64> = fit.coef_path().row(k).iter().copied().collect();
            let b: Vec<f64> = orig.row(k).iter().copied().collect();
            assert!(rel_err(&a, &b, cmax * 1e-3) < 1e-9, "{name} knot {k}");
        }
        assert!(rel_err(fit.intercepts(), &intercepts, 1.0) < 1e-9);
        // the final model predicts on the original scale: compare with the fixture's model
        for i in [0usize, 100, 441] {
            let row: Vec<f64> = x_raw.row(i).iter().copied().collect();
            let ours = fit.predict_row(&row).expect("predict");
            let reference = intercepts[knots - 1]
                + row
                    .iter()
                    .zip(orig.row(knots - 1).iter())
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            assert!((ours - reference).abs() < 1e-9 * reference.abs());
        }
    }
}

#[test]
fn scaled_diabetes_data_equals_standardised_raw_data() {
    // scikit-learn's scaled diabetes columns are (raw - mean) / norm: fitting the scaled data
    // without preprocessing and the raw data with it must give the same standardised path.
    let f = fixture();
    let xs = matrix(&f["diabetes"]["x_scaled"]);
    let xr = matrix(&f["diabetes"]["x_raw"]);
    let y = vector(&f["diabetes"]["target"]);
    let a = Lars::params().fit(&xr, &y).expect("raw");
    let b = Lars::params().fit(&xs, &y).expect("scaled");
    assert_eq!(a.n_knots(), b.n_knots());
    let diff = (a.standardized_coef_path() - b.standardized_coef_path()).amax();
    // scikit-learn stores the scaled data rounded to ~1e-16 relative: 1e-9 of the largest
    // coefficient (~800) is far above that
    assert!(diff < 1e-9 * a.standardized_coef_path().amax(), "{diff:e}");
}

#[test]
fn correlated_and_sign_flip_lasso_match_sklearn() {
    let f = fixture();
    for (name, c) in cases(
        &f,
        &[
            "correlated_lar",
            "correlated_lasso",
            "sign_flip_lasso",
            "collinear_lar",
            "scale_unit_lar",
        ],
    ) {
        let fit = fit_plain(c, Gram::Auto);
        assert_knots_match(&fit, c, name);
    }
}

#[test]
fn collinear_and_duplicate_columns_are_excluded_and_reported() {
    let f = fixture();
    let c = case(&f, "collinear_lar");
    let fit = fit_plain(c, Gram::Auto);
    let ex: Vec<(usize, ExclusionReason)> = fit
        .excluded()
        .iter()
        .map(|e| (e.feature, e.reason))
        .collect();
    // column 6 duplicates column 2 and ties with it: excluded for good when it would enter.
    // Column 5 = column 0 + column 1 with opposite-signed correlations never ties (its
    // correlation is c_0 + c_1, which shrinks to 0 with the others), so it simply never enters.
    assert_eq!(ex, vec![(6, ExclusionReason::Collinear)]);
    assert!(fit.coef_path().column(5).iter().all(|&v| v == 0.0));
    assert!(fit.coef_path().column(6).iter().all(|&v| v == 0.0));
    assert_eq!(fit.stop_reason(), StopReason::CorrelationVanished);
    assert!(fit.coef_path().iter().all(|v| v.is_finite()));
}

#[test]
fn lars_path_returns_sklearns_values_in_sklearns_layout() {
    use trajpred_sparse::{LarsPathOptions, lars_path};
    let f = fixture();
    for (name, c) in cases(
        &f,
        &[
            "diabetes_lar",
            "diabetes_lasso",
            "diabetes_lasso_alpha_min",
            "diabetes_lar_max_iter",
            "correlated_lasso",
        ],
    ) {
        let x = matrix(&c["x"]);
        let y = vector(&c["y"]);
        let mut opts = LarsPathOptions::default();
        if let Some(m) = c["kwargs"]["max_iter"].as_u64() {
            opts = opts.max_iter(m as usize);
        }
        if let Some(a) = c["kwargs"]["alpha_min"].as_f64() {
            opts = opts.alpha_min(a);
        }
        let path = lars_path(&x, &y, method(c), &opts).expect("path");
        let alphas = vector(&c["alphas"]);
        // the fixture stores coefs knot by knot; scikit-learn returns them n_features x n_alphas
        let coefs_t = matrix(&c["coefs"]);
        assert_eq!(path.alphas.len(), alphas.len(), "{name}: n_alphas");
        assert_eq!(path.n_iter, alphas.len() - 1, "{name}: n_iter");
        assert_eq!(
            path.coefs.shape(),
            (x.ncols(), alphas.len()),
            "{name}: layout"
        );
        assert_eq!(path.active, active(c), "{name}: active");
        let err = rel_err(&path.alphas, &alphas, alphas[0] * 1e-3);
        assert!(err < 1e-9, "{name}: alphas differ by {err:e}");
        let c_max = coefs_t.amax();
        for k in 0..alphas.len() {
            let ours: Vec<f64> = path.coefs.column(k).iter().copied().collect();
            let theirs: Vec<f64> = coefs_t.row(k).iter().copied().collect();
            let err = rel_err(&ours, &theirs, c_max * 1e-3);
            assert!(
                err < 1e-9,
                "{name}: alpha {k} coefficients differ by {err:e}"
            );
        }
    }
}

#[test]
fn lars_path_rejects_a_bad_alpha_min() {
    use trajpred_core::Error as CoreError;
    use trajpred_sparse::{Error, LarsPathOptions, lars_path};
    let f = fixture();
    let c = case(&f, "diabetes_lar");
    let (x, y) = (matrix(&c["x"]), vector(&c["y"]));
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let r = lars_path(
            &x,
            &y,
            Method::Lar,
            &LarsPathOptions::default().alpha_min(bad),
        );
        assert!(
            matches!(
                r,
                Err(Error::Core(CoreError::InvalidParameter {
                    name: "alpha_min",
                    ..
                }))
            ),
            "{bad}"
        );
    }
}
