#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod error;
pub mod papers;
pub mod pool;
pub mod report;
pub mod runner;
pub mod spec;

pub use error::{ReproError, Result};
pub use report::{
    Claim, Column, ColumnKind, Difference, Figure, PaperResult, RunInfo, Table, Value,
};

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

/// The specs of the four papers (`papers/<slug>.toml`), in the order of [`Paper::ALL`].
const SPECS: [&str; 4] = [
    include_str!("../papers/gskf.toml"),
    include_str!("../papers/kf-dynamic.toml"),
    include_str!("../papers/mkpf.toml"),
    include_str!("../papers/kfu-lstm.toml"),
];

/// The parsed specs (or why one cannot be read), parsed once.
fn parsed() -> &'static [std::result::Result<spec::Spec, String>] {
    static PARSED: OnceLock<Vec<std::result::Result<spec::Spec, String>>> = OnceLock::new();
    PARSED.get_or_init(|| {
        SPECS
            .iter()
            .map(|text| spec::Spec::parse(text).map_err(|e| e.to_string()))
            .collect()
    })
}

/// One of the four papers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Paper {
    /// MSTPM-GSKF: group sparse coding + improved Kalman filter (`docs/papers.md` A).
    Gskf,
    /// Dynamic trajectory prediction with a Kalman filter (`docs/papers.md` B).
    KfDynamic,
    /// MKPF: particle filter with a UKF+EKF proposal (`docs/papers.md` C).
    Mkpf,
    /// KFU-LSTM-Net: a Kalman-filter-unfolded LSTM (`docs/papers.md` D).
    KfuLstm,
}

impl Paper {
    /// The four papers, in the order of `docs/papers.md` (A to D).
    pub const ALL: [Paper; 4] = [Paper::Gskf, Paper::KfDynamic, Paper::Mkpf, Paper::KfuLstm];

    /// The four papers, the longest full run first (kfu-lstm about 60 s, gskf 40 s,
    /// kf-dynamic 4 s, mkpf 1.5 s in the release profile): the order [`run_papers`] starts
    /// them in.
    pub const LONGEST_FIRST: [Paper; 4] =
        [Paper::KfuLstm, Paper::Gskf, Paper::KfDynamic, Paper::Mkpf];

    /// The slug used on the command line and as the results folder name.
    pub fn slug(self) -> &'static str {
        match self {
            Paper::Gskf => "gskf",
            Paper::KfDynamic => "kf-dynamic",
            Paper::Mkpf => "mkpf",
            Paper::KfuLstm => "kfu-lstm",
        }
    }

    /// The paper's spec (`papers/<slug>.toml`): its datasets, parameters, methods, tables,
    /// figures and claims.
    pub fn spec(self) -> Result<&'static spec::Spec> {
        let i = Paper::ALL.iter().position(|p| *p == self).unwrap_or(0);
        match parsed().get(i) {
            Some(Ok(s)) => Ok(s),
            Some(Err(reason)) => Err(ReproError::Spec {
                paper: self.slug().to_string(),
                reason: reason.clone(),
            }),
            None => Err(ReproError::Spec {
                paper: self.slug().to_string(),
                reason: "no spec".into(),
            }),
        }
    }

    /// The paper's title (from its spec; the slug if the spec cannot be read).
    pub fn title(self) -> &'static str {
        self.spec().map_or(self.slug(), |s| s.title.as_str())
    }

    /// Parses a slug.
    pub fn from_slug(s: &str) -> Option<Paper> {
        Paper::ALL.into_iter().find(|p| p.slug() == s)
    }

    /// Why this paper's numbers and ours can differ, for the results index (no numbers here:
    /// those come from the run; from the spec, empty if it cannot be read).
    pub fn explanation(self) -> &'static str {
        self.spec().map_or("", |s| s.explanation.as_str())
    }
}

/// How to run: reduced or full, the seed, where the real data is, whether to draw progress.
#[derive(Debug, Clone)]
pub struct Context {
    /// A reduced run (fewer seeds, epochs and trajectories) that finishes in under a minute.
    pub quick: bool,
    /// Base seed; every random choice of every experiment derives from it.
    pub seed: u64,
    /// Folder holding the real datasets (`geolife/`, `tdrive/`, `adsb-traffic/`), if any.
    pub data_dir: Option<PathBuf>,
    /// Draw progress bars on stderr.
    pub progress: bool,
}

impl Default for Context {
    fn default() -> Self {
        Self {
            quick: false,
            seed: 20260611,
            data_dir: None,
            progress: false,
        }
    }
}

impl Context {
    /// The folder of one real dataset (`geolife`, `tdrive`, `adsb-traffic`), when present.
    pub fn data(&self, name: &str) -> Option<PathBuf> {
        let dir = self.data_dir.as_ref()?.join(name);
        dir.is_dir().then_some(dir)
    }

    /// The message recorded when a dataset is missing: what to download and where to put it.
    pub fn missing(&self, name: &str, what: &str) -> String {
        let place = self
            .data_dir
            .as_deref()
            .unwrap_or(Path::new("../shared/data"))
            .join(name);
        format!(
            "{what}: the {name} data was not found at {}; download it (see SOURCE.md of that \
             folder in the project's shared data, or the dataset's public page) and put it \
             there, or pass --data DIR",
            place.display()
        )
    }

    /// A progress bar (hidden unless `progress` is set). The bars of papers run at once
    /// ([`run_papers`]) share one stderr area, one line each.
    pub fn bar(&self, len: u64, message: impl Into<String>) -> ProgressBar {
        static BARS: OnceLock<MultiProgress> = OnceLock::new();
        let bar = if self.progress {
            BARS.get_or_init(MultiProgress::new)
                .add(ProgressBar::new(len))
        } else {
            ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden())
        };
        if let Ok(style) =
            ProgressStyle::with_template("{msg:40} [{bar:30}] {pos}/{len} {elapsed_precise}")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message(message.into());
        bar
    }
}

/// Runs one paper's experiments and returns its tables, figures, claims and notes, with the
/// wall time in seconds.
pub fn run_paper(paper: Paper, ctx: &Context) -> Result<(PaperResult, f64)> {
    let start = Instant::now();
    let result = match paper {
        Paper::Gskf => papers::gskf::run(ctx),
        Paper::KfDynamic => papers::kf_dynamic::run(ctx),
        Paper::Mkpf => papers::mkpf::run(ctx),
        Paper::KfuLstm => papers::kfu_lstm::run(ctx),
    }?;
    Ok((result, start.elapsed().as_secs_f64()))
}

/// Runs several papers, up to `jobs` at once (at least one), and returns each paper's result
/// and wall time in the order of `papers`. The longest papers start first, so that two
/// workers finish about when the longest one does; a paper whose spec says `runs_alone`
/// (its claims compare wall times) runs afterwards with nothing beside it. The results are
/// those of [`run_paper`] one at a time: every experiment is seeded from `ctx.seed` alone.
pub fn run_papers(papers: &[Paper], ctx: &Context, jobs: usize) -> Vec<Result<(PaperResult, f64)>> {
    let alone = |p: Paper| p.spec().is_ok_and(|s| s.runs_alone);
    let mut order: Vec<usize> = (0..papers.len()).collect();
    order.sort_by_key(|&i| Paper::LONGEST_FIRST.iter().position(|&p| p == papers[i]));
    let (solo, shared): (Vec<usize>, Vec<usize>) =
        order.into_iter().partition(|&i| alone(papers[i]));
    let mut back: Vec<Option<Result<(PaperResult, f64)>>> = papers.iter().map(|_| None).collect();
    let results = pool::map_in_parallel(&shared, jobs, |&i| run_paper(papers[i], ctx));
    for (&i, r) in shared.iter().zip(results) {
        back[i] = Some(r);
    }
    for i in solo {
        back[i] = Some(run_paper(papers[i], ctx));
    }
    back.into_iter().flatten().collect()
}

/// The [`RunInfo`] of a finished run.
pub fn run_info(
    paper: Paper,
    ctx: &Context,
    result: &PaperResult,
    wall_seconds: f64,
    revision: &str,
) -> RunInfo {
    RunInfo {
        paper: paper.slug().to_string(),
        title: paper.title().to_string(),
        seed: ctx.seed,
        revision: revision.to_string(),
        quick: ctx.quick,
        wall_seconds,
        data: result.data.clone(),
        missing: result.missing.clone(),
        claims: result.claims.clone(),
        notes: result.notes.clone(),
        tables: result
            .tables
            .iter()
            .map(|t| (t.id.clone(), t.title.clone()))
            .collect(),
        figures: result
            .figures
            .iter()
            .map(|f| (f.id.clone(), f.caption.clone()))
            .collect(),
    }
}

/// Writes a finished run of `paper` under `root/<slug>/` (replacing an earlier run there), then
/// refreshes the index `root/README.md`.
pub fn write_run(paper: Paper, result: &PaperResult, info: &RunInfo, root: &Path) -> Result<()> {
    report::write_paper(result, info, &root.join(paper.slug()))?;
    write_index(root)
}

/// Runs `paper` and writes its results under `root/<slug>/`, then refreshes `root/README.md`.
pub fn reproduce_into(paper: Paper, ctx: &Context, root: &Path, revision: &str) -> Result<RunInfo> {
    let (result, wall) = run_paper(paper, ctx)?;
    let info = run_info(paper, ctx, &result, wall, revision);
    write_run(paper, &result, &info, root)?;
    Ok(info)
}

/// Rewrites the results index `root/README.md` from every paper's `run.json` under `root`.
pub fn write_index(root: &Path) -> Result<()> {
    let explanations: Vec<(&str, &str)> = Paper::ALL
        .iter()
        .map(|p| (p.slug(), p.explanation()))
        .collect();
    report::write_index(root, &explanations)
}

/// `--check`: compares a fresh run of `paper` with the run committed under
/// `committed_root/<slug>/` (see [`report::compare_run`] for what is compared and how) and
/// returns [`ReproError::CheckFailed`], listing every difference, unless they agree.
pub fn check_paper(paper: Paper, result: &PaperResult, committed_root: &Path) -> Result<()> {
    report::check_run(paper.slug(), result, &committed_root.join(paper.slug()))
}

/// `--bless`: replaces the run of `paper` under `committed_root/<slug>/` with the one written
/// under `fresh_root/<slug>/` (files the fresh run did not write are removed), then rewrites
/// the index `committed_root/README.md`.
pub fn bless(paper: Paper, fresh_root: &Path, committed_root: &Path) -> Result<()> {
    report::replace_run(
        &fresh_root.join(paper.slug()),
        &committed_root.join(paper.slug()),
    )?;
    write_index(committed_root)
}
