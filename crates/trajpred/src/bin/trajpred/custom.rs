//! What `evaluate` and `fit` build from the command line when no `--protocol` preset is
//! named: the methods' options, the protocol, and the loaded segments.

use super::SegmentArgs;
use crate::progress::Bars;
use anyhow::{Context, Result, bail};
use trajpred::dataset::{self, Dataset, Loaded, Segment};
use trajpred::harness::{EvalConfig, Split};
use trajpred::protocol::{self, Protocol};
use trajpred::registry::MethodOptions;

/// The options of the methods `evaluate` and `fit` build from the command line.
pub(crate) fn custom_options(kf_q: f64, seed: u64, eval: EvalConfig) -> MethodOptions {
    MethodOptions {
        kf_q,
        seed,
        horizons: MethodOptions::default().horizons.max(eval.horizon),
        // what `auto` and `aligned-ridge` score their held-out folds by
        eval,
        // `auto` and `blend` fit each candidate on each fold once between them
        held_out: Some(std::sync::Arc::new(
            trajpred::predictors::HeldOutCache::new(),
        )),
        ..Default::default()
    }
}

/// The protocol `evaluate` and `fit` build from the command line (without `--protocol`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn custom_protocol(
    ds: Dataset,
    names: &[&str],
    opts: &MethodOptions,
    segment: &SegmentArgs,
    history: usize,
    horizon: usize,
    max_units: Option<usize>,
    split: Split,
) -> Protocol {
    let segmentation = segment.segmentation(history + horizon);
    Protocol {
        max_units,
        ..protocol::custom(ds, names, opts, segmentation, split, history, horizon)
    }
}

/// Loads and segments the protocol's data (at least two segments), telling what was read;
/// with a training segmentation, also the tracks cut by it (the training side's pool,
/// [`protocol::split_with_pool`]).
pub(crate) fn load_segments(
    p: &Protocol,
    path: &std::path::Path,
    bars: &Bars,
) -> Result<(Loaded, Option<Vec<Segment>>)> {
    let spinner = bars.spinner(format!("loading {}", path.display()));
    let (loaded, pool) = dataset::load_cut_twice(
        p.dataset,
        path,
        &p.load_options,
        &p.segmentation,
        p.train_segmentation.as_ref(),
        p.max_units,
    )
    .with_context(|| format!("cannot load {}", path.display()))?;
    spinner.finish_and_clear();
    eprintln!("{}: {}", path.display(), loaded.summary());
    if let (Some(ts), Some((pool, c))) = (&p.train_segmentation, &pool) {
        eprintln!(
            "{}: cut for training where fixes are more than {} s apart: {} segments of {} \
             kept ({} points), {} shorter than the minimum",
            path.display(),
            ts.max_gap.map_or("never".to_string(), |g| g.to_string()),
            pool.len(),
            c.segments_all,
            c.points,
            c.too_short
        );
    }
    if loaded.segments.len() < 2 {
        bail!(
            "{}: need at least 2 segments of {} points, found {}",
            path.display(),
            p.segmentation.min_points,
            loaded.segments.len()
        );
    }
    Ok((loaded, pool.map(|(s, _)| s)))
}
