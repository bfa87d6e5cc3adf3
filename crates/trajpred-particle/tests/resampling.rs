//! Resamplers against the numpy/filterpy fixture (exact indices for given uniforms) and hand-worked
//! cases, and every error variant. The seeded statistics are in `resampling_properties.rs`, the systematic
//! kernel in `resampling_systematic.rs`, the residual remainder in `resampling_residual.rs`.

mod common;

use common::schemes;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use trajpred_core::Error as CoreError;
use trajpred_particle::{
    ParticleError, Resampler, multinomial_indices, residual_indices, stratified_indices,
    systematic_indices,
};

fn fixture() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/particle/resampling.json"
    );
    let text = std::fs::read_to_string(path).expect("fixture present");
    serde_json::from_str(&text).expect("fixture parses")
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn indices(v: &Value) -> Vec<usize> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_u64().expect("index") as usize)
        .collect()
}

/// Exact equality: the reference and ours do the same floating-point operations (positions
/// `(j + u) / N` scaled by the sequential sum of the weights, sequential cumulative sums), so
/// no tolerance is needed; a mismatch would be a wrong index.
#[test]
fn indices_match_the_textbook_reference_for_given_uniforms() {
    let fx = fixture();
    for case in fx["cases"].as_array().expect("cases") {
        let name = case["name"].as_str().expect("name");
        let w = floats(&case["weights"]);
        let n = w.len();
        let mut out = vec![usize::MAX; n];

        systematic_indices(&w, case["offset"].as_f64().expect("offset"), &mut out)
            .expect("systematic");
        assert_eq!(out, indices(&case["systematic"]), "systematic, {name}");

        stratified_indices(&w, &floats(&case["stratified_uniforms"]), &mut out)
            .expect("stratified");
        assert_eq!(out, indices(&case["stratified"]), "stratified, {name}");

        multinomial_indices(&w, &floats(&case["multinomial_uniforms"]), &mut out)
            .expect("multinomial");
        assert_eq!(out, indices(&case["multinomial"]), "multinomial, {name}");

        let k =
            residual_indices(&w, &floats(&case["residual_uniforms"]), &mut out).expect("residual");
        assert_eq!(out, indices(&case["residual"]), "residual, {name}");
        assert_eq!(
            k as u64,
            case["residual_copies"].as_u64().expect("k"),
            "{name}"
        );
    }
}

/// Our functions against filterpy 2.0.0's answers for the same uniforms (recorded in the
/// fixture by its script): the same systematic, stratified and multinomial indices on
/// normalised weights; at the edge offset filterpy raises IndexError where ours returns valid
/// indices; for residual resampling the deterministic copies agree and the remainder draws
/// differ, since filterpy draws them from the biased residuals `w_i - floor(N w_i)` (filterpy
/// #290). Exact equality: an index either matches or it does not.
#[test]
fn agrees_with_filterpy_where_filterpy_is_right() {
    let fx = fixture();
    let mut residual_differs = 0;
    for case in fx["cases"].as_array().expect("cases") {
        let name = case["name"].as_str().expect("name");
        if name == "unnormalised50" {
            continue; // filterpy assumes normalised weights
        }
        let w = floats(&case["weights"]);
        let n = w.len();
        let mut out = vec![usize::MAX; n];
        if name == "edge_offset" {
            assert_eq!(case["filterpy_systematic"].as_str(), Some("IndexError"));
            systematic_indices(&w, case["offset"].as_f64().expect("u"), &mut out)
                .expect("no crash at the edge");
            assert!(out.iter().all(|&i| i < n));
            assert_eq!(out[n - 1], n - 1);
            continue;
        }
        systematic_indices(&w, case["offset"].as_f64().expect("offset"), &mut out)
            .expect("systematic");
        assert_eq!(
            out,
            indices(&case["filterpy_systematic"]),
            "systematic, {name}"
        );
        stratified_indices(&w, &floats(&case["stratified_uniforms"]), &mut out)
            .expect("stratified");
        assert_eq!(
            out,
            indices(&case["filterpy_stratified"]),
            "stratified, {name}"
        );
        multinomial_indices(&w, &floats(&case["multinomial_uniforms"]), &mut out)
            .expect("multinomial");
        assert_eq!(
            out,
            indices(&case["filterpy_multinomial"]),
            "multinomial, {name}"
        );

        let k =
            residual_indices(&w, &floats(&case["residual_uniforms"]), &mut out).expect("residual");
        let theirs = indices(&case["filterpy_residual"]);
        // k = sum of floor(N w_i), worked here; filterpy places the same copies first
        let copies: Vec<usize> = w
            .iter()
            .map(|&wi| (n as f64 * wi).floor() as usize)
            .collect();
        assert_eq!(k, copies.iter().sum::<usize>(), "copies, {name}");
        assert_eq!(out[..k], theirs[..k], "deterministic copies, {name}");
        for (i, &c) in copies.iter().enumerate() {
            assert!(
                out.iter().filter(|&&j| j == i).count() >= c,
                "{name}: copies of {i}"
            );
        }
        if out[k..] != theirs[k..] {
            residual_differs += 1;
        }
    }
    assert!(residual_differs >= 3, "filterpy's residual bias visible");
}

/// Small cases worked by hand.
#[test]
fn hand_worked_systematic_and_residual() {
    let mut out = [usize::MAX; 4];
    // w = [0.1, 0.2, 0.3, 0.4], u = 0.5: positions 0.125, 0.375, 0.625, 0.875 against the
    // cumulative sums 0.1, 0.3, 0.6, 1.0 fall in particles 1, 2, 3, 3
    systematic_indices(&[0.1, 0.2, 0.3, 0.4], 0.5, &mut out).expect("systematic");
    assert_eq!(out, [1, 2, 3, 3]);
    // u = 0: positions 0, 0.25, 0.5, 0.75 fall in particles 0, 1, 2, 3
    systematic_indices(&[0.1, 0.2, 0.3, 0.4], 0.0, &mut out).expect("systematic");
    assert_eq!(out, [0, 1, 2, 3]);
    // residual, w = [0.375, 0.375, 0.125, 0.125]: N w = [1.5, 1.5, 0.5, 0.5], so one copy
    // each of 0 and 1 (k = 2) and two draws from the residuals [0.5, 0.5, 0.5, 0.5] / 2
    // (cumulative 0.25, 0.5, 0.75, 1): u = 0.1 -> 0, u = 0.6 -> 2
    let k =
        residual_indices(&[0.375, 0.375, 0.125, 0.125], &[0.1, 0.6], &mut out).expect("residual");
    assert_eq!((k, out), (2, [0, 1, 0, 2]));
    // filterpy's biased residuals w - floor(N w) = [0.375, 0.375, 0.125, 0.125] (cumulative
    // 0.375, 0.75, 0.875, 1) would give 0 and 1 for these draws instead
    // a remainder of zero: N w = [2, 1, 1] exactly, no draw needed
    let mut out = [usize::MAX; 4];
    let k = residual_indices(&[0.5, 0.25, 0.25], &[], &mut out).expect("residual");
    assert_eq!((k, out), (4, [0, 0, 1, 2]));
}

#[test]
fn edge_offsets_never_index_past_the_end() {
    let just_below_one = f64::from_bits(1.0f64.to_bits() - 1);
    // weights whose sum rounds below 1, trailing zeros, and a single particle
    let cases: Vec<Vec<f64>> = vec![
        vec![0.1; 10],
        vec![0.3, 0.3, 0.4, 0.0, 0.0],
        vec![1.0],
        vec![1e-300, 1.0, 1e-300],
    ];
    for w in &cases {
        let last_positive = w.iter().rposition(|&x| x > 0.0).expect("positive");
        for &u in &[0.0, just_below_one, 1.0] {
            for n in [1usize, w.len(), 3 * w.len()] {
                let mut out = vec![usize::MAX; n];
                systematic_indices(w, u, &mut out).expect("systematic");
                assert!(
                    out.iter().all(|&i| i <= last_positive && w[i] > 0.0),
                    "{w:?} {u}"
                );
                stratified_indices(w, &vec![u; n], &mut out).expect("stratified");
                assert!(
                    out.iter().all(|&i| i <= last_positive && w[i] > 0.0),
                    "{w:?} {u}"
                );
                multinomial_indices(w, &vec![u; n], &mut out).expect("multinomial");
                assert!(
                    out.iter().all(|&i| i <= last_positive && w[i] > 0.0),
                    "{w:?} {u}"
                );
                residual_indices(w, &vec![u; n], &mut out).expect("residual");
                assert!(
                    out.iter().all(|&i| i <= last_positive && w[i] > 0.0),
                    "{w:?} {u}"
                );
            }
        }
    }
}

#[test]
fn hand_worked_indices() {
    // N = 4, w = [0.5, 0.25, 0.25]: cumulative 0.5, 0.75, 1.0
    let w = [0.5, 0.25, 0.25];
    let mut out = [0; 4];
    // positions 0, 0.25, 0.5, 0.75: 0.5 is not < 0.5, so it selects 1; 0.75 selects 2
    systematic_indices(&w, 0.0, &mut out).expect("ok");
    assert_eq!(out, [0, 0, 1, 2]);
    // stratified with u = (0.9, 0.1, 0.9, 0.1): positions 0.225, 0.275, 0.725, 0.775
    stratified_indices(&w, &[0.9, 0.1, 0.9, 0.1], &mut out).expect("ok");
    assert_eq!(out, [0, 0, 1, 2]);
    // multinomial keeps the order of the uniforms
    multinomial_indices(&w, &[0.8, 0.1, 0.6, 0.49], &mut out).expect("ok");
    assert_eq!(out, [2, 0, 1, 0]);
    // residual, N = 4, w = [0.6, 0.3, 0.1]: N w = [2.4, 1.2, 0.4] -> copies [0, 0, 1];
    // residuals [0.4, 0.2, 0.4] (sum 1); u = 0.5 -> position 0.5 in [0.4, 0.6) -> particle 1
    let k = residual_indices(&[0.6, 0.3, 0.1], &[0.5], &mut out).expect("ok");
    assert_eq!((k, out), (3, [0, 0, 1, 1]));
    // unnormalised weights give the same answer as normalised ones
    systematic_indices(&[2.0, 1.0, 1.0], 0.0, &mut out).expect("ok");
    assert_eq!(out, [0, 0, 1, 2]);
}

#[test]
fn bad_weights_are_typed_errors() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for (name, scheme) in schemes() {
        let mut out = [0usize; 3];
        assert!(
            matches!(
                scheme.resample_into(&[], &mut rng, &mut out),
                Err(ParticleError::Core(CoreError::Empty { what: "weights" }))
            ),
            "{name}"
        );
        assert!(
            matches!(
                scheme.resample_into(&[0.0, 0.0], &mut rng, &mut out),
                Err(ParticleError::AllWeightsZero { count: 2 })
            ),
            "{name}"
        );
        assert!(
            matches!(
                scheme.resample_into(&[0.5, -0.1], &mut rng, &mut out),
                Err(ParticleError::InvalidWeight { index: 1, .. })
            ),
            "{name}"
        );
        assert!(
            matches!(
                scheme.resample_into(&[f64::NAN, 1.0], &mut rng, &mut out),
                Err(ParticleError::InvalidWeight { index: 0, .. })
            ),
            "{name}"
        );
        assert!(
            matches!(
                scheme.resample_into(&[f64::INFINITY], &mut rng, &mut out),
                Err(ParticleError::InvalidWeight { index: 0, .. })
            ),
            "{name}"
        );
        assert!(
            matches!(
                scheme.resample_into(&[f64::MAX, f64::MAX], &mut rng, &mut out),
                Err(ParticleError::Core(CoreError::NonFinite { .. }))
            ),
            "{name}"
        );
    }
    // from 2^17 weights the residual scheme checks them by parts, in parallel: the first
    // offending weight is still the one reported, and a negative zero is a valid zero
    let len = (1 << 17) + 5;
    let mut out = vec![0usize; len];
    for (index, value) in [
        (len - 2, -1e-300),
        (70_000, f64::NAN),
        (3, f64::NEG_INFINITY),
    ] {
        let mut w = vec![1.0; len];
        w[index] = value;
        w[len - 1] = -1.0;
        for (name, scheme) in schemes() {
            let got = scheme.resample_into(&w, &mut rng, &mut out);
            assert!(
                matches!(got, Err(ParticleError::InvalidWeight { index: i, .. }) if i == index),
                "{name}, weight {value} at {index}: {got:?}"
            );
        }
    }
    let mut w = vec![1.0; len];
    w[100_000] = -0.0;
    for (name, scheme) in schemes() {
        scheme.resample_into(&w, &mut rng, &mut out).expect(name);
        assert!(!out.contains(&100_000), "{name}");
    }
    let mut out = [0usize; 2];
    assert!(matches!(
        systematic_indices(&[1.0], 1.5, &mut out),
        Err(ParticleError::InvalidUniform { index: 0, .. })
    ));
    assert!(matches!(
        stratified_indices(&[1.0], &[0.5], &mut out),
        Err(ParticleError::Core(CoreError::LengthMismatch { .. }))
    ));
    assert!(matches!(
        multinomial_indices(&[1.0], &[0.5, -0.5], &mut out),
        Err(ParticleError::InvalidUniform { index: 1, .. })
    ));
    // N = 2, w = [0.25, 0.75]: copies [1], one remainder draw needs one uniform
    assert!(matches!(
        residual_indices(&[0.25, 0.75], &[], &mut out),
        Err(ParticleError::Core(CoreError::LengthMismatch {
            expected: 1,
            ..
        }))
    ));
}
