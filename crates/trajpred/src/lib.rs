//! # trajpred
//!
//! Every method of trajpred behind one [`Predictor`], an
//! evaluation harness that runs them over many trajectories, and the `trajpred` command-line
//! tool.
//!
//! ```
//! use trajpred::predictors::{KfDynamic, KfDynamicParams, PolyFit, PolyFitParams};
//! use trajpred::harness::{evaluate, EvalConfig};
//! use trajpred_core::{Predictor, Trajectory};
//!
//! // a straight track at 3 m/s, sampled every second
//! let track = Trajectory::uniform(0.0, 1.0, vec![
//!     (0..60).map(|i| 3.0 * i as f64).collect(),
//!     (0..60).map(|i| 1.0 * i as f64).collect(),
//! ])?;
//! let methods: Vec<Box<dyn Predictor>> = vec![
//!     Box::new(KfDynamic::new(KfDynamicParams::paper_position(10.0))?),
//!     Box::new(PolyFit::new(PolyFitParams { degree: 1, points: 5 })?),
//! ];
//! let cfg = EvalConfig { history: 20, horizon: 5, ..Default::default() };
//! for m in &methods {
//!     let report = evaluate(m.as_ref(), std::slice::from_ref(&track), &cfg, None)?;
//!     assert!(report.forecasts > 0 && report.hit_rate_all > 0.9);
//! }
//! # Ok::<(), trajpred_core::Error>(())
//! ```
#![forbid(unsafe_code)]

pub mod dataset;
pub mod harness;
pub mod params;
pub mod plot;
pub mod predictors;
pub mod protocol;
pub mod registry;

pub use trajpred_core::{Error, Forecast, Predictor, Result, Trajectory};
