//! The Kalman-filter-unfolded LSTM: gradient of the Kalman update against an independent
//! finite difference, training, reproducibility, batched one-step-ahead = per-origin forecast,
//! save/load, typed errors.

use trajpred_core::{Error as CoreError, Predictor, Trajectory};
use trajpred_neural::burn::tensor::{Device, Tensor, TensorData};
use trajpred_neural::{KfuConfig, KfuLstmNet, NeuralError, TrainConfig, kalman_update};

// ---------------------------------------------------------------------------------------
// Gradient of the Kalman update w.r.t. log Q and log R: burn's autodiff (f32) against a
// central finite difference of an independent plain-f64 implementation of the same loss.

const B: usize = 2;
const D: usize = 2;
const N: usize = 6;

fn z_obs(b: usize, t: usize, k: usize) -> f64 {
    ((t as f64) * 0.7 + (k as f64) * 1.3 + b as f64).sin() + 0.1 * ((t * 7 + k * 3 + b) % 5) as f64
}
fn truth(b: usize, t: usize, k: usize) -> f64 {
    ((t as f64) * 0.7 + (k as f64) * 1.3 + b as f64).sin()
}

/// Plain f64: prior = 0.9 x + 0.05, diagonal update, loss = MSE(post) + 0.5 MSE(prior).
fn loss_f64(log_q: [f64; D], log_r: [f64; D]) -> f64 {
    let (mut post_se, mut prior_se) = (0.0, 0.0);
    for b in 0..B {
        for k in 0..D {
            let (q, r) = (log_q[k].exp(), log_r[k].exp());
            let mut x = z_obs(b, 0, k);
            let mut p = 1.0;
            for t in 1..N {
                let prior = 0.9 * x + 0.05;
                let pp = p + q;
                let gain = pp / (pp + r);
                x = prior + gain * (z_obs(b, t, k) - prior);
                p = (1.0 - gain) * pp;
                prior_se += (prior - truth(b, t, k)).powi(2);
                post_se += (x - truth(b, t, k)).powi(2);
            }
        }
    }
    let n = (B * D * (N - 1)) as f64;
    post_se / n + 0.5 * prior_se / n
}

fn col(f: impl Fn(usize, usize, usize) -> f64, t: usize, device: &Device) -> Tensor<2> {
    let v: Vec<f32> = (0..B)
        .flat_map(|b| (0..D).map(move |k| (b, k)))
        .map(|(b, k)| f(b, t, k) as f32)
        .collect();
    Tensor::from_data(TensorData::new(v, [B, D]), device)
}

#[test]
fn kalman_update_gradient_matches_finite_difference() {
    let (lq, lr) = ([-1.2, -2.0], [-0.7, -1.5]);
    let device = Device::flex().autodiff();
    let log_q = Tensor::<1>::from_data(
        TensorData::new(vec![lq[0] as f32, lq[1] as f32], [D]),
        &device,
    )
    .require_grad();
    let log_r = Tensor::<1>::from_data(
        TensorData::new(vec![lr[0] as f32, lr[1] as f32], [D]),
        &device,
    )
    .require_grad();
    let q = log_q.clone().exp().unsqueeze::<2>();
    let r = log_r.clone().exp().unsqueeze::<2>();
    let mut x = col(z_obs, 0, &device);
    let mut p = Tensor::<2>::ones([B, D], &device);
    let mut priors = Vec::new();
    let mut posts = Vec::new();
    let mut truths = Vec::new();
    for t in 1..N {
        let prior = x * 0.9 + 0.05;
        let (post, pp) = kalman_update(
            prior.clone(),
            p,
            q.clone(),
            r.clone(),
            col(z_obs, t, &device),
        );
        priors.push(prior);
        posts.push(post.clone());
        truths.push(col(truth, t, &device));
        x = post;
        p = pp;
    }
    let y = Tensor::stack::<3>(truths, 1);
    let sq = |a: Tensor<3>| {
        let d = a - y.clone();
        (d.clone() * d).mean()
    };
    let loss = sq(Tensor::stack::<3>(posts, 1)) + sq(Tensor::stack::<3>(priors, 1)) * 0.5;
    let value = f64::from(loss.clone().into_data().try_to_vec::<f32>().unwrap()[0]);
    assert!(
        (value - loss_f64(lq, lr)).abs() < 1e-5,
        "the two implementations agree"
    );
    let grads = loss.backward();
    let gq = log_q
        .grad(&grads)
        .unwrap()
        .into_data()
        .try_to_vec::<f32>()
        .unwrap();
    let gr = log_r
        .grad(&grads)
        .unwrap()
        .into_data()
        .try_to_vec::<f32>()
        .unwrap();
    let h = 1e-5;
    for k in 0..D {
        let (mut a, mut b) = (lq, lq);
        a[k] += h;
        b[k] -= h;
        let fd_q = (loss_f64(a, lr) - loss_f64(b, lr)) / (2.0 * h);
        let (mut a, mut b) = (lr, lr);
        a[k] += h;
        b[k] -= h;
        let fd_r = (loss_f64(lq, a) - loss_f64(lq, b)) / (2.0 * h);
        for (what, ad, fd) in [("log Q", gq[k], fd_q), ("log R", gr[k], fd_r)] {
            let ad = f64::from(ad);
            assert!(
                fd.abs() > 1e-4,
                "{what}[{k}]: gradient too small to test ({fd})"
            );
            assert!(
                (ad - fd).abs() <= 1e-3 * fd.abs() + 1e-6,
                "{what}[{k}]: autodiff {ad} vs finite difference {fd}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------

fn clean(n: usize, phase: f64) -> Trajectory {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1 + phase).collect();
    Trajectory::uniform(
        0.0,
        0.1,
        vec![
            t.iter().map(|s| s.cos()).collect(),
            t.iter().map(|s| s.sin()).collect(),
            t.iter().map(|s| 0.2 * s).collect(),
        ],
    )
    .unwrap()
}

/// `clean` plus deterministic pseudo-noise.
fn noisy(n: usize, phase: f64) -> Trajectory {
    let c = clean(n, phase);
    let axes = c
        .axes()
        .enumerate()
        .map(|(k, a)| {
            a.iter()
                .enumerate()
                .map(|(i, v)| v + 0.05 * (((i * 31 + k * 17) % 13) as f64 / 6.0 - 1.0))
                .collect()
        })
        .collect();
    Trajectory::uniform(0.0, 0.1, axes).unwrap()
}

fn small(seed: u64, epochs: usize) -> KfuLstmNet {
    KfuLstmNet::new(
        KfuConfig {
            layers: vec![16],
            fc: vec![16],
            seq_len: 20,
            stride: 5,
            ..KfuConfig::default()
        },
        TrainConfig::new(3e-3)
            .with_epochs(epochs)
            .with_batch_size(16)
            .with_seed(seed),
    )
    .unwrap()
}

#[test]
fn supervised_loss_falls_and_noise_moves() {
    let obs = vec![noisy(80, 0.0), noisy(80, 2.0)];
    let truth = vec![clean(80, 0.0), clean(80, 2.0)];
    let mut m = small(5, 12);
    let mut epochs = Vec::new();
    let r = m
        .fit_supervised(&obs, &truth, &mut |e| epochs.push(e.train_loss))
        .unwrap()
        .clone();
    assert_eq!(epochs.len(), 12);
    let (first, last) = (r.first_loss().unwrap(), r.last_loss().unwrap());
    assert!(last < 0.7 * first, "loss {first} -> {last}");
    let (q, rr) = m.noise().unwrap();
    assert_eq!(q.len(), 3);
    assert!(
        rr.iter().any(|v| (v.ln() + 2.0).abs() > 1e-3),
        "log R moved: {rr:?}"
    );
}

#[test]
fn kfu_same_seed_same_predictions_and_batched_equals_forecast() {
    let obs = vec![noisy(60, 0.0)];
    let mut a = small(9, 2);
    a.fit(&obs).unwrap();
    let mut b = small(9, 2);
    b.fit(&obs).unwrap();
    let test = noisy(40, 1.0);
    let pa = a.one_step_ahead(&test).unwrap();
    assert_eq!(
        pa,
        b.one_step_ahead(&test).unwrap(),
        "same seed, same predictions"
    );
    assert_eq!(pa.len(), 39);
    // entry i = forecast from points 0..=i (short history, and beyond the 20-point context)
    for i in [0usize, 5, 18, 19, 20, 30, 38] {
        let f = a.forecast(&test.prefix(i + 1).unwrap(), 1).unwrap();
        for (k, (x, y)) in f.step(1).iter().zip(&pa[i]).enumerate() {
            assert!((x - y).abs() < 1e-5, "origin {i} axis {k}: {x} vs {y}");
        }
    }
}

/// `tr` with every point after `origin` changed: each coordinate moved by 100 to 200 (the
/// curves span about 2), each timestamp delayed by 0.03 to 0.07 s (samples are 0.1 s apart).
fn change_after(tr: &Trajectory, origin: usize) -> Trajectory {
    let mut times = tr.times().to_vec();
    let mut axes: Vec<Vec<f64>> = tr.axes().map(<[f64]>::to_vec).collect();
    for i in origin + 1..tr.len() {
        times[i] += 0.03 + 0.04 * ((i % 5) as f64 / 4.0);
        for (k, a) in axes.iter_mut().enumerate() {
            let sign = if (i + k) % 2 == 0 { 1.0 } else { -1.0 };
            a[i] += sign * (100.0 + (i % 101) as f64);
        }
    }
    Trajectory::from_axes(times, axes).unwrap()
}

/// Whether the prediction at some origin changes when every point after it changes;
/// `route` gets the whole trajectory and an origin.
fn leaks(
    route: &dyn Fn(&Trajectory, usize) -> Vec<f64>,
    tr: &Trajectory,
    origins: &[usize],
) -> bool {
    origins
        .iter()
        .any(|&o| route(tr, o) != route(&change_after(tr, o), o))
}

#[test]
fn kfu_is_causal_through_forecast_and_the_batched_pass() {
    let mut m = small(9, 2);
    m.fit(&[noisy(60, 0.0)]).unwrap();
    let tr = noisy(40, 1.0);
    // the context is 20 points: origins before it (one filter from point 0), at its edge
    // and after it (batched windows), up to the last but one point
    let origins = [0, 5, 18, 19, 20, 25, 38];
    // the batched pass is handed the whole trajectory: entry o is the prediction from
    // points 0..=o, and every earlier entry must not move either
    let batched =
        |tr: &Trajectory, o: usize| -> Vec<f64> { m.one_step_ahead(tr).unwrap()[..=o].concat() };
    assert!(!leaks(&batched, &tr, &origins), "one_step_ahead");
    let prefix = |tr: &Trajectory, o: usize| -> Vec<f64> {
        let f = m.forecast(&tr.prefix(o + 1).unwrap(), 3).unwrap();
        f.points().flat_map(|p| p.to_vec()).collect()
    };
    assert!(!leaks(&prefix, &tr, &origins), "forecast");
    // the check has power: reading one entry (one point) too far is caught on either route
    let one_too_far = |tr: &Trajectory, o: usize| m.one_step_ahead(tr).unwrap()[o + 1].clone();
    assert!(leaks(&one_too_far, &tr, &origins[..6]));
    let one_too_many = |tr: &Trajectory, o: usize| -> Vec<f64> {
        let f = m.forecast(&tr.prefix(o + 2).unwrap(), 3).unwrap();
        f.points().flat_map(|p| p.to_vec()).collect()
    };
    assert!(leaks(&one_too_many, &tr, &origins));
    // and the predictions do depend on the past
    let moved = change_after(&tr, 0);
    for o in &origins[1..] {
        assert_ne!(prefix(&tr, *o), prefix(&moved, *o), "origin {o}");
    }
}

#[test]
fn kfu_save_load_and_typed_errors() {
    let mut m = small(1, 1);
    assert!(matches!(m.noise(), Err(NeuralError::NotFitted)));
    assert!(matches!(
        m.fit_supervised(&[noisy(30, 0.0)], &[], &mut |_| {}),
        Err(NeuralError::Core(CoreError::DimensionMismatch { .. }))
    ));
    assert!(matches!(
        m.fit_supervised(&[noisy(30, 0.0)], &[clean(29, 0.0)], &mut |_| {}),
        Err(NeuralError::Core(CoreError::DimensionMismatch {
            expected: 30,
            got: 29,
            ..
        }))
    ));
    assert!(matches!(
        m.fit_observed(&[noisy(2, 0.0)], &mut |_| {}),
        Err(NeuralError::Core(CoreError::TooShort {
            needed: 3,
            got: 2,
            ..
        }))
    ));
    m.fit(&[noisy(30, 0.0)]).unwrap();
    let mut h = vec![vec![0.1, 0.2, 0.3]; 6];
    h[4][0] = f64::INFINITY;
    assert!(matches!(
        m.predict_series(&h, 1),
        Err(NeuralError::Core(CoreError::NonFinite { index: 4, .. }))
    ));
    assert!(matches!(
        m.predict_series(&[vec![0.0; 2]], 1),
        Err(NeuralError::Core(CoreError::DimensionMismatch {
            expected: 3,
            got: 2,
            ..
        }))
    ));
    assert!(matches!(
        m.predict_series(&[], 1),
        Err(NeuralError::Core(CoreError::TooShort { .. }))
    ));
    let dir = std::env::temp_dir().join(format!("trajpred-kfu-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("kfu.tpnn");
    m.save(&path).unwrap();
    let back = KfuLstmNet::load(&path).unwrap();
    let test = noisy(30, 0.5);
    assert_eq!(
        m.forecast(&test, 2).unwrap(),
        back.forecast(&test, 2).unwrap()
    );
    assert_eq!(m.noise().unwrap(), back.noise().unwrap());
    std::fs::write(&path, b"junk").unwrap();
    assert!(matches!(
        KfuLstmNet::load(&path),
        Err(NeuralError::Persistence { .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(matches!(
        KfuLstmNet::new(
            KfuConfig {
                seq_len: 2,
                ..KfuConfig::default()
            },
            TrainConfig::new(1e-3)
        ),
        Err(NeuralError::Core(CoreError::InvalidParameter {
            name: "seq_len",
            ..
        }))
    ));
}
