//! Dynamic trajectory prediction with a Kalman filter (Qiao et al., Acta Electronica Sinica
//! 46(2), 2018; `docs/papers.md` B.4).
//!
//! On GeoLife and on T-Drive (each read from [`Context::data`]; when one is absent its
//! experiments are listed in [`PaperResult::missing`] and the rest still runs):
//!
//! - methods: KF dynamic and naive KF with both parameter sets of the paper's Table 1, the HMM
//!   (fitted on a seeded training part disjoint from the test trajectories), and the N-point
//!   linear and quadratic fits (N = 5);
//! - the mean Euclidean error (the paper's "RMSE", def. 3) and the accuracy (share of
//!   predictions closer than 25 m) against the history length 10..50 and the step 1..5;
//! - the run time against the number of test trajectories (seeded random test sets of
//!   increasing size, up to what the subset holds);
//! - the paper's four reported figures beside ours, and its claims decided from the run.
//!
//! Every history length forecasts from the same origins (the test trajectories are trimmed so
//! that the first origin is the 50th point for every history), so the rows of a table differ
//! only by the method or the history. See `docs/kf-dynamic.md`. The tables' layout, the paper's
//! figures and its claims are in `papers/kf-dynamic.toml`; this module computes the numbers.

use crate::report::PaperResult;
use crate::runner::{Computed, assemble};
use crate::spec::Spec;
use crate::{Context, Paper, ReproError, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use trajpred::dataset::{self, Segment, Segmentation};
use trajpred::protocol::{self, Protocol};
use trajpred_data::LoadReport;

mod figures;
mod grid;
mod rows;

use grid::{Grid, run_grid};

/// The protocol parameters of the spec (`[params]`); the presets must agree with them.
#[derive(Debug, Clone, Deserialize)]
pub(crate) struct Params {
    /// History lengths of the paper's Table 1.
    histories: Vec<usize>,
    /// Forecast steps 1..=horizon.
    horizon: usize,
    /// The paper's limit on the sampling interval, seconds.
    paper_max_interval_s: f64,
    /// Points the shortest history needs (for the count at the paper's limit).
    min_points_shortest: usize,
    /// History length of the run-time experiment.
    timing_history: usize,
    /// Increasing test-set sizes of the run-time experiment.
    timing_sizes: usize,
}

/// What the run adds to the protocol presets (`[budget]`).
#[derive(Debug, Clone, Deserialize)]
struct Budget {
    /// Origins per test trajectory in the run-time experiment.
    timing_origins: usize,
}

/// One of the two datasets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ds {
    Geolife,
    Tdrive,
}

impl Ds {
    /// The dataset's key in the spec (and its folder).
    fn key(self) -> &'static str {
        match self {
            Ds::Geolife => "geolife",
            Ds::Tdrive => "tdrive",
        }
    }
    fn label(self) -> &'static str {
        match self {
            Ds::Geolife => "GeoLife",
            Ds::Tdrive => "T-Drive",
        }
    }
    /// The number of the paper's figure `k` (1..3) for this dataset.
    fn fig(self, k: usize) -> usize {
        match self {
            Ds::Geolife => k,
            Ds::Tdrive => k + 3,
        }
    }
    /// The protocol preset this dataset runs (segmentation, split, histories, methods),
    /// checked against the spec's parameters and methods.
    fn protocol(self, ctx: &Context, spec: &Spec, params: &Params) -> Result<Protocol> {
        let name = match self {
            Ds::Geolife => "kf-dynamic-geolife",
            Ds::Tdrive => "kf-dynamic-tdrive",
        };
        let p = protocol::preset(name, ctx.seed, ctx.quick).map_err(experiment_err("protocol"))?;
        let same_methods =
            spec.methods.len() == p.methods.len()
                && spec.methods.iter().zip(&p.methods).all(|(s, m)| {
                    s.registry.as_deref() == Some(m.name.as_str()) && s.label == m.label
                });
        if !same_methods || p.histories != params.histories || p.horizon != params.horizon {
            return Err(ReproError::Spec {
                paper: spec.slug.clone(),
                reason: format!(
                    "the preset {name} does not run the spec's methods, histories and horizon"
                ),
            });
        }
        Ok(p)
    }
}

fn experiment_err(experiment: &str) -> impl Fn(trajpred::Error) -> ReproError + '_ {
    move |e| ReproError::Experiment {
        experiment: format!("kf-dynamic/{experiment}"),
        reason: e.to_string(),
    }
}

/// The trajectories of one dataset, as the experiments use them.
struct Loaded {
    /// Segments with at least the protocol's points after the gap split.
    segments: Vec<Segment>,
    /// Loader's report over every file read.
    report: LoadReport,
    /// Folder read.
    folder: PathBuf,
    /// User folders (GeoLife) or taxi files (T-Drive) read, and how many there were.
    units_read: usize,
    units_total: usize,
    /// Trajectories the loader returned.
    loaded: usize,
    /// Segments after the split at the protocol's limit (any length).
    segments_all: usize,
    /// Segments long enough for the shortest history at the paper's 5 s limit.
    paper_limit_usable: usize,
    /// Points in [`Self::segments`].
    points: usize,
    /// The protocol's gap limit, seconds, and the points a segment needs.
    max_gap: f64,
    min_points: usize,
}

fn load(p: &Protocol, params: &Params, dir: &Path) -> Result<Loaded> {
    let e = experiment_err("load");
    let t = dataset::load_tracks(p.dataset, dir, &p.load_options, p.max_units).map_err(&e)?;
    let paper_limit = Segmentation {
        max_gap: Some(params.paper_max_interval_s),
        min_points: params.min_points_shortest,
        ..Segmentation::default()
    };
    let (usable, _) = paper_limit.apply(&t.tracks).map_err(&e)?;
    let (segments, counts) = p.segmentation.apply(&t.tracks).map_err(&e)?;
    Ok(Loaded {
        segments,
        report: t.report,
        folder: dir.to_path_buf(),
        units_read: t.units_read,
        units_total: t.units_total,
        loaded: t.tracks.len(),
        segments_all: counts.segments_all,
        paper_limit_usable: usable.len(),
        points: counts.points,
        max_gap: p.segmentation.max_gap.unwrap_or(f64::INFINITY),
        min_points: p.segmentation.min_points,
    })
}

fn data_lines(ds: Ds, p: &Params, d: &Loaded) -> Vec<String> {
    let r = &d.report;
    let skipped: Vec<String> = r
        .skipped_by_reason()
        .filter(|(_, n)| *n > 0)
        .map(|(reason, n)| format!("{reason}: {n}"))
        .collect();
    vec![
        format!(
            "{}: read {} of {} {} in {}; {} files, {} records, {} points kept, {} skipped ({}); \
             {} trajectories loaded.",
            ds.label(),
            d.units_read,
            d.units_total,
            if ds == Ds::Geolife {
                "user folders"
            } else {
                "taxi files"
            },
            d.folder.display(),
            r.files_read,
            r.records_read,
            r.points_kept,
            r.skipped_total(),
            if skipped.is_empty() {
                "none".to_string()
            } else {
                skipped.join(", ")
            },
            d.loaded
        ),
        format!(
            "{}: split where the sampling interval exceeds {} s: {} segments, {} with at least \
             {} points ({} points) used; at the paper's {} s limit, {} segments \
             would have at least {} points.",
            ds.label(),
            d.max_gap,
            d.segments_all,
            d.segments.len(),
            d.min_points,
            d.points,
            p.paper_max_interval_s,
            d.paper_limit_usable,
            p.min_points_shortest
        ),
    ]
}

/// The template variables of a dataset's protocol (its notes and setup lines).
fn protocol_vars(ds: Ds, p: &Protocol, out: &mut Computed) {
    let d = ds.key();
    // (the presets always split; `none` would say 0)
    let fraction = p.split.train_fraction().unwrap_or(0.0);
    out.var(&format!("{d}.protocol"), p.name.as_str());
    out.var(&format!("{d}.max_units"), p.max_units.unwrap_or(0));
    out.var(&format!("{d}.max_test"), p.max_test.unwrap_or(0));
    out.var(&format!("{d}.max_train"), p.max_train.unwrap_or(0));
    out.var(&format!("{d}.max_origins"), p.max_origins.unwrap_or(0));
    out.var(&format!("{d}.stride"), p.stride);
    out.var(&format!("{d}.split"), p.split.label());
    out.var(&format!("{d}.train_fraction"), fraction);
    out.var(
        &format!("{d}.max_gap"),
        p.segmentation.max_gap.unwrap_or(f64::INFINITY),
    );
}

/// Runs the paper's experiments (see the module documentation) and builds its report.
pub fn run(ctx: &Context) -> Result<PaperResult> {
    let spec = Paper::KfDynamic.spec()?;
    let params: Params = spec.params()?;
    let budget: Budget = spec.budget_as(ctx.quick)?;
    let mut out = Computed::default();
    let mut grids: Vec<(Ds, Grid)> = Vec::new();
    let mut hmm_notes = Vec::new();
    for ds in [Ds::Geolife, Ds::Tdrive] {
        let p = ds.protocol(ctx, spec, &params)?;
        protocol_vars(ds, &p, &mut out);
        if ds == Ds::Geolife {
            out.var("min_points", p.segmentation.min_points);
            out.var(
                "max_history",
                p.histories.iter().copied().max().unwrap_or(0),
            );
        }
        let Some(dir) = out.locate(spec, ctx, ds.key())? else {
            continue;
        };
        let t0 = std::time::Instant::now();
        let data = load(&p, &params, &dir)?;
        let load_s = t0.elapsed().as_secs_f64();
        out.data.extend(data_lines(ds, &params, &data));
        out.data.push(format!(
            "{}: reading and splitting took {load_s:.1} s of wall time.",
            ds.label()
        ));
        let hmm = rows::index(spec, "hmm");
        let grid = run_grid(ds, &p, &params, &data, ctx, budget.timing_origins, hmm)?;
        let d = ds.key();
        out.var(&format!("{d}.tests"), grid.run.test.len());
        out.var(&format!("{d}.trains"), grid.run.train.len());
        rows::dataset_rows(spec, ds, &params, &grid, &mut out)?;
        out.figures
            .extend(figures::figures(spec, ds, &params, &grid));
        if let Some(k) = &grid.hmm_states {
            hmm_notes.push(format!(
                "{}: the HMM chose {k} on its training part.",
                ds.label()
            ));
        }
        grids.push((ds, grid));
    }
    rows::headline(spec, &grids, &mut out);
    out.notes = hmm_notes;
    assemble(spec, ctx, out)
}
