//! Training cost of the recurrent models (criterion).
//!
//! - `lstm_epoch_800x10_b16`: one epoch of the 2 x 64 LSTM (+ one 64 fully connected hidden
//!   layer) on an 800-step 3-D sine trajectory, window 10, next-step target, batch 16
//!   (790 windows -> 50 batches), Adam lr 1e-3.
//! - `lstm_epoch_800x10_b16_plain_head`: the same with the output layer directly on the LSTM
//!   (Linear(64, 3)), the network of `shared/research/torch-anchor.md` row a.
//! - `kfu_iteration_200_b16`: one KFU-LSTM-Net iteration (forward through 200 steps, backward,
//!   Adam step) on a batch of 16 noisy 200-step 3-D sine trajectories.
//!
//! Run: `cargo bench -p trajpred-neural -- --warm-up-time 1 --measurement-time 5`.

use criterion::{Criterion, criterion_group, criterion_main};
use trajpred_core::Trajectory;
use trajpred_neural::burn::module::Module;
use trajpred_neural::burn::nn::{Linear, LinearConfig, Lstm, LstmConfig};
use trajpred_neural::burn::optim::{AdamConfig, GradientsParams};
use trajpred_neural::burn::tensor::{Device, Tensor, TensorData};
use trajpred_neural::{
    AxisMode, KfuConfig, KfuLstmNet, LstmArch, LstmNet, RecurrentLayers, TrainConfig, WindowConfig,
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

fn lstm_epoch(c: &mut Criterion, name: &str, fc: Vec<usize>) {
    let data = vec![sine(800, 0.0, 0.0)];
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
        TrainConfig::new(1e-3).with_epochs(1).with_batch_size(16),
    )
    .expect("valid config");
    c.bench_function(name, |b| {
        b.iter(|| model.fit_with(&data, &mut |_| {}).expect("trains").len())
    });
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
    c.bench_function("burn_nn_lstm_epoch_800x10_b16", |b| {
        b.iter(|| {
            for start in (0..n).step_by(16) {
                let bs = 16.min(n - start);
                let x = Tensor::<3>::from_data(
                    TensorData::new(xs[start * m * 3..(start + bs) * m * 3].to_vec(), [bs, m, 3]),
                    &device,
                );
                let y = Tensor::<2>::from_data(
                    TensorData::new(ys[start * 3..(start + bs) * 3].to_vec(), [bs, 3]),
                    &device,
                );
                let (h, _) = model.l0.forward(x, None);
                let (_, s) = model.l1.forward(h, None);
                let d = model.out.forward(s.hidden) - y;
                let loss = (d.clone() * d).mean();
                let grads = GradientsParams::from_grads(loss.backward(), &model);
                model = opt.step(1e-3, model.clone(), grads);
            }
        })
    });
}

fn benches(c: &mut Criterion) {
    burn_lstm_epoch(c);
    lstm_epoch(c, "lstm_epoch_800x10_b16", vec![64]);
    lstm_epoch(c, "lstm_epoch_800x10_b16_plain_head", vec![]);
    let data: Vec<Trajectory> = (0..16).map(|i| sine(200, i as f64 * 0.4, 0.1)).collect();
    let mut kfu = KfuLstmNet::new(
        KfuConfig {
            seq_len: 200,
            stride: 200,
            ..KfuConfig::default()
        },
        TrainConfig::new(1e-4).with_epochs(1).with_batch_size(16),
    )
    .expect("valid config");
    c.bench_function("kfu_iteration_200_b16", |b| {
        b.iter(|| {
            kfu.fit_observed(&data, &mut |_| {})
                .expect("trains")
                .epochs
                .len()
        })
    });
}

criterion_group! {
    name = training;
    config = Criterion::default().sample_size(10);
    targets = benches
}
criterion_main!(training);
