//! The full LAR path timed with the protocol of `benches/sklearn_lars_path.py`, so that the two
//! can be compared like for like: the same data (splitmix64 + Box-Muller, see
//! `benches/common/mod.rs`), one untimed warm-up run, then `reps` timed runs, and the median,
//! quartiles and extremes of the wall-clock time in milliseconds, and the thread's CPU time
//! over the timed runs divided by `reps` (on a shared machine it leaves out the time spent
//! waiting for a core).
//!
//! - `gram`: [`Gram::Auto`] (the Gram matrix is computed inside the timed call when `p <= n`),
//!   beside scikit-learn's `lars_path(X, y, Gram='auto')`;
//! - `no_gram`: [`Gram::Never`], beside `lars_path(X, y, Gram=None)`.
//!
//! Our configuration is `fit_intercept(false).normalize(false)`: what `lars_path` computes.
//!
//! ```text
//! cargo bench -p trajpred-sparse --bench lars_timing [-- --quick]
//! ```
#![allow(missing_docs, clippy::print_stdout)]
mod common;
use common::data;
use std::hint::black_box;
use std::time::Instant;
use trajpred_sparse::{Gram, Lars, Method};

const CASES: [(usize, usize); 4] = [(442, 10), (2000, 100), (5000, 500), (200, 1000)];

/// The repetition counts of the Python script.
fn reps_for(n: usize, p: usize, quick: bool) -> usize {
    let work = n * p * n.min(p);
    if quick {
        3
    } else if work >= 1_000_000_000 {
        11
    } else if work >= 10_000_000 {
        31
    } else {
        201
    }
}

/// CPU time of this thread in ns (`/proc/thread-self/schedstat`), when readable: on a shared
/// machine it leaves out the time the thread waited for a core.
fn cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Linear-interpolated percentile of sorted data (numpy's default).
fn percentile(sorted: &[f64], q: f64) -> f64 {
    let pos = q / 100.0 * (sorted.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    // cargo bench passes --bench; any other word selects cases by substring
    let filters: Vec<&String> = args[1..].iter().filter(|a| !a.starts_with("--")).collect();
    for (n, p) in CASES {
        let (x, y) = data(n, p);
        let reps = reps_for(n, p, quick);
        for (label, gram) in [("gram", Gram::Auto), ("no_gram", Gram::Never)] {
            let name = format!("ours    {label:8} {n}x{p}");
            if !filters.is_empty() && !filters.iter().any(|f| name.contains(f.as_str())) {
                continue;
            }
            let params = Lars::params()
                .method(Method::Lar)
                .fit_intercept(false)
                .normalize(false)
                .gram(gram);
            let knots = match params.fit(&x, &y) {
                Ok(fit) => fit.n_knots(),
                Err(e) => {
                    eprintln!("{name}: {e}");
                    continue;
                }
            };
            let mut times = Vec::with_capacity(reps);
            let c0 = cpu_ns();
            for _ in 0..reps {
                let t = Instant::now();
                let fit = params.fit(black_box(&x), black_box(&y));
                times.push(t.elapsed().as_secs_f64() * 1e3);
                black_box(fit).ok();
            }
            // CPU time over all the timed runs (the scheduler's counter is only updated at
            // context switches and ticks: exact over the batch, not per run)
            let cpu_mean = match (c0, cpu_ns()) {
                (Some(a), Some(b)) => b.saturating_sub(a) as f64 * 1e-6 / reps as f64,
                _ => f64::NAN,
            };
            times.sort_by(f64::total_cmp);
            println!(
                "{name}: {knots} knots, median {:.4} ms  IQR [{:.4}, {:.4}]  range [{:.4}, {:.4}]  n={reps}  cpu mean {cpu_mean:.4} ms",
                percentile(&times, 50.0),
                percentile(&times, 25.0),
                percentile(&times, 75.0),
                times[0],
                times[reps - 1],
            );
        }
    }
}
