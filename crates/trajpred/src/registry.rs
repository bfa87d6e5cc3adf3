//! Every predictor by name, for the CLI, the harness and the reproduction: one place that
//! turns `"kf-dynamic"` into a `Box<dyn Predictor>`.

use crate::predictors::*;
use serde::{Deserialize, Serialize};
use trajpred_core::{Error, Predictor, Result};

/// Options shared by the predictors built by name (each method reads the ones it uses).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodOptions {
    /// `Q = q I` of the KF-dynamic paper's filters.
    pub kf_q: f64,
    /// Points fitted by the polynomial baselines.
    pub poly_points: usize,
    /// Seed of every randomised method.
    pub seed: u64,
    /// Window length m of the GSC/GSKF.
    pub window: usize,
    /// Horizons T the multi-step models are fitted for (the longest forecast they answer).
    pub horizons: usize,
    /// Training epochs of the neural networks; `None` keeps each preset's (the papers').
    pub epochs: Option<usize>,
    /// The evaluation the methods that choose by cross-validation (`auto`, `aligned-ridge`)
    /// score their held-out folds by: the run's history, horizon, stride and origins.
    #[serde(default)]
    pub eval: crate::harness::EvalConfig,
    /// Held-out forecasts shared by the methods built with these options that
    /// cross-validate candidates (`auto`, `blend`): with one cache, a run that holds both
    /// fits each candidate on each fold once. `None` (the default): each computes its own.
    /// Not saved.
    #[serde(skip)]
    pub held_out: Option<std::sync::Arc<crate::predictors::HeldOutCache>>,
}

impl Default for MethodOptions {
    fn default() -> Self {
        MethodOptions {
            kf_q: 10.0,
            poly_points: 5,
            seed: 0,
            window: 6,
            horizons: 6,
            epochs: None,
            eval: crate::harness::EvalConfig::default(),
            held_out: None,
        }
    }
}

/// A method the registry can build: its name and a one-line description.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MethodInfo {
    /// The name used on the command line.
    pub name: &'static str,
    /// What it is.
    pub description: &'static str,
}

/// Every method the registry knows, in a stable order.
pub const METHODS: &[MethodInfo] = &[
    MethodInfo {
        name: "kf-dynamic",
        description: "KF-dynamic paper: predictor form of the Kalman filter (eq. 13-15), CV model, \
                      extrapolated after the first step",
    },
    MethodInfo {
        name: "kf-dynamic-4d",
        description: "KF dynamic with the 4-D position + velocity observation (R = I)",
    },
    MethodInfo {
        name: "kf-dynamic-literal",
        description: "KF dynamic as the paper reads literally: every step re-uses the last observation",
    },
    MethodInfo {
        name: "kf-dynamic-4d-literal",
        description: "kf-dynamic-literal with the 4-D position + velocity observation (R = I)",
    },
    MethodInfo {
        name: "naive-kf",
        description: "Kalman filter through the history, then uncorrected CV extrapolation",
    },
    MethodInfo {
        name: "naive-kf-4d",
        description: "naive KF with the 4-D position + velocity observation (R = I)",
    },
    MethodInfo {
        name: "kf-cv",
        description: "Kalman filter over actual time: constant velocity, continuous white-noise acceleration, q and r fitted by maximum likelihood",
    },
    MethodInfo {
        name: "kf-ca",
        description: "Kalman filter over actual time: constant acceleration, continuous white-noise jerk, q and r fitted by maximum likelihood",
    },
    MethodInfo {
        name: "imm",
        description: "interacting multiple model over actual time: constant velocity + coordinated turn (EKF), noise and switching fitted by maximum likelihood",
    },
    MethodInfo {
        name: "cv-time",
        description: "last velocity (last two points over their time difference), on the history's mean interval",
    },
    MethodInfo {
        name: "last-position",
        description: "persistence: the last position at every step",
    },
    MethodInfo {
        name: "poly1",
        description: "least-squares line through the last N points, extrapolated",
    },
    MethodInfo {
        name: "poly2",
        description: "least-squares parabola through the last N points, extrapolated",
    },
    MethodInfo {
        name: "gsc",
        description: "GSKF paper: group sparse coding (LAR per horizon), per axis",
    },
    MethodInfo {
        name: "gskf",
        description: "GSKF paper: GSC corrected by the improved one-step-ahead Kalman filter, or by a gain fitted to the training series where held-out data prefer it",
    },
    MethodInfo {
        name: "pf",
        description: "MKPF paper baseline: bootstrap particle filter (500 particles), CV model",
    },
    MethodInfo {
        name: "mkpf",
        description: "MKPF paper: particle filter with a UKF+EKF proposal (50 particles), CV model",
    },
    MethodInfo {
        name: "hmm",
        description: "k-means motion states + HMM forward filter (K chosen on training data)",
    },
    MethodInfo {
        name: "aligned-ridge",
        description: "last velocity corrected by a ridge regression in the heading-aligned frame, strength chosen by CV by user",
    },
    MethodInfo {
        name: "aligned-gbm",
        description: "last velocity (or last position, where it forecasts the training tracks better) corrected by gradient-boosted trees in the heading-aligned frame",
    },
    #[cfg(feature = "neural")]
    MethodInfo {
        name: "aligned-mlp",
        description: "last velocity (or last position, where it forecasts the training tracks better) corrected by a neural network in the heading-aligned frame, fitted to the mean distance",
    },
    MethodInfo {
        name: "auto",
        description: "the candidate with the lowest cross-validated error by user on the training part (see predictors::Auto)",
    },
    MethodInfo {
        name: "blend",
        description: "a weighted mean of the candidates' forecasts, weights per step chosen on forecasts held out by user (see predictors::Blend)",
    },
];

/// The neural methods (with the `neural` feature, on by default).
#[cfg(feature = "neural")]
pub const NEURAL_METHODS: &[MethodInfo] = &[
    MethodInfo {
        name: "bp",
        description: "GSKF paper's BP: MLP (one hidden layer of 10), SGD lr 0.1, 500 epochs, per axis",
    },
    MethodInfo {
        name: "lstm",
        description: "GSKF paper's LSTM baseline: 2 x 64 LSTM + FC, lr 0.1, 500 epochs, per axis",
    },
    MethodInfo {
        name: "rnn-patent",
        description: "KFU-LSTM patent baseline: 2 x 64 RNN + FC, Adam lr 1e-3",
    },
    MethodInfo {
        name: "lstm-patent",
        description: "KFU-LSTM patent baseline: 2 x 64 LSTM + FC, Adam lr 1e-3",
    },
    MethodInfo {
        name: "kfu-lstm",
        description: "KFU-LSTM-Net: Kalman filter unfolded around a learned LSTM transition",
    },
];

/// Every method this build knows: [`METHODS`] and, with the `neural` feature, the networks.
pub fn all_methods() -> Vec<MethodInfo> {
    let mut v = METHODS.to_vec();
    #[cfg(feature = "neural")]
    v.extend_from_slice(NEURAL_METHODS);
    v
}

/// Methods `--methods all` leaves out: the particle filters, for their run time (minutes on
/// a leaderboard's hundred thousand forecasts, and far behind on real data: see
/// `docs/accuracy.md`). The neural networks ([`all_methods`] beyond [`METHODS`]) are left
/// out too: hundreds of training epochs each.
pub const SLOW_METHODS: &[&str] = &["pf", "mkpf"];

/// What `--methods all` runs: [`METHODS`] without [`SLOW_METHODS`], in registry order.
pub fn leaderboard_methods() -> Vec<&'static str> {
    METHODS
        .iter()
        .map(|m| m.name)
        .filter(|n| !SLOW_METHODS.contains(n))
        .collect()
}

#[cfg(feature = "neural")]
fn build_neural(name: &str, opts: &MethodOptions) -> Result<Option<Box<dyn Predictor>>> {
    use trajpred_neural::{KfuLstmNet, LstmNet, Mlp, RnnNet};
    let e = |err: trajpred_neural::NeuralError| Error::from_crate(name.to_string(), err);
    macro_rules! with_epochs {
        ($net:expr) => {{
            let mut net = $net.map_err(e)?;
            if let Some(n) = opts.epochs {
                let cfg = net.train_config().clone().with_epochs(n);
                net.set_train_config(cfg).map_err(e)?;
            }
            Some(Box::new(net) as Box<dyn Predictor>)
        }};
    }
    let (m, t) = (opts.window, opts.horizons);
    Ok(match name {
        "bp" => with_epochs!(Mlp::gskf_bp(m, t)),
        "lstm" => with_epochs!(LstmNet::gskf_lstm(m, t)),
        "rnn-patent" => with_epochs!(RnnNet::patent_baseline(m, t)),
        "lstm-patent" => with_epochs!(LstmNet::patent_baseline(m, t)),
        "kfu-lstm" => with_epochs!(KfuLstmNet::patent()),
        _ => None,
    })
}

#[cfg(not(feature = "neural"))]
fn build_neural(_name: &str, _opts: &MethodOptions) -> Result<Option<Box<dyn Predictor>>> {
    Ok(None)
}

/// Builds the predictor called `name` (see [`METHODS`]); an unknown name is an
/// [`Error::InvalidParameter`] listing the known ones.
pub fn build(name: &str, opts: &MethodOptions) -> Result<Box<dyn Predictor>> {
    if let Some(p) = build_neural(name, opts)? {
        return Ok(p);
    }
    Ok(match name {
        "kf-dynamic" => Box::new(KfDynamic::new(KfDynamicParams::paper_position(opts.kf_q))?),
        "kf-dynamic-4d" => Box::new(KfDynamic::new(KfDynamicParams::paper_position_velocity(
            opts.kf_q,
        ))?),
        "kf-dynamic-literal" => Box::new(KfDynamic::new(KfDynamicParams::paper_position_literal(
            opts.kf_q,
        ))?),
        "kf-dynamic-4d-literal" => Box::new(KfDynamic::new(
            KfDynamicParams::paper_position_velocity_literal(opts.kf_q),
        )?),
        "naive-kf" => Box::new(NaiveKf::new(KfDynamicParams::paper_position(opts.kf_q))?),
        "naive-kf-4d" => Box::new(NaiveKf::new(KfDynamicParams::paper_position_velocity(
            opts.kf_q,
        ))?),
        "kf-cv" | "kf-ca" => Box::new(KfTime::new(KfTimeParams {
            derivatives: if name == "kf-cv" { 2 } else { 3 },
            ..Default::default()
        })?),
        "cv-time" => Box::new(CvTime::new()),
        "last-position" => Box::new(LastPosition::new()),
        "imm" => Box::new(ImmPredictor::new(ImmParams::default())?),
        "poly1" | "poly2" => Box::new(PolyFit::new(PolyFitParams {
            degree: if name == "poly1" { 1 } else { 2 },
            points: opts.poly_points,
        })?),
        "gsc" => Box::new(Gsc::new(GskfParams {
            window: opts.window,
            horizons: opts.horizons,
            ..Default::default()
        })?),
        "gskf" => Box::new(Gskf::new(GskfParams {
            window: opts.window,
            horizons: opts.horizons,
            ..Default::default()
        })?),
        "pf" | "mkpf" => Box::new(ParticlePredictor::new(ParticleParams {
            seed: opts.seed,
            ..ParticleParams::new(if name == "pf" {
                ParticleKind::Bootstrap
            } else {
                ParticleKind::Mkpf
            })
        })?),
        "hmm" => Box::new(Hmm::new(HmmParams {
            seed: opts.seed,
            horizon: opts.eval.horizon,
            ..Default::default()
        })?),
        "aligned-ridge" => Box::new(AlignedRidge::new(AlignedRidgeParams {
            horizons: opts.horizons,
            seed: opts.seed,
            eval: opts.eval,
            ..Default::default()
        })?),
        "aligned-gbm" => Box::new(AlignedGbm::new(AlignedGbmParams {
            horizons: opts.horizons,
            ..Default::default()
        })?),
        #[cfg(feature = "neural")]
        "aligned-mlp" => Box::new(crate::predictors::AlignedMlp::new(
            crate::predictors::AlignedMlpParams {
                horizons: opts.horizons,
                network: trajpred_neural::DistanceMlpConfig {
                    seed: opts.seed,
                    ..Default::default()
                },
                ..Default::default()
            },
        )?),
        "auto" => Box::new(Auto::new(
            AutoParams {
                seed: opts.seed,
                eval: opts.eval,
                ..Default::default()
            },
            opts.clone(),
        )?),
        "blend" => Box::new(Blend::new(
            BlendParams {
                seed: opts.seed,
                eval: opts.eval,
                ..Default::default()
            },
            opts.clone(),
        )?),
        _ => {
            return Err(Error::InvalidParameter {
                name: "method",
                reason: format!(
                    "unknown method `{name}`; known: {}",
                    all_methods()
                        .iter()
                        .map(|m| m.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
    })
}
