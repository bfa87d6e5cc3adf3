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
mod common;
use common::data;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use trajpred_sparse::{Gram, Lars, Method};

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
