//! Training cost of the recurrent models (criterion).
//!
//! - `lstm_epoch_800x10_b16`: one epoch of the 2 x 64 LSTM (+ one 64 fully connected hidden
//!   layer, ReLU, then Linear(64, 3)) on an 800-step 3-D sine trajectory, window 10,
//!   next-step target, batch 16 (790 windows -> 50 batches), Adam lr 1e-3: the workload of
//!   `examples/profile_speed.rs lstm` and `benches/pytorch_lstm_epoch.py`.
//! - `lstm_epoch_800x10_b16_plain_head`: the same with the output layer directly on the LSTM
//!   (Linear(64, 3)), the network of `shared/research/torch-anchor.md` row a.
//! - `burn_nn_lstm_epoch_800x10_b16`: burn's own `nn::Lstm` on the same batches, for scale.
//! - `kfu_iteration_200_b16`: one KFU-LSTM-Net iteration (forward through 200 steps, backward,
//!   Adam step) on a batch of 16 noisy 200-step 3-D sine trajectories.
//!
//! Each case times epochs only, as the training loop reports them (`EpochReport::elapsed`;
//! not `fit`'s data preparation and network build): criterion gets the sum over the epochs
//! it asks for, and after its estimate every case prints the **median** epoch with its
//! quartiles, minimum and maximum over all the epochs criterion ran (its warm-up included).
//!
//! Run: `cargo bench -p trajpred-neural --bench training` (criterion's own median and
//! median absolute deviation: add `-- --verbose`).

// the per-epoch summary on standard output is this benchmark's result
#![allow(clippy::print_stdout)]

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::{Duration, Instant};
use trajpred_core::Trajectory;
use trajpred_neural::burn::module::Module;
use trajpred_neural::burn::nn::{Linear, LinearConfig, Lstm, LstmConfig};
use trajpred_neural::burn::optim::{AdamConfig, GradientsParams};
use trajpred_neural::burn::tensor::{Device, Tensor, TensorData};
use trajpred_neural::{
    AxisMode, EpochReport, KfuConfig, KfuLstmNet, LstmArch, LstmNet, RecurrentLayers, TrainConfig,
    WindowConfig,
};

fn sine(n: usize, phase: f64, noise: f64) -> Trajectory {
    let k: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let wobble = |i: usize, a: usize| noise * ((((i * 31 + a * 17) % 13) as f64) / 6.0 - 1.0);
    Trajectory::uniform(
        0.0,
        1.0,
        vec![
            k.iter()
                .enumerate()
                .map(|(i, s)| (0.05 * s + phase).sin() + wobble(i, 0))
                .collect(),
            k.iter()
                .enumerate()
                .map(|(i, s)| (0.065 * s + 0.5 + phase).sin() + wobble(i, 1))
                .collect(),
            k.iter()
                .enumerate()
                .map(|(i, s)| (0.035 * s + 1.0 + phase).sin() + wobble(i, 2))
                .collect(),
        ],
    )
    .expect("valid trajectory")
}

/// Prints the median, quartiles, minimum and maximum of `epochs`.
fn report_epochs(name: &str, epochs: &mut [Duration]) {
    if epochs.is_empty() {
        return;
    }
    epochs.sort();
    let ms = |q: f64| {
        let pos = q * (epochs.len() - 1) as f64;
        let (lo, hi) = (epochs[pos.floor() as usize], epochs[pos.ceil() as usize]);
        let (lo, hi) = (lo.as_secs_f64(), hi.as_secs_f64());
        1e3 * (lo + (hi - lo) * (pos - pos.floor()))
    };
    println!(
        "{name}: per epoch median {:.2} ms, quartiles [{:.2} {:.2}] ms, min {:.2} ms, max {:.2} ms, {} epochs",
        ms(0.5),
        ms(0.25),
        ms(0.75),
        ms(0.0),
        ms(1.0),
        epochs.len()
    );
}

/// Criterion's routine over `iters` epochs of a fresh training run: trains with `fit`
/// (given the number of epochs), records each epoch's time in `epochs`, returns their sum.
fn epochs_of(
    iters: u64,
    epochs: &mut Vec<Duration>,
    fit: impl FnOnce(usize, &mut dyn FnMut(&EpochReport)),
) -> Duration {
    let mut total = Duration::ZERO;
    fit(iters as usize, &mut |r| {
        total += r.elapsed;
        epochs.push(r.elapsed);
    });
    total
}

fn lstm_epoch(c: &mut Criterion, name: &str, fc: Vec<usize>) {
    let data = vec![sine(800, 0.0, 0.0)];
    let train = TrainConfig::new(1e-3).with_batch_size(16);
    let mut model = LstmNet::new(
        LstmArch(RecurrentLayers {
            layers: vec![64, 64],
            fc,
            ..RecurrentLayers::default()
        }),
        WindowConfig {
            window: 10,
            horizon: 1,
            axes: AxisMode::Joint,
        },
        train.clone(),
    )
    .expect("valid config");
    let mut epochs = Vec::new();
    c.bench_function(name, |b| {
        b.iter_custom(|iters| {
            epochs_of(iters, &mut epochs, |n, progress| {
                model
                    .set_train_config(train.clone().with_epochs(n))
                    .expect("valid config");
                model.fit_with(&data, progress).expect("trains");
            })
        })
    });
    report_epochs(name, &mut epochs);
}

/// burn's own `nn::Lstm` (one linear map per gate), 2 x 64 + Linear(64, 3), the same 50
/// batches of 16 windows: the reference for our fused layer, in the same sitting.
#[derive(Module, Debug)]
struct BurnLstm {
    l0: Lstm,
    l1: Lstm,
    out: Linear,
}

fn burn_lstm_epoch(c: &mut Criterion) {
    let device = Device::flex().autodiff();
    let tr = sine(800, 0.0, 0.0);
    let (m, n) = (10, 790);
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for i in 0..n {
        for s in i..i + m {
            xs.extend((0..3).map(|k| tr.axis(k)[s] as f32));
        }
        ys.extend((0..3).map(|k| tr.axis(k)[i + m] as f32));
    }
    let mut model = BurnLstm {
        l0: LstmConfig::new(3, 64, true).init(&device),
        l1: LstmConfig::new(64, 64, true).init(&device),
        out: LinearConfig::new(64, 3).init(&device),
    };
    let mut opt = AdamConfig::new().with_epsilon(1e-8).init();
    let mut epoch = || {
        let start = Instant::now();
        for first in (0..n).step_by(16) {
            let bs = 16.min(n - first);
            let x = Tensor::<3>::from_data(
                TensorData::new(xs[first * m * 3..(first + bs) * m * 3].to_vec(), [bs, m, 3]),
                &device,
            );
            let y = Tensor::<2>::from_data(
                TensorData::new(ys[first * 3..(first + bs) * 3].to_vec(), [bs, 3]),
                &device,
            );
            let (h, _) = model.l0.forward(x, None);
            let (_, s) = model.l1.forward(h, None);
            let d = model.out.forward(s.hidden) - y;
            let loss = (d.clone() * d).mean();
            let grads = GradientsParams::from_grads(loss.backward(), &model);
            model = opt.step(1e-3, model.clone(), grads);
        }
        start.elapsed()
    };
    let name = "burn_nn_lstm_epoch_800x10_b16";
    let mut epochs = Vec::new();
    c.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let t = epoch();
                total += t;
                epochs.push(t);
            }
            total
        })
    });
    report_epochs(name, &mut epochs);
}

fn kfu_iteration(c: &mut Criterion) {
    let data: Vec<Trajectory> = (0..16).map(|i| sine(200, i as f64 * 0.4, 0.1)).collect();
    let train = TrainConfig::new(1e-4).with_batch_size(16);
    let mut kfu = KfuLstmNet::new(
        KfuConfig {
            seq_len: 200,
            stride: 200,
            ..KfuConfig::default()
        },
        train.clone(),
    )
    .expect("valid config");
    let name = "kfu_iteration_200_b16";
    let mut epochs = Vec::new();
    c.bench_function(name, |b| {
        b.iter_custom(|iters| {
            epochs_of(iters, &mut epochs, |n, progress| {
                kfu.set_train_config(train.clone().with_epochs(n))
                    .expect("valid config");
                kfu.fit_observed(&data, progress).expect("trains");
            })
        })
    });
    report_epochs(name, &mut epochs);
}

fn benches(c: &mut Criterion) {
    burn_lstm_epoch(c);
    lstm_epoch(c, "lstm_epoch_800x10_b16", vec![64]);
    lstm_epoch(c, "lstm_epoch_800x10_b16_plain_head", vec![]);
    kfu_iteration(c);
}

criterion_group! {
    name = training;
    config = Criterion::default().sample_size(10);
    targets = benches
}
criterion_main!(training);
