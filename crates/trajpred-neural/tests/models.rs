//! Behaviour of the trained models: the loss falls, runs are reproducible, forecasts are
//! causal (and the causality check catches a leak), models save and load, bad input gives typed errors.

use trajpred_core::{Error as CoreError, Forecast, Predictor, Trajectory};
use trajpred_neural::{
    AxisMode, EarlyStopping, LstmArch, LstmNet, Mlp, MlpArch, NeuralError, RecurrentLayers,
    RnnArch, RnnNet, TrainConfig, TrainReport, WindowConfig, WindowNet,
};

/// A small 3-D curve: `n` points of a helix-like path.
fn curve(n: usize, phase: f64) -> Trajectory {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1 + phase).collect();
    Trajectory::uniform(
        0.0,
        0.1,
        vec![
            t.iter().map(|s| (0.7 * s).sin()).collect(),
            t.iter().map(|s| (0.5 * s).cos()).collect(),
            t.iter().map(|s| 0.3 * s + 0.2 * (1.3 * s).sin()).collect(),
        ],
    )
    .unwrap()
}

fn small_rec() -> RecurrentLayers {
    RecurrentLayers {
        layers: vec![16],
        fc: vec![16],
        ..RecurrentLayers::default()
    }
}

fn layout(axes: AxisMode) -> WindowConfig {
    WindowConfig {
        window: 5,
        horizon: 2,
        axes,
    }
}

fn falls(report: &TrainReport) {
    let first = report.first_loss().unwrap();
    let last = report.last_loss().unwrap();
    assert!(
        last < 0.5 * first,
        "loss did not fall enough: {first} -> {last}"
    );
}

#[test]
fn mlp_loss_falls_per_axis_and_forecasts() {
    let train = vec![curve(120, 0.0)];
    let mut m = Mlp::new(
        MlpArch::default(),
        layout(AxisMode::PerAxis),
        TrainConfig::new(1e-2).with_epochs(15).with_seed(3),
    )
    .unwrap();
    let mut seen = 0;
    let reports = m.fit_with(&train, &mut |_| seen += 1).unwrap().to_vec();
    assert_eq!(reports.len(), 3, "one network per axis");
    assert_eq!(seen, 45, "one callback per epoch per network");
    for r in &reports {
        falls(r);
    }
    let hist = curve(60, 0.0);
    let f = m.forecast(&hist, 4).unwrap();
    assert_eq!(f.horizon(), 4);
    let truth = curve(64, 0.0);
    let err = (f.step(1)[0] - truth.axis(0)[60]).abs();
    assert!(err < 0.2, "one-step error {err}");
}

#[test]
fn rnn_loss_falls_joint() {
    let train = vec![curve(100, 0.0), curve(100, 1.0)];
    let mut m = RnnNet::new(
        RnnArch(small_rec()),
        layout(AxisMode::Joint),
        TrainConfig::new(1e-2).with_epochs(8).with_seed(1),
    )
    .unwrap();
    let r = m.fit_with(&train, &mut |_| {}).unwrap();
    assert_eq!(r.len(), 1);
    falls(&r[0]);
}

#[test]
fn lstm_loss_falls_joint() {
    let train = vec![curve(100, 0.0), curve(100, 1.0)];
    let mut m = LstmNet::new(
        LstmArch(small_rec()),
        layout(AxisMode::Joint),
        TrainConfig::new(1e-2).with_epochs(8).with_seed(1),
    )
    .unwrap();
    let r = m.fit_with(&train, &mut |_| {}).unwrap();
    falls(&r[0]);
}

fn lstm_predictions(seed: u64) -> Vec<f64> {
    let train = vec![curve(60, 0.0)];
    let mut m = LstmNet::new(
        LstmArch(small_rec()),
        layout(AxisMode::Joint),
        TrainConfig::new(1e-2).with_epochs(2).with_seed(seed),
    )
    .unwrap();
    m.fit(&train).unwrap();
    let f = m.forecast(&curve(30, 0.5), 3).unwrap();
    f.points().flat_map(|p| p.to_vec()).collect()
}

#[test]
fn same_seed_same_predictions() {
    let a = lstm_predictions(11);
    let b = lstm_predictions(11);
    assert_eq!(a, b, "same seed must reproduce bit for bit");
    let c = lstm_predictions(12);
    assert_ne!(a, c, "another seed gives other weights");
}

/// `tr` with every point after `origin` changed: each coordinate moved by 100 to 200 (the
/// curves span about 2), each timestamp delayed by 0.03 to 0.07 s (samples are 0.1 s apart,
/// so times still increase).
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

/// A forecasting route: the forecast at `origin`, given the whole trajectory.
type Route<'a> = dyn Fn(&Trajectory, usize) -> Forecast + 'a;

/// Whether the forecast at some origin changes when every point after it changes.
fn leaks(route: &Route, tr: &Trajectory, origins: &[usize]) -> bool {
    origins
        .iter()
        .any(|&o| route(tr, o) != route(&change_after(tr, o), o))
}

/// A leaky predictor: it holds the trajectory it is evaluated on and returns the points
/// that follow its history's last timestamp there.
struct Peeker {
    full: Trajectory,
}

impl Predictor for Peeker {
    fn name(&self) -> &str {
        "peeker"
    }
    fn fit(&mut self, _train: &[Trajectory]) -> trajpred_core::Result<()> {
        Ok(())
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> trajpred_core::Result<Forecast> {
        let t = history.times().last().unwrap();
        let i = self.full.times().iter().position(|s| s == t).unwrap();
        let last = self.full.len() - 1;
        let steps: Vec<_> = (1..=horizon)
            .map(|k| self.full.point((i + k).min(last)))
            .collect();
        Forecast::new(history.dim(), steps)
    }
}

#[test]
fn forecasts_are_causal_and_the_check_catches_leaks() {
    let cfg = || TrainConfig::new(1e-2).with_epochs(2).with_seed(2);
    let mut mlp = Mlp::new(
        MlpArch {
            hidden: vec![8],
            ..MlpArch::default()
        },
        layout(AxisMode::Joint),
        cfg(),
    )
    .unwrap();
    let mut per_axis = Mlp::new(
        MlpArch {
            hidden: vec![8],
            ..MlpArch::default()
        },
        layout(AxisMode::PerAxis),
        cfg(),
    )
    .unwrap();
    let mut rnn = RnnNet::new(RnnArch(small_rec()), layout(AxisMode::Joint), cfg()).unwrap();
    let mut lstm = LstmNet::new(LstmArch(small_rec()), layout(AxisMode::PerAxis), cfg()).unwrap();
    let train = [curve(50, 0.0)];
    mlp.fit(&train).unwrap();
    per_axis.fit(&train).unwrap();
    rnn.fit(&train).unwrap();
    lstm.fit(&train).unwrap();
    let models: [(&str, &dyn Predictor); 4] = [
        ("mlp", &mlp),
        ("mlp per axis", &per_axis),
        ("rnn", &rnn),
        ("lstm", &lstm),
    ];
    let tr = curve(40, 0.3);
    // the first origin with a full window, one in the middle, the last but one point
    let origins = [4, 20, 38];
    for (name, m) in models {
        // horizon 5 > trained T = 2: the recursive part is covered too
        let prefix = |tr: &Trajectory, o: usize| m.forecast(&tr.prefix(o + 1).unwrap(), 5).unwrap();
        assert!(!leaks(&prefix, &tr, &origins), "{name}");
        // the check has power on this model: a history one point too long is caught
        let one_too_many =
            |tr: &Trajectory, o: usize| m.forecast(&tr.prefix(o + 2).unwrap(), 5).unwrap();
        assert!(
            leaks(&one_too_many, &tr, &origins),
            "{name}: leak unnoticed"
        );
        // and the forecast does depend on the past
        let moved = change_after(&tr, 0);
        for o in origins {
            assert_ne!(prefix(&tr, o), prefix(&moved, o), "{name} at origin {o}");
        }
    }
    // a predictor holding the trajectory it is evaluated on is caught
    let peek = |tr: &Trajectory, o: usize| {
        Peeker { full: tr.clone() }
            .forecast(&tr.prefix(o + 1).unwrap(), 5)
            .unwrap()
    };
    assert!(leaks(&peek, &tr, &origins));
    assert_eq!(peek(&tr, 20).step(1), &tr.point(21)[..]);
}

#[test]
fn beyond_the_trained_horizon_forecasts_are_recursive() {
    let mut m = Mlp::new(
        MlpArch {
            hidden: vec![8],
            ..MlpArch::default()
        },
        layout(AxisMode::Joint),
        TrainConfig::new(1e-2).with_epochs(2),
    )
    .unwrap();
    m.fit(&[curve(50, 0.0)]).unwrap();
    let h = curve(30, 0.0);
    let f = m.forecast(&h, 5).unwrap();
    // horizon 5 > trained T = 2: the first two steps equal the direct output ...
    let direct = m.forecast(&h, 2).unwrap();
    assert_eq!(f.step(1), direct.step(1));
    assert_eq!(f.step(2), direct.step(2));
    // ... and steps 3 and 4 are the direct output on the window moved by the first two
    let mut w: Vec<Vec<f64>> = (25..30).map(|i| h.point(i).to_vec()).collect();
    w.drain(..2);
    w.push(f.step(1).to_vec());
    w.push(f.step(2).to_vec());
    let next = m.predict_window(&w).unwrap();
    assert_eq!(f.step(3), &next[0][..]);
    assert_eq!(f.step(4), &next[1][..]);
}

#[test]
fn early_stopping_restores_best_and_reports_validation() {
    let mut m = Mlp::new(
        MlpArch {
            hidden: vec![8],
            ..MlpArch::default()
        },
        layout(AxisMode::Joint),
        TrainConfig::new(5e-2)
            .with_epochs(200)
            .with_early_stopping(EarlyStopping {
                validation_fraction: 0.25,
                patience: 3,
                min_delta: 1e-3,
            }),
    )
    .unwrap();
    let r = m.fit_with(&[curve(80, 0.0)], &mut |_| {}).unwrap()[0].clone();
    assert!(r.epochs.iter().all(|e| e.validation_loss.is_some()));
    assert!(r.stopped_early, "stopped after {} epochs", r.epochs.len());
    let best = r
        .epochs
        .iter()
        .map(|e| e.validation_loss.unwrap())
        .fold(f64::INFINITY, f64::min);
    assert_eq!(r.epochs[r.best_epoch - 1].validation_loss, Some(best));
}

#[test]
fn save_and_load_give_the_same_forecast() {
    let mut m = RnnNet::new(
        RnnArch(small_rec()),
        layout(AxisMode::PerAxis),
        TrainConfig::new(1e-2).with_epochs(2),
    )
    .unwrap();
    m.fit(&[curve(40, 0.0)]).unwrap();
    let dir = std::env::temp_dir().join(format!("trajpred-neural-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rnn.tpnn");
    m.save(&path).unwrap();
    let back = RnnNet::load(&path).unwrap();
    let h = curve(20, 0.3);
    assert_eq!(m.forecast(&h, 3).unwrap(), back.forecast(&h, 3).unwrap());
    // a file of another family is refused with a typed error
    assert!(matches!(
        LstmNet::load(&path),
        Err(NeuralError::Persistence { .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_gives_typed_errors() {
    let cfg = TrainConfig::new(1e-2).with_epochs(1);
    let mut m = WindowNet::new(MlpArch::default(), layout(AxisMode::Joint), cfg.clone()).unwrap();
    // not fitted
    assert!(matches!(
        m.predict_window(&vec![vec![0.0; 3]; 5]),
        Err(NeuralError::NotFitted)
    ));
    // too short to make one window + horizon
    assert!(matches!(
        m.fit_with(&[curve(6, 0.0)], &mut |_| {}),
        Err(NeuralError::Core(CoreError::TooShort {
            needed: 7,
            got: 6,
            ..
        }))
    ));
    // no data
    assert!(matches!(
        m.fit_with(&[], &mut |_| {}),
        Err(NeuralError::NoTrainingData { .. })
    ));
    // mixed dimensions
    let two_d = Trajectory::uniform(0.0, 1.0, vec![vec![0.0; 20], vec![1.0; 20]]).unwrap();
    assert!(matches!(
        m.fit_with(&[curve(20, 0.0), two_d.clone()], &mut |_| {}),
        Err(NeuralError::Core(CoreError::DimensionMismatch {
            expected: 3,
            got: 2,
            ..
        }))
    ));
    m.fit(&[curve(20, 0.0)]).unwrap();
    // NaN in a raw window
    let mut w = vec![vec![0.1, 0.2, 0.3]; 5];
    w[2][1] = f64::NAN;
    assert!(matches!(
        m.predict_window(&w),
        Err(NeuralError::Core(CoreError::NonFinite { index: 2, .. }))
    ));
    // wrong point dimension, wrong window length
    assert!(matches!(
        m.predict_window(&vec![vec![0.0; 2]; 5]),
        Err(NeuralError::Core(CoreError::DimensionMismatch {
            expected: 3,
            got: 2,
            ..
        }))
    ));
    assert!(matches!(
        m.predict_window(&vec![vec![0.0; 3]; 4]),
        Err(NeuralError::Core(CoreError::DimensionMismatch {
            expected: 5,
            got: 4,
            ..
        }))
    ));
    // through the Predictor trait: history too short, wrong dimension
    assert!(matches!(
        m.forecast(&curve(4, 0.0), 1),
        Err(trajpred_core::Error::TooShort {
            needed: 5,
            got: 4,
            ..
        })
    ));
    assert!(matches!(
        m.forecast(&two_d, 1),
        Err(trajpred_core::Error::DimensionMismatch {
            expected: 3,
            got: 2,
            ..
        })
    ));
    // invalid configurations
    assert!(matches!(
        WindowNet::new(
            MlpArch::default(),
            layout(AxisMode::Joint),
            cfg.clone().with_epochs(0)
        ),
        Err(NeuralError::Core(CoreError::InvalidParameter {
            name: "epochs",
            ..
        }))
    ));
    assert!(matches!(
        WindowNet::new(
            MlpArch::default(),
            WindowConfig {
                window: 0,
                horizon: 1,
                axes: AxisMode::Joint
            },
            cfg.clone()
        ),
        Err(NeuralError::Core(CoreError::InvalidParameter {
            name: "window",
            ..
        }))
    ));
    assert!(matches!(
        WindowNet::new(
            LstmArch(RecurrentLayers {
                layers: vec![],
                ..RecurrentLayers::default()
            }),
            layout(AxisMode::Joint),
            cfg.clone()
        ),
        Err(NeuralError::Core(CoreError::InvalidParameter {
            name: "layers",
            ..
        }))
    ));
    assert!(matches!(
        WindowNet::new(
            MlpArch::default(),
            layout(AxisMode::Joint),
            cfg.with_learning_rate(f64::NAN)
        ),
        Err(NeuralError::Core(CoreError::InvalidParameter {
            name: "learning_rate",
            ..
        }))
    ));
}

#[test]
fn divergence_is_an_error_not_a_nan() {
    let mut m = Mlp::new(
        MlpArch::default(),
        layout(AxisMode::Joint),
        TrainConfig::new(1e6)
            .with_optimizer(trajpred_neural::Optimizer::SGD)
            .with_epochs(50),
    )
    .unwrap();
    assert!(matches!(
        m.fit_with(&[curve(60, 0.0)], &mut |_| {}),
        Err(NeuralError::Diverged { .. })
    ));
}

#[test]
fn presets_have_the_papers_settings() {
    let bp = Mlp::gskf_bp(6, 6).unwrap();
    assert_eq!(bp.train_config().learning_rate, 0.1);
    assert_eq!(bp.train_config().epochs, 500);
    assert_eq!(bp.layout().axes, AxisMode::PerAxis);
    let lstm = LstmNet::gskf_lstm(6, 6).unwrap();
    assert_eq!(lstm.train_config().epochs, 500);
    assert_eq!(lstm.arch().0.layers, vec![64, 64]);
    let rnn = RnnNet::patent_baseline(10, 1).unwrap();
    assert_eq!(rnn.train_config().learning_rate, 1e-3);
    let lstm = LstmNet::patent_baseline(10, 1).unwrap();
    assert_eq!(lstm.train_config().batch_size, 16);
}

#[test]
fn per_axis_networks_train_in_parallel_and_reproducibly() {
    let run = || {
        let mut m = Mlp::new(
            MlpArch {
                hidden: vec![8],
                ..MlpArch::default()
            },
            layout(AxisMode::PerAxis),
            TrainConfig::new(1e-2).with_epochs(3).with_seed(4),
        )
        .unwrap();
        let mut seen = Vec::new();
        m.fit_with(&[curve(50, 0.0)], &mut |e| seen.push((e.network, e.epoch)))
            .unwrap();
        seen.sort_unstable();
        let f = m.forecast(&curve(20, 0.2), 2).unwrap();
        (seen, f)
    };
    let (seen, a) = run();
    let expected: Vec<(usize, usize)> = (0..3).flat_map(|n| (1..=3).map(move |e| (n, e))).collect();
    assert_eq!(
        seen, expected,
        "every epoch of every axis network is reported"
    );
    let (_, b) = run();
    assert_eq!(a, b);
}

/// `fit_targets` trains on the targets it is given: with the inputs as targets it is
/// `fit_with`; with other targets (here the inputs shifted by a constant, so a net that has
/// learnt them predicts about that constant higher) the forecasts move; mismatched targets
/// are typed errors.
#[test]
fn fit_targets_trains_on_the_given_targets() {
    let x = curve(80, 0.0);
    let shifted = Trajectory::uniform(
        0.0,
        0.1,
        (0..3)
            .map(|k| x.axis(k).iter().map(|v| v + 0.5).collect())
            .collect(),
    )
    .unwrap();
    let fit = |targets: Option<&Trajectory>| {
        let mut n = RnnNet::new(
            RnnArch(small_rec()),
            layout(AxisMode::Joint),
            TrainConfig::new(1e-2).with_epochs(30).with_seed(4),
        )
        .unwrap();
        match targets {
            None => n.fit_with(std::slice::from_ref(&x), &mut |_| {}).unwrap(),
            Some(t) => n
                .fit_targets(
                    std::slice::from_ref(&x),
                    std::slice::from_ref(t),
                    &mut |_| {},
                )
                .unwrap(),
        };
        let w: Vec<Vec<f64>> = x.points().skip(40).take(5).map(|p| p.to_vec()).collect();
        n.predict_window(&w).unwrap()
    };
    let plain = fit(None);
    assert_eq!(fit(Some(&x)), plain, "targets == inputs is fit_with");
    let up = fit(Some(&shifted));
    let lift: f64 = up
        .iter()
        .zip(&plain)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(p, q)| p - q))
        .sum::<f64>()
        / 6.0;
    assert!(
        (lift - 0.5).abs() < 0.25,
        "mean lift {lift}, expected about 0.5"
    );
    let mut n = RnnNet::new(
        RnnArch(small_rec()),
        layout(AxisMode::Joint),
        TrainConfig::new(1e-2).with_epochs(1),
    )
    .unwrap();
    let short = curve(70, 0.0);
    assert!(matches!(
        n.fit_targets(
            std::slice::from_ref(&x),
            std::slice::from_ref(&short),
            &mut |_| {}
        ),
        Err(NeuralError::Core(CoreError::DimensionMismatch { .. }))
    ));
    assert!(matches!(
        n.fit_targets(std::slice::from_ref(&x), &[], &mut |_| {}),
        Err(NeuralError::Core(CoreError::DimensionMismatch { .. }))
    ));
}
