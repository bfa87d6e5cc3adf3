//! Criterion benchmarks: the full LAR path on Gaussian data (442x10, 2000x100, 5000x500, and
//! the wide 200x1000). For the comparison with scikit-learn, `benches/lars_timing.rs` times
//! the same fits with the protocol of the peer script (`benches/compare.sh` runs both).
//!
//! The data come from a counter-based generator (splitmix64 + Box-Muller) that
//! `benches/sklearn_lars_path.py` reproduces in numpy, so scikit-learn's `lars_path` is timed
//! on the same matrices.
//!
//! ```text
//! cargo bench -p trajpred-sparse --bench lars -- --warm-up-time 1 --measurement-time 3
//! ```
#![allow(missing_docs)]
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::DMatrix;
use std::hint::black_box;
use trajpred_sparse::{Gram, Lars, Method};

const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

fn splitmix(k: u64) -> u64 {
    let mut z = k.wrapping_add(1).wrapping_mul(GOLDEN);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn uniform(k: u64) -> f64 {
    ((splitmix(k) >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
}

/// Standard normal number `k` of the stream (Box-Muller on uniforms 2k, 2k+1).
fn normal(k: u64) -> f64 {
    let (u1, u2) = (uniform(2 * k), uniform(2 * k + 1));
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// X[i, j] = normal(i p + j); beta_j = normal(n p + j); y = X beta + normal(n p + p + i).
pub fn data(n: usize, p: usize) -> (DMatrix<f64>, Vec<f64>) {
    let x = DMatrix::from_fn(n, p, |i, j| normal((i * p + j) as u64));
    let beta: Vec<f64> = (0..p).map(|j| normal((n * p + j) as u64)).collect();
    let y = (0..n)
        .map(|i| (0..p).map(|j| x[(i, j)] * beta[j]).sum::<f64>() + normal((n * p + p + i) as u64))
        .collect();
    (x, y)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("lar_full_path");
    group.sample_size(10);
    for (n, p) in [(442, 10), (2000, 100), (5000, 500), (200, 1000)] {
        let (x, y) = data(n, p);
        let params = Lars::params()
            .method(Method::Lar)
            .fit_intercept(false)
            .normalize(false);
        if let Ok(fit) = params.fit(&x, &y) {
            eprintln!(
                "{n}x{p}: {} knots, stop {:?}",
                fit.n_knots(),
                fit.stop_reason()
            );
        }
        for (label, gram) in [("auto", Gram::Auto), ("no_gram", Gram::Never)] {
            let params = params.clone().gram(gram);
            group.bench_with_input(
                BenchmarkId::new(label, format!("{n}x{p}")),
                &(x.clone(), y.clone()),
                |b, (x, y)| b.iter(|| params.fit(black_box(x), black_box(y))),
            );
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
