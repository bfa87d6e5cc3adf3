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
}

impl Default for MethodOptions {
    fn default() -> Self {
        MethodOptions {
            kf_q: 10.0,
            poly_points: 5,
            seed: 0,
            window: 6,
            horizons: 6,
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
        description: "KF-dynamic paper: predictor form of the Kalman filter (eq. 13-15), CV model",
    },
    MethodInfo {
        name: "kf-dynamic-4d",
        description: "KF dynamic with the 4-D position + velocity observation (R = I)",
    },
    MethodInfo {
        name: "naive-kf",
        description: "Kalman filter through the history, then uncorrected CV extrapolation",
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
        description: "GSKF paper: GSC corrected by the improved one-step-ahead Kalman filter",
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
];

/// Builds the predictor called `name` (see [`METHODS`]); an unknown name is an
/// [`Error::InvalidParameter`] listing the known ones.
pub fn build(name: &str, opts: &MethodOptions) -> Result<Box<dyn Predictor>> {
    Ok(match name {
        "kf-dynamic" => Box::new(KfDynamic::new(KfDynamicParams::paper_position(opts.kf_q))?),
        "kf-dynamic-4d" => Box::new(KfDynamic::new(KfDynamicParams::paper_position_velocity(
            opts.kf_q,
        ))?),
        "naive-kf" => Box::new(NaiveKf::new(KfDynamicParams::paper_position(opts.kf_q))?),
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
            ..Default::default()
        })?),
        _ => {
            return Err(Error::InvalidParameter {
                name: "method",
                reason: format!(
                    "unknown method `{name}`; known: {}",
                    METHODS
                        .iter()
                        .map(|m| m.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
    })
}
