//! The fused path (`TrainConfig::fused`, default on) against burn's per-operation autodiff:
//! the same weights give the same predictions, and the same seed trains to the same
//! predictions, up to f32 rounding.
//!
//! Tolerance 1e-5 in original units (data of amplitude ~1), for the same weights and for the
//! same seed after four epochs of training (measured: 0 to 1e-7; the two paths round
//! differently in f32, which moves the weights apart a little at every Adam step).

use trajpred_core::{Predictor, Trajectory};
use trajpred_neural::{
    AxisMode, KfuConfig, KfuLstmNet, LstmArch, LstmNet, RecurrentLayers, TrainConfig, WindowConfig,
};

fn sine(n: usize, phase: f64) -> Trajectory {
    let axis = |w: f64, p: f64| -> Vec<f64> {
        (0..n)
            .map(|i| (w * i as f64 + p + phase).sin() + 0.05 * ((i * 7) % 5) as f64)
            .collect()
    };
    Trajectory::uniform(0.0, 1.0, vec![axis(0.11, 0.0), axis(0.07, 0.5)]).expect("valid")
}

fn max_diff(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn forecast(m: &dyn Predictor, history: &Trajectory, horizon: usize) -> Vec<Vec<f64>> {
    let f = m.forecast(history, horizon).expect("forecast");
    (1..=horizon).map(|k| f.step(k).to_vec()).collect()
}

fn kfu(fused: bool) -> KfuLstmNet {
    KfuLstmNet::new(
        KfuConfig {
            layers: vec![8, 6],
            fc: vec![5],
            seq_len: 12,
            stride: 4,
            ..KfuConfig::default()
        },
        TrainConfig::new(3e-3)
            .with_epochs(4)
            .with_batch_size(4)
            .with_seed(3)
            .with_fused(fused),
    )
    .expect("valid config")
}

#[test]
fn kfu_same_weights_same_predictions_with_and_without_fused_path() {
    let data = vec![sine(60, 0.0), sine(60, 1.0)];
    let history = sine(40, 2.0);
    let mut model = kfu(false);
    model.fit(&data).expect("trains");
    let composed = forecast(&model, &history, 5);
    let composed_1 = model.one_step_ahead(&history).expect("one step");
    model
        .set_train_config(model.train_config().clone().with_fused(true))
        .expect("valid");
    let fused = forecast(&model, &history, 5);
    let fused_1 = model.one_step_ahead(&history).expect("one step");
    let (d, d1) = (max_diff(&fused, &composed), max_diff(&fused_1, &composed_1));
    assert!(d <= 1e-5, "forecast: {d:e}");
    assert!(d1 <= 1e-5, "one step ahead: {d1:e}");
}

#[test]
fn kfu_same_seed_trains_to_the_same_predictions_with_and_without_fused_path() {
    let data = vec![sine(60, 0.0), sine(60, 1.0)];
    let history = sine(40, 2.0);
    let mut runs = Vec::new();
    for fused in [true, false] {
        let mut model = kfu(fused);
        model.fit(&data).expect("trains");
        runs.push(forecast(&model, &history, 5));
    }
    let d = max_diff(&runs[0], &runs[1]);
    assert!(d <= 1e-5, "{d:e}");
}

#[test]
fn lstm_same_seed_trains_to_the_same_predictions_with_and_without_fused_path() {
    let data = vec![sine(80, 0.0)];
    let history = sine(30, 2.0);
    let mut runs = Vec::new();
    for fused in [true, false] {
        let mut model = LstmNet::new(
            LstmArch(RecurrentLayers {
                layers: vec![8, 6],
                fc: vec![5],
                ..RecurrentLayers::default()
            }),
            WindowConfig {
                window: 6,
                horizon: 2,
                axes: AxisMode::Joint,
            },
            TrainConfig::new(3e-3)
                .with_epochs(4)
                .with_batch_size(8)
                .with_seed(5)
                .with_fused(fused),
        )
        .expect("valid config");
        model.fit(&data).expect("trains");
        runs.push(forecast(&model, &history, 4));
    }
    let d = max_diff(&runs[0], &runs[1]);
    assert!(d <= 1e-5, "{d:e}");
}
