//! The multi-step forecast of "KF dynamic": the default (first step with the last observation,
//! then prediction alone) against the naive KF and a 2x2 Kalman recursion written out here,
//! and the paper's literal reading (every step re-uses the last observation) against the same
//! recursion.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trajpred::predictors::{Continuation, KfDynamic, KfDynamicParams, NaiveKf};
use trajpred::registry::{MethodOptions, build};
use trajpred_core::{Predictor, Trajectory};

/// A 1-D constant-velocity Kalman filter in the paper's predictor form, written out by hand:
/// state `[x, v]`, `A = [[1, dt], [0, 1]]`, `H = [1, 0]`, `Q = q I`, `R = r`.
#[derive(Clone, Copy)]
struct Hand {
    dt: f64,
    q: f64,
    r: f64,
}

type State = ([f64; 2], [[f64; 2]; 2]);

impl Hand {
    /// `A P A^T` of a symmetric `P`.
    fn apat(&self, p: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
        let dt = self.dt;
        let p00 = p[0][0] + 2.0 * dt * p[0][1] + dt * dt * p[1][1];
        let p01 = p[0][1] + dt * p[1][1];
        [[p00, p01], [p01, p[1][1]]]
    }

    /// Eq. 13-15 with observation `z`: `K = A P H^T / (P00 + r)`,
    /// `X' = A X + K (z - x)`, `P' = A P A^T - K (H P A^T) + Q`.
    fn step(&self, (x, p): State, z: f64) -> State {
        let dt = self.dt;
        let s = p[0][0] + self.r;
        // A P H^T = A (first column of P) = H P A^T transposed
        let aph = [p[0][0] + dt * p[1][0], p[1][0]];
        let k = [aph[0] / s, aph[1] / s];
        let innov = z - x[0];
        let xn = [x[0] + dt * x[1] + k[0] * innov, x[1] + k[1] * innov];
        let a = self.apat(p);
        let pn = [
            [a[0][0] - k[0] * aph[0] + self.q, a[0][1] - k[0] * aph[1]],
            [a[1][0] - k[1] * aph[0], a[1][1] - k[1] * aph[1] + self.q],
        ];
        (xn, pn)
    }

    /// Prediction alone: `X' = A X`, `P' = A P A^T + Q`.
    fn predict(&self, (x, p): State) -> State {
        let a = self.apat(p);
        (
            [x[0] + self.dt * x[1], x[1]],
            [[a[0][0] + self.q, a[0][1]], [a[1][0], a[1][1] + self.q]],
        )
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + b.abs())
}

#[test]
fn both_readings_match_a_hand_written_recursion_on_irregular_times() {
    // times 0, 1, 3, 3.5, 6: the filters step by the mean interval, 6 / 4 = 1.5 s
    let times = vec![0.0, 1.0, 3.0, 3.5, 6.0];
    let xs = vec![0.0, 2.0, 7.0, 8.0, 14.0];
    let tr = Trajectory::from_axes(times, vec![xs.clone()]).unwrap();
    let (q, r, p0) = (10.0, 10.0, 100.0);
    let hand = Hand { dt: 1.5, q, r };
    // X(1|0) = [z_0, 0], P(1|0) = p0 I, then eq. 13-15 through z_0..z_3
    let mut s: State = ([xs[0], 0.0], [[p0, 0.0], [0.0, p0]]);
    for &z in &xs[..4] {
        s = hand.step(s, z);
    }
    let last = xs[4];
    // step 1 uses the last observation in both readings
    let first = hand.step(s, last);
    // literal: steps 2 and 3 are the same update with the same observation again
    let lit2 = hand.step(first, last);
    let lit3 = hand.step(lit2, last);
    // default: prediction alone after the first step
    let ext2 = hand.predict(first);
    let ext3 = hand.predict(ext2);

    let literal = KfDynamic::new(KfDynamicParams::paper_position_literal(q)).unwrap();
    let default = KfDynamic::new(KfDynamicParams::paper_position(q)).unwrap();
    let fl = literal.forecast(&tr, 3).unwrap();
    let fd = default.forecast(&tr, 3).unwrap();
    for (k, (l, d)) in [(first, first), (lit2, ext2), (lit3, ext3)]
        .into_iter()
        .enumerate()
    {
        let k = k + 1;
        assert!(close(fl.step(k)[0], l.0[0]), "literal step {k}: {fl:?}");
        assert!(close(fd.step(k)[0], d.0[0]), "default step {k}: {fd:?}");
        let (cl, cd) = (fl.covariance(k).unwrap(), fd.covariance(k).unwrap());
        assert!(close(cl[(0, 0)], l.1[0][0]), "literal variance {k}");
        assert!(close(cd[(0, 0)], d.1[0][0]), "default variance {k}");
    }
    // the two readings part from step 2 on, and the literal one lags: it is pulled back
    // towards x = 14, where the target was last seen
    assert!(fl.step(2)[0] < fd.step(2)[0] - 0.1);
    assert!(fl.step(3)[0] < fd.step(3)[0] - 0.1);
    // the default extrapolates the filtered state by A, as the naive KF does
    let naive = NaiveKf::new(KfDynamicParams::paper_position(q))
        .unwrap()
        .forecast(&tr, 3)
        .unwrap();
    for k in 1..=3 {
        assert!(close(fd.step(k)[0], naive.step(k)[0]), "step {k}");
    }
}

/// A turning 2-D track (a circle of 80 m radius at about 8 m/s, then a straight leg) sampled
/// at seeded irregular intervals of 0.5..3.5 s, with a little position noise.
fn turning_track(n: usize, seed: u64) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut t: f64 = 0.0;
    let (mut times, mut x, mut y) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..n {
        let (px, py) = if t < 60.0 {
            let a = 0.1 * t;
            (80.0 * a.sin(), 80.0 * (1.0 - a.cos()))
        } else {
            // leave the circle along its tangent at t = 60 s
            let a: f64 = 6.0;
            let (x0, y0) = (80.0 * a.sin(), 80.0 * (1.0 - a.cos()));
            (
                x0 + 8.0 * a.cos() * (t - 60.0),
                y0 + 8.0 * a.sin() * (t - 60.0),
            )
        };
        times.push(t);
        x.push(px + rng.random::<f64>() - 0.5);
        y.push(py + rng.random::<f64>() - 0.5);
        t += 0.5 + 3.0 * rng.random::<f64>();
    }
    Trajectory::from_axes(times, vec![x, y]).unwrap()
}

/// Mean Euclidean error per step 1..=horizon over every origin of `tr` with `history` points.
fn step_errors(p: &dyn Predictor, tr: &Trajectory, history: usize, horizon: usize) -> Vec<f64> {
    let mut sum = vec![0.0; horizon];
    let mut count = 0usize;
    for origin in history - 1..tr.len() - horizon {
        let h = tr.slice(origin + 1 - history..origin + 1).unwrap();
        let f = p.forecast(&h, horizon).unwrap();
        for (k, s) in sum.iter_mut().enumerate() {
            let truth = tr.point(origin + k + 1);
            let got = f.step(k + 1);
            *s += ((got[0] - truth[0]).powi(2) + (got[1] - truth[1]).powi(2)).sqrt();
        }
        count += 1;
    }
    sum.into_iter().map(|s| s / count as f64).collect()
}

#[test]
fn default_is_no_worse_than_naive_kf_at_every_step_on_a_turning_irregular_track() {
    let tr = turning_track(120, 7);
    let opts = MethodOptions::default();
    for (dynamic, literal, naive) in [
        ("kf-dynamic", "kf-dynamic-literal", "naive-kf"),
        ("kf-dynamic-4d", "kf-dynamic-4d-literal", "naive-kf-4d"),
    ] {
        let d = step_errors(build(dynamic, &opts).unwrap().as_ref(), &tr, 20, 5);
        let l = step_errors(build(literal, &opts).unwrap().as_ref(), &tr, 20, 5);
        let n = step_errors(build(naive, &opts).unwrap().as_ref(), &tr, 20, 5);
        for k in 0..5 {
            assert!(
                d[k] <= n[k] * (1.0 + 1e-9),
                "{dynamic} step {}: {} vs {naive} {}",
                k + 1,
                d[k],
                n[k]
            );
        }
        // step 1 is the same in both readings; from step 2 on the literal one is worse here
        assert!(close(l[0], d[0]), "{literal} step 1: {} vs {}", l[0], d[0]);
        for k in 1..5 {
            assert!(
                l[k] > d[k],
                "{literal} step {}: {} vs {}",
                k + 1,
                l[k],
                d[k]
            );
        }
    }
}

#[test]
fn presets_and_registry_names_keep_the_mode() {
    assert_eq!(
        KfDynamicParams::default().multi_step,
        Continuation::Extrapolate
    );
    assert_eq!(
        KfDynamicParams::paper_position_velocity(100.0).multi_step,
        Continuation::Extrapolate
    );
    let lit = KfDynamicParams::paper_position_velocity_literal(100.0);
    assert_eq!(lit.multi_step, Continuation::ReuseLastObservation);
    assert_eq!(
        KfDynamicParams {
            multi_step: Continuation::Extrapolate,
            ..lit
        },
        KfDynamicParams::paper_position_velocity(100.0)
    );
    // on a straight uniform track the registry's default and literal methods agree at step
    // 1 and differ at step 2 (the literal one is pulled back towards the last point)
    let tr =
        Trajectory::uniform(0.0, 1.0, vec![(0..30).map(|i| 2.0 * i as f64).collect()]).unwrap();
    let opts = MethodOptions::default();
    let d = build("kf-dynamic", &opts)
        .unwrap()
        .forecast(&tr, 2)
        .unwrap();
    let l = build("kf-dynamic-literal", &opts)
        .unwrap()
        .forecast(&tr, 2)
        .unwrap();
    assert!(close(d.step(1)[0], l.step(1)[0]));
    assert!((d.step(2)[0] - 62.0).abs() < 0.5, "{d:?}");
    assert!(l.step(2)[0] < 61.0, "{l:?}");
}
