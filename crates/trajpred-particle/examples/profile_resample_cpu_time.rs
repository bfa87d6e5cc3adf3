//! Wall-clock and CPU time (of every thread of the process, from
//! /proc/self/task/*/schedstat, Linux) of the four resamplers on i.i.d. uniform linear
//! weights, for a shared machine where criterion's wall-clock figures include time the
//! threads spent descheduled; after each scheme, a hash of its last output, to compare the
//! indices of two builds (same `N` and `REPS`, so the same draws). Usage:
//! `cargo run --release -p trajpred-particle --example profile_resample_cpu_time -- N REPS`
//! (`EXPT=1`: cost of one Exp(1) / one uniform draw with a running sum; `SCHEME=name`: only
//! that scheme, e.g. for `perf record`).
use rand::rngs::SmallRng;
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::time::Instant;
/// CPU seconds of every thread of this process so far.
fn cpu() -> f64 {
    let mut ns = 0.0;
    for task in std::fs::read_dir("/proc/self/task").unwrap() {
        let path = task.unwrap().path().join("schedstat");
        // a thread may have exited since the directory was read
        if let Ok(s) = std::fs::read_to_string(path) {
            ns += s.split_whitespace().next().unwrap().parse::<f64>().unwrap();
        }
    }
    ns * 1e-9
}
use trajpred_particle::{Resampler, Resampling};
fn main() {
    if std::env::var("EXPT").is_ok() {
        exp_time();
        return;
    }
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(1_000_000);
    let reps: usize = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(50);
    let mut wrng = SmallRng::seed_from_u64(1);
    let weights: Vec<f64> = (0..n).map(|_| wrng.random::<f64>()).collect();
    let mut out = vec![0usize; n];
    let mut rng = SmallRng::seed_from_u64(2);
    for _ in 0..3 {
        let t = Instant::now();
        let mut s = 0.0;
        for _ in 0..reps {
            s += black_box(&weights).iter().sum::<f64>();
        }
        black_box(s);
        let dt = t.elapsed().as_secs_f64() / reps as f64;
        eprintln!(
            "sum {:8.2} ns/p {:8.1} M/s",
            dt * 1e9 / n as f64,
            n as f64 / dt / 1e6
        );
        let only = std::env::var("SCHEME").ok();
        for scheme in Resampling::ALL {
            if only.as_deref().is_some_and(|o| o != scheme.name()) {
                continue;
            }
            let t = Instant::now();
            let c0 = cpu();
            for _ in 0..reps {
                scheme
                    .resample_into(black_box(&weights), &mut rng, &mut out)
                    .unwrap();
                black_box(&out);
            }
            let dt = t.elapsed().as_secs_f64() / reps as f64;
            let dc = (cpu() - c0) / reps as f64;
            let hash = out.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &i| {
                (h ^ i as u64).wrapping_mul(0x0100_0000_01b3)
            });
            eprintln!(
                "{:12} {:8.2} ns/p {:8.1} M/s   cpu {:8.2} ns/p {:8.1} M/s   hash {hash:016x}",
                scheme.name(),
                dt * 1e9 / n as f64,
                n as f64 / dt / 1e6,
                dc * 1e9 / n as f64,
                n as f64 / dc / 1e6
            );
        }
    }
}
#[allow(dead_code)]
fn exp_time() {
    use rand_distr::{Distribution, Exp1};
    let mut rng = SmallRng::seed_from_u64(2);
    let n = 1_000_000;
    let mut buf = vec![0u64; n];
    for _ in 0..3 {
        let c0 = cpu();
        for _ in 0..10 {
            let mut s = 0.0f64;
            for b in buf.iter_mut() {
                let e: f64 = Exp1.sample(&mut rng);
                s += e;
                *b = s.to_bits();
            }
            black_box(&buf);
        }
        eprintln!(
            "exp1 cpu {:.2} ns/draw",
            (cpu() - c0) / 10.0 / n as f64 * 1e9
        );
        let c0 = cpu();
        for _ in 0..10 {
            let mut s = 0.0f64;
            for b in buf.iter_mut() {
                let e: f64 = rng.random();
                s += e;
                *b = s.to_bits();
            }
            black_box(&buf);
        }
        eprintln!(
            "unif cpu {:.2} ns/draw",
            (cpu() - c0) / 10.0 / n as f64 * 1e9
        );
    }
}
