//! The runs of one dataset: the protocol's grid (every method and history), the run-time
//! experiment on test sets of increasing size, and the other two pairings of Table 1's R and Q.

use super::{Ds, Loaded, Params, experiment_err};
use crate::{Context, ReproError, Result};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use trajpred::Trajectory;
use trajpred::harness::{self, EvalConfig, MethodReport};
use trajpred::predictors::{KfDynamic, KfDynamicParams, NaiveKf};
use trajpred::protocol::{self, Protocol, ProtocolRun};

/// The grid of one dataset: per method (in the spec's order, which is the protocol's), per
/// history, the protocol's report.
pub(super) struct Grid {
    /// The protocol's run: `run.reports[m][h]`.
    pub run: ProtocolRun,
    /// Run-time experiment: per size, (test trajectories, per method report).
    pub timing: Vec<(usize, Vec<MethodReport>)>,
    /// The other two KF parameter pairings at the timing history: (row key, kf-dynamic, naive).
    pub combos: Vec<(&'static str, MethodReport, MethodReport)>,
    /// HMM fit time, seconds, and what its fit chose.
    pub hmm_fit_seconds: f64,
    pub hmm_states: Option<String>,
}

/// A progress bar that moves once per stage of the protocol run.
struct StageBar<'a>(&'a indicatif::ProgressBar);

impl protocol::Progress for StageBar<'_> {
    fn finish(&self) {
        self.0.inc(1);
    }
}

/// Runs the protocol `p` on the loaded segments, then the run-time experiment and the extra
/// parameter pairings; `hmm` is the HMM's index among the methods.
pub(super) fn run_grid(
    ds: Ds,
    p: &Protocol,
    params: &Params,
    data: &Loaded,
    ctx: &Context,
    timing_origins: usize,
    hmm: usize,
) -> Result<Grid> {
    let too_few = |reason: String| ReproError::Experiment {
        experiment: format!("kf-dynamic/{}", ds.key()),
        reason,
    };
    if data.segments.len() < 2 {
        return Err(too_few(format!(
            "{} segments of at least {} points: too few for a training and a test part",
            data.segments.len(),
            p.segmentation.min_points
        )));
    }
    let n_methods = p.methods.len();
    let n_sizes = params.timing_sizes.min(data.segments.len());
    let bar = ctx.bar(
        (n_methods * (2 + n_sizes) + 4) as u64,
        format!("kf-dynamic {}", ds.label()),
    );
    let run = protocol::run(p, &data.segments, &StageBar(&bar)).map_err(experiment_err("grid"))?;
    if run.train.is_empty() {
        return Err(too_few("no training segment".into()));
    }
    let hmm_fit_seconds = run.fit_seconds[hmm];
    let hmm_states = run.predictors[hmm].fitted_summary();
    // run time against the number of test trajectories: seeded random samples of the pool
    let seed = p.split.seed().unwrap_or(ctx.seed);
    let timing_test = p
        .test_at(&run.test, params.timing_history)
        .map_err(experiment_err("trim"))?;
    let n_sizes = params.timing_sizes.min(timing_test.len());
    let cfg = EvalConfig {
        max_origins_per_trajectory: Some(timing_origins),
        ..p.config(params.timing_history)
    };
    let mut timing = Vec::with_capacity(n_sizes);
    for k in 1..=n_sizes {
        let n = (k * timing_test.len()).div_ceil(n_sizes);
        let mut idx: Vec<usize> = (0..timing_test.len()).collect();
        idx.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(
            seed.wrapping_add(k as u64),
        ));
        let sample: Vec<Trajectory> = idx[..n].iter().map(|&i| timing_test[i].clone()).collect();
        let mut per = Vec::with_capacity(n_methods);
        for pr in &run.predictors {
            per.push(
                harness::evaluate(pr.as_ref(), &sample, &cfg, None)
                    .map_err(experiment_err("timing"))?,
            );
            bar.inc(1);
        }
        timing.push((n, per));
    }
    // the other two pairings of Table 1's R and Q; KF dynamic re-uses the last observation at
    // every step (the paper read literally), as in the protocol's rows
    let cfg = p.config(params.timing_history);
    let mut combos = Vec::new();
    for (key, kf_params) in [
        ("r10_q100", KfDynamicParams::paper_position_literal(100.0)),
        (
            "r1_q10",
            KfDynamicParams::paper_position_velocity_literal(10.0),
        ),
    ] {
        let e = experiment_err("parameter sets");
        let kd = KfDynamic::new(kf_params).map_err(&e)?;
        let nv = NaiveKf::new(kf_params).map_err(&e)?;
        let a = harness::evaluate(&kd, &timing_test, &cfg, None).map_err(&e)?;
        bar.inc(1);
        let b = harness::evaluate(&nv, &timing_test, &cfg, None).map_err(&e)?;
        bar.inc(1);
        combos.push((key, a, b));
    }
    bar.finish_and_clear();
    Ok(Grid {
        run,
        timing,
        combos,
        hmm_fit_seconds,
        hmm_states,
    })
}
