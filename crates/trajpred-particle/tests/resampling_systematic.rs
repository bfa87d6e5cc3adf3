//! The systematic kernel (counts per particle, split in two halves on two threads) against
//! the plain definition.

mod common;

use common::pool;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trajpred_particle::systematic_indices;

/// The textbook definition written plainly (as `fixtures/particle/make_resampling_fixture.py`
/// does in numpy): cumulative sums `C`, positions `p_j * C[N-1]`, index
/// `#{i : C_i <= p}` (searchsorted, side right), clamped to the last positive weight.
fn reference_pick(w: &[f64], positions: impl Iterator<Item = f64>) -> Vec<usize> {
    let mut c = Vec::with_capacity(w.len());
    let mut s = 0.0;
    for &x in w {
        s += x;
        c.push(s);
    }
    let total = s;
    let last = w.iter().rposition(|&x| x > 0.0).expect("positive");
    positions
        .map(|p| c.partition_point(|&ci| ci <= p * total).min(last))
        .collect()
}

/// The one-pass systematic kernel (counts per particle, estimated with a multiplication and
/// corrected near ties) gives exactly the indices of the plain merge, on many weight shapes
/// (ties from equal weights and `u = 0`, zeros, a dominant weight, unnormalised weights,
/// `n != N`) and offsets (0, 1, just below 1, random).
#[test]
fn systematic_kernel_equals_the_plain_definition() {
    use rand::RngExt;
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let below_one = f64::from_bits(1.0f64.to_bits() - 1);
    let mut shapes: Vec<Vec<f64>> = vec![
        vec![0.1; 10],
        vec![1.0; 1000],
        vec![1.0 / 3.0; 999],
        vec![0.25, 0.0, 0.25, 0.0, 0.5, 0.0],
    ];
    for &n in &[1usize, 2, 7, 100, 5000] {
        shapes.push((0..n).map(|_| rng.random::<f64>()).collect());
        shapes.push((0..n).map(|_| rng.random::<f64>().powi(8) * 1e-3).collect());
        let mut w: Vec<f64> = (0..n)
            .map(|i| if i % 3 == 0 { 0.0 } else { rng.random() })
            .collect();
        w[n / 2] = 1.0e6;
        shapes.push(w);
    }
    for w in &shapes {
        if !w.iter().any(|&x| x > 0.0) {
            continue;
        }
        for &n_out in &[1usize, w.len(), 2 * w.len() + 1, w.len() / 3 + 1] {
            let mut offsets = vec![0.0, 1.0, below_one, 0.5];
            offsets.extend((0..4).map(|_| rng.random::<f64>()));
            for &u in &offsets {
                let mut out = vec![usize::MAX; n_out];
                systematic_indices(w, u, &mut out).expect("systematic");
                let nf = n_out as f64;
                let expected = reference_pick(w, (0..n_out).map(|j| (j as f64 + u) / nf));
                assert_eq!(out, expected, "N {} n {n_out} u {u}", w.len());
            }
        }
    }
}

/// From 2^17 particles on the systematic pass runs as two halves on the rayon pool (the
/// second starting from the running sum at the midpoint): on a 1-thread and a 2-thread pool
/// the indices are identical, and equal to the plain definition, for ties (equal weights
/// with `u = 0`), zeros, a dominant weight, a last positive weight before and just after
/// the midpoint, and output sizes other than `N`.
#[test]
fn systematic_split_pass_equals_the_plain_definition_on_any_thread_count() {
    use rand::RngExt;
    let mut rng = ChaCha8Rng::seed_from_u64(78);
    let below_one = f64::from_bits(1.0f64.to_bits() - 1);
    let big = 300_001usize;
    let mut shapes: Vec<Vec<f64>> = vec![
        (0..big).map(|_| rng.random::<f64>()).collect(),
        vec![1.0 / 3.0; big],
    ];
    let mut w: Vec<f64> = (0..big)
        .map(|i| if i % 3 == 0 { 0.0 } else { rng.random() })
        .collect();
    w[big / 2 + 1] = 1.0e6;
    shapes.push(w);
    // last positive weight just before and just after the midpoint (150_000)
    for last in [149_990usize, 150_003] {
        shapes.push(
            (0..big)
                .map(|i| if i <= last { rng.random::<f64>() } else { 0.0 })
                .collect(),
        );
    }
    let (one, two) = (pool(1), pool(2));
    for w in &shapes {
        for &n_out in &[big, (1 << 17) + 3] {
            for &u in &[0.0, below_one, rng.random::<f64>()] {
                let run = |p: &rayon::ThreadPool| {
                    let mut out = vec![usize::MAX; n_out];
                    p.install(|| systematic_indices(w, u, &mut out))
                        .expect("systematic");
                    out
                };
                let (a, b) = (run(&one), run(&two));
                let nf = n_out as f64;
                let expected = reference_pick(w, (0..n_out).map(|j| (j as f64 + u) / nf));
                assert!(a == expected, "1 thread, n {n_out} u {u}");
                assert!(b == expected, "2 threads, n {n_out} u {u}");
            }
        }
    }
}
