//! Residual resampling: the remainder is multinomial (across blocks and parts), the copies
//! are exact floors, and the parts give the same indices on any number of threads.

mod common;

use common::pool;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trajpred_particle::{Resampler, Residual};

/// Residual resampling's random remainder, drawn per block of particles (binomial block
/// totals, then draws within each block), over several blocks: counts per particle as
/// `copies + extra`, accumulated over `reps` seeded runs.
fn residual_extras(w: &[f64], n: usize, reps: usize, seed: u64) -> (Vec<f64>, Vec<f64>, usize) {
    let total: f64 = w.iter().sum();
    let floors: Vec<usize> = w
        .iter()
        .map(|&x| (x * (n as f64 / total)).floor() as usize)
        .collect();
    let m = n - floors.iter().sum::<usize>();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = vec![0usize; n];
    let mut count = vec![0usize; w.len()];
    let mut sum = vec![0.0f64; w.len()];
    let mut sum2 = vec![0.0f64; w.len()];
    for _ in 0..reps {
        Residual
            .resample_into(w, &mut rng, &mut out)
            .expect("residual");
        count.fill(0);
        for &i in &out {
            count[i] += 1;
        }
        for i in 0..w.len() {
            assert!(count[i] >= floors[i], "particle {i} lost a copy");
            let extra = (count[i] - floors[i]) as f64;
            sum[i] += extra;
            sum2[i] += extra * extra;
        }
        // the indices come out sorted (copies and remainder merged by particle)
        assert!(out.windows(2).all(|p| p[0] <= p[1]));
    }
    let r = reps as f64;
    let mean: Vec<f64> = sum.iter().map(|s| s / r).collect();
    let var: Vec<f64> = sum2
        .iter()
        .zip(&mean)
        .map(|(s2, m)| (s2 / r - m * m) * r / (r - 1.0))
        .collect();
    (mean, var, m)
}

/// The remainder's extra copies are multinomial: with `p_i = r_i / sum r` (residuals
/// `r_i = n w_i - floor(n w_i)`), `E[extra_i] = m p_i` and `Var[extra_i] = m p_i (1 - p_i)`.
/// Weights over 3 blocks of particles with zeros, exact-integer `n w_i` (zero residual) and
/// fractional ones; the scale `n / W` is a power of 2, so `n w_i` is exact.
/// Means: the statistic `sum_i (mean_i - m p_i)^2 / (m p_i (1 - p_i) / reps)` over the
/// particles with positive residual is chi-square with as many degrees of freedom `d`
/// (for these sample sizes nearly so); the check is `|stat - d| < 6 sqrt(2 d)`. Variances:
/// `sum_i Var[extra_i] = m (1 - sum p_i^2)`, checked within 3%, which a systematic or
/// stratified remainder (variance at most 1/4 per particle, sum far below `m`) fails.
///
/// Two inputs, so that both ways of drawing within a block are checked: residuals 0, 0,
/// 1/2, 1/2 (per group of 4) over 5000 particles, whose full blocks (acceptance exactly 1/4)
/// draw by rejection and whose last block (904 particles, 226 of residual on 2048 slots)
/// by search; and residuals 1/4, 3/4, 1/4, 3/4 over 5296 particles, whose last block (1200
/// particles, 600 of residual on 2048 slots, acceptance 0.29) draws by rejection with 848
/// empty slots; and 5000 i.i.d. uniform weights, whose residuals use all their digits.
#[test]
fn residual_remainder_is_multinomial() {
    // per group of 4: weight 0 (never drawn), 1 (n w = 2, no residual), 0.75, 0.25
    assert_multinomial_remainder(&[0.0, 1.0, 0.75, 0.25], 5000, 11);
    // n w = 0.25, 0.75, 1.25, 1.75
    assert_multinomial_remainder(&[0.125, 0.375, 0.625, 0.875], 5296, 12);
    // i.i.d. uniform weights (residuals with all their digits): full blocks by rejection
    // (acceptance about 1/2), the last (904 particles) by search
    let mut wrng = ChaCha8Rng::seed_from_u64(3);
    let w: Vec<f64> = (0..5000).map(|_| wrng.random::<f64>()).collect();
    assert_multinomial_extras(&w, 13);
}

/// [`residual_remainder_is_multinomial`] on `len` weights repeating `pattern` (which sums
/// to 2, so that `n / W = 2` for `n = len`, a multiple of 4).
fn assert_multinomial_remainder(pattern: &[f64; 4], len: usize, seed: u64) {
    let w: Vec<f64> = (0..len).map(|i| pattern[i % 4]).collect();
    let total: f64 = w.iter().sum();
    assert_eq!(len as f64 / total, 2.0);
    let m = assert_multinomial_extras(&w, seed);
    // every n w_i is exact here, so the residuals sum to m exactly
    let s: f64 = w.iter().map(|&x| 2.0 * x - (2.0 * x).floor()).sum();
    assert_eq!(m as f64, s);
}

/// The remainder of residual resampling of `w` into `n = w.len()` places, over 3000 seeded
/// runs, against the multinomial (see [`residual_remainder_is_multinomial`]); returns `m`.
fn assert_multinomial_extras(w: &[f64], seed: u64) -> usize {
    let len = w.len();
    let n = len;
    let total: f64 = w.iter().sum();
    let reps = 3000;
    let (mean, var, m) = residual_extras(w, n, reps, seed);
    let scale = n as f64 / total;
    let r: Vec<f64> = w.iter().map(|&x| x * scale - (x * scale).floor()).collect();
    let s: f64 = r.iter().sum();
    assert!((m as f64 - s).abs() < 1e-6 * s, "m {m}, residual sum {s}");
    let mut stat = 0.0;
    let mut d = 0.0;
    let mut sum_var = 0.0;
    let mut sum_p2 = 0.0;
    for i in 0..len {
        let p = r[i] / s;
        if p == 0.0 {
            assert_eq!(
                (mean[i], var[i]),
                (0.0, 0.0),
                "particle {i} without residual drawn"
            );
            continue;
        }
        let e = m as f64 * p;
        let v = m as f64 * p * (1.0 - p);
        stat += (mean[i] - e).powi(2) / (v / reps as f64);
        d += 1.0;
        sum_var += var[i];
        sum_p2 += p * p;
    }
    assert!(
        (stat - d).abs() < 6.0 * (2.0 * d).sqrt(),
        "chi-square {stat} with {d} degrees of freedom"
    );
    let expected = m as f64 * (1.0 - sum_p2);
    assert!(
        (sum_var / expected - 1.0).abs() < 0.03,
        "sum of variances {sum_var}, multinomial {expected}"
    );
    m
}

/// One positive residual per block: blocks 0 and 2 each hold one particle with residual
/// 1/2, so the single remainder draw picks either with probability 1/2 (5 standard
/// errors), and nothing else moves. (A single positive residual in the whole input can
/// only come from rounding, the residuals summing to the integer `m`.)
#[test]
fn residual_remainder_single_residual_per_block() {
    let mut w = vec![1.0; 5000];
    w[10] = 1.5;
    w[4500] = 0.5;
    let n = 5000; // n / W = 1: copies 1 each, 1 at 10, 0 at 4500, one draw
    let reps = 4000;
    let (mean, _, m) = residual_extras(&w, n, reps, 12);
    assert_eq!(m, 1);
    let sd = (0.25 / reps as f64).sqrt();
    assert!((mean[10] - 0.5).abs() < 5.0 * sd, "{}", mean[10]);
    assert!((mean[4500] - 0.5).abs() < 5.0 * sd, "{}", mean[4500]);
    assert_eq!(mean[10] + mean[4500], 1.0);
    // a last block of one particle (2049 = 2048 + 1)
    let mut w = vec![1.0; 2049];
    w[0] = 0.5;
    w[2048] = 1.5;
    let (mean, _, m) = residual_extras(&w, 2049, reps, 14);
    assert_eq!(m, 1);
    assert!((mean[0] - 0.5).abs() < 5.0 * sd, "{}", mean[0]);
    assert!((mean[2048] - 0.5).abs() < 5.0 * sd, "{}", mean[2048]);
    assert_eq!(mean[0] + mean[2048], 1.0);
}

/// No remainder (`n w_i` all integers, over several blocks): the copies only, whatever the
/// seed; and outputs of a different length than the weights over several blocks keep the
/// copies and the total.
#[test]
fn residual_without_remainder_and_other_output_lengths() {
    let w = vec![0.5; 4096];
    let ident: Vec<usize> = (0..4096).collect();
    for seed in 0..3 {
        let out = Residual
            .resample(&w, 4096, &mut ChaCha8Rng::seed_from_u64(seed))
            .expect("r");
        assert_eq!(out, ident);
        let out = Residual
            .resample(&w, 8192, &mut ChaCha8Rng::seed_from_u64(seed))
            .expect("r");
        assert!(out.iter().enumerate().all(|(j, &i)| i == j / 2));
    }
    assert_eq!(
        Residual
            .resample(&[1.0, 2.0, 1.0], 4, &mut ChaCha8Rng::seed_from_u64(1))
            .expect("r"),
        [0, 1, 1, 2]
    );
    let w: Vec<f64> = (0..5000).map(|i| ((i * 7919) % 101) as f64).collect();
    let total: f64 = w.iter().sum();
    for n in [1usize, 999, 5000, 12_345] {
        let (mean, _, _) = residual_extras(&w, n, 200, 13);
        let floors_sum: f64 = w.iter().map(|&x| (x * n as f64 / total).floor()).sum();
        let extra: f64 = mean.iter().sum();
        assert!((extra + floors_sum - n as f64).abs() < 1e-9, "n = {n}");
        assert!(
            w.iter().zip(&mean).all(|(&x, &e)| x > 0.0 || e == 0.0),
            "zero weight drawn, n = {n}"
        );
    }
}

/// The residual scheme's copies are exact floors where `n w_i / W` is an integer (odd ones
/// included, where rounding to the nearest integer and to even differ) or a fraction
/// (halves included, the ties of rounding to the nearest). The weights sum to `n`, so the
/// scale is exactly 1: a particle of integer weight gets exactly that many places (its
/// residual is zero), and over 2000 seeds each particle's places beyond its floor average
/// its residual `w_i - floor(w_i)` (the three remainder draws are `Multinomial(3, r / 3)`,
/// so each mean has a standard deviation below 0.02; bound 0.1). A copy too many or too few
/// for any weight moves its mean by 1.
#[test]
fn residual_copies_are_exact_floors() {
    let w = [
        3.0, 5.0, 7.0, 1.0, 9.0, 11.0, 13.0, 0.5, 0.5, 2.5, 1.5, 2.0, 3.0, 4.0, 0.75, 0.25,
    ];
    let n = 64;
    assert_eq!(w.iter().sum::<f64>(), n as f64);
    let seeds = 2000;
    let mut extra = [0usize; 16];
    for seed in 0..seeds {
        let out = Residual
            .resample(&w, n, &mut ChaCha8Rng::seed_from_u64(seed))
            .expect("r");
        let mut count = [0usize; 16];
        for &i in &out {
            count[i] += 1;
        }
        for (i, &x) in w.iter().enumerate() {
            let floor = x.floor() as usize;
            assert!(count[i] >= floor, "seed {seed}, particle {i}: {count:?}");
            if x == x.floor() {
                assert_eq!(count[i], floor, "seed {seed}, particle {i}: {count:?}");
            }
            extra[i] += count[i] - floor;
        }
    }
    for (i, &x) in w.iter().enumerate() {
        let mean = extra[i] as f64 / seeds as f64;
        assert!(
            (mean - (x - x.floor())).abs() < 0.1,
            "particle {i}: mean {mean}"
        );
    }
}

/// From 2^17 particles the residual scheme works in parts (by the input size alone), each
/// drawing from its own generator seeded from the caller's: the indices are the same on 1,
/// 2 and 3 threads, for random weights, zeros with a dominant weight, a part without any
/// residual (all its draws then go elsewhere), positive weights in the first part only, and
/// output sizes other than `N`; they come out sorted and never pick a zero weight.
#[test]
fn residual_parts_give_the_same_indices_on_any_thread_count() {
    use rand::RngExt;
    let mut rng = ChaCha8Rng::seed_from_u64(91);
    let big = 300_001usize;
    let mut shapes: Vec<Vec<f64>> = vec![(0..big).map(|_| rng.random::<f64>()).collect()];
    let mut w: Vec<f64> = (0..big)
        .map(|i| if i % 3 == 0 { 0.0 } else { rng.random() })
        .collect();
    w[big / 2 + 1] = 1.0e6;
    shapes.push(w);
    // equal weights (no residual for n = N) over the second quarter, random elsewhere
    shapes.push(
        (0..big)
            .map(|i| {
                if (big / 4..big / 2).contains(&i) {
                    0.5
                } else {
                    rng.random()
                }
            })
            .collect(),
    );
    shapes.push(
        (0..big)
            .map(|i| if i < 40_000 { rng.random::<f64>() } else { 0.0 })
            .collect(),
    );
    let pools = [pool(1), pool(2), pool(3)];
    for (k, w) in shapes.iter().enumerate() {
        for &n_out in &[big, (1 << 17) + 3, 2 * big] {
            for seed in [5u64, 6] {
                let run = |p: &rayon::ThreadPool| {
                    let mut out = vec![usize::MAX; n_out];
                    p.install(|| {
                        Residual.resample_into(w, &mut ChaCha8Rng::seed_from_u64(seed), &mut out)
                    })
                    .expect("residual");
                    out
                };
                let first = run(&pools[0]);
                assert!(first.windows(2).all(|p| p[0] <= p[1]), "sorted, shape {k}");
                assert!(first.iter().all(|&i| w[i] > 0.0), "zero weight, shape {k}");
                for (t, p) in pools.iter().enumerate().skip(1) {
                    assert!(run(p) == first, "{} threads, shape {k}, n {n_out}", t + 1);
                }
            }
        }
    }
}

/// The remainder over several parts is still one multinomial draw: `N = 2^18` particles
/// (four parts) whose quarters carry residual mass 0, `N/16`, `N/8` and `N/16` (`n / W = 2`,
/// so every `n w_i` is exact), `m = N/4` draws. Over 1000 seeded runs the extra copies in
/// each eighth of the particles have mean `m p` within 5 standard errors and variance
/// `m p (1 - p)` within 20 % (the sample variance of 1000 nearly normal counts has a
/// relative standard deviation of `sqrt(2 / 999) = 4.5 %`, so that is 4.5 of them; a split
/// of the draws by fixed proportions would leave only the within-part variance, about half),
/// and particles without residual never gain a copy.
#[test]
fn residual_remainder_over_parts_is_multinomial() {
    let len = 1usize << 18;
    let quarter = len / 4;
    // per group of 4 (sum 2, n w = 2 x): residuals 0, 1, 2 and 1 per group
    let groups: [[f64; 4]; 4] = [
        [0.5, 0.5, 0.5, 0.5],
        [0.25, 0.25, 0.5, 1.0],
        [0.25, 0.75, 0.25, 0.75],
        [0.125, 0.125, 0.75, 1.0],
    ];
    let w: Vec<f64> = (0..len).map(|i| groups[i / quarter][i % 4]).collect();
    let scale = 2.0;
    assert_eq!(len as f64 / w.iter().sum::<f64>(), scale);
    let floors: Vec<usize> = w.iter().map(|&x| (x * scale).floor() as usize).collect();
    let resid: Vec<f64> = w.iter().map(|&x| x * scale - (x * scale).floor()).collect();
    let m = len - floors.iter().sum::<usize>();
    assert_eq!(m, len / 4);
    let ranges = 8;
    let width = len / ranges;
    let p: Vec<f64> = (0..ranges)
        .map(|r| resid[r * width..(r + 1) * width].iter().sum::<f64>() / m as f64)
        .collect();
    let reps = 1000;
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    let mut out = vec![0usize; len];
    let mut count = vec![0usize; len];
    let (mut sum, mut sum2) = (vec![0.0f64; ranges], vec![0.0f64; ranges]);
    for _ in 0..reps {
        Residual
            .resample_into(&w, &mut rng, &mut out)
            .expect("residual");
        count.fill(0);
        for &i in &out {
            count[i] += 1;
        }
        let mut extra = vec![0.0f64; ranges];
        for i in 0..len {
            assert!(count[i] >= floors[i], "particle {i} lost a copy");
            let e = count[i] - floors[i];
            assert!(
                e == 0 || resid[i] > 0.0,
                "particle {i} without residual drawn"
            );
            extra[i / width] += e as f64;
        }
        for r in 0..ranges {
            sum[r] += extra[r];
            sum2[r] += extra[r] * extra[r];
        }
    }
    let n = reps as f64;
    for r in 0..ranges {
        let mean = sum[r] / n;
        let var = (sum2[r] / n - mean * mean) * n / (n - 1.0);
        let (e, v) = (m as f64 * p[r], m as f64 * p[r] * (1.0 - p[r]));
        if p[r] == 0.0 {
            assert_eq!((mean, var), (0.0, 0.0), "range {r}");
            continue;
        }
        assert!(
            (mean - e).abs() < 5.0 * (v / n).sqrt(),
            "range {r}: mean {mean}, expected {e}"
        );
        assert!(
            (var / v - 1.0).abs() < 0.2,
            "range {r}: variance {var}, expected {v}"
        );
    }
}
