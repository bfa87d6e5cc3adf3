//! Tables, figures and claims: what a paper's runner returns, how a run is written (every file
//! atomically, [`write_atomic`]), compared with the committed one ([`compare_run`], `--check`)
//! and copied over it ([`replace_run`], `--bless`).
//!
//! Every number in a [`Table`] comes from a run, except the cells of [`ColumnKind::Paper`]
//! columns, which hold the figure the paper itself reports (from `docs/papers.md`), so that ours
//! can be read beside it.

use crate::error::{ReproError, Result, io_err};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use trajpred::plot::{Chart, write_chart};

/// One cell of a table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Value {
    /// A label (method name, dataset, parameter).
    Text(String),
    /// A number.
    Num(f64),
    /// No value (the paper reports none, or the experiment could not give one).
    Missing,
}

impl From<f64> for Value {
    fn from(v: f64) -> Self {
        Value::Num(v)
    }
}

impl From<&str> for Value {
    fn from(v: &str) -> Self {
        Value::Text(v.to_string())
    }
}

impl From<String> for Value {
    fn from(v: String) -> Self {
        Value::Text(v)
    }
}

impl From<usize> for Value {
    fn from(v: usize) -> Self {
        Value::Num(v as f64)
    }
}

impl From<Option<f64>> for Value {
    fn from(v: Option<f64>) -> Self {
        v.map_or(Value::Missing, Value::Num)
    }
}

/// What a column holds, which decides how `--check` compares it with the committed run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum ColumnKind {
    /// A label: must be equal.
    Label,
    /// A number of ours: equal within `abs + rel * |committed|`.
    Ours {
        /// Absolute tolerance.
        abs: f64,
        /// Relative tolerance.
        rel: f64,
    },
    /// The paper's reported figure: must be equal.
    Paper,
    /// Wall time or anything else that depends on the machine: not compared.
    Timing,
}

/// A column: its header, kind and how many decimals the Markdown shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Column {
    /// Header.
    pub name: String,
    /// What the column holds.
    pub kind: ColumnKind,
    /// Decimals shown in Markdown (CSV keeps full precision). Values smaller than the last
    /// shown decimal are printed in scientific notation instead of as zero.
    pub decimals: usize,
}

/// A table of a paper, reproduced.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Table {
    /// File stem, unique within the paper, e.g. `table1`.
    pub id: String,
    /// Title, e.g. "Table 1: RMSE (1e-3 m) against window length m, T = 1".
    pub title: String,
    /// The columns.
    pub columns: Vec<Column>,
    /// The rows; each has one value per column.
    pub rows: Vec<Vec<Value>>,
    /// Notes printed under the table (setup, units, why a number differs).
    pub notes: Vec<String>,
}

impl Table {
    /// An empty table.
    pub fn new(id: impl Into<String>, title: impl Into<String>) -> Self {
        Self {
            id: id.into(),
            title: title.into(),
            columns: Vec::new(),
            rows: Vec::new(),
            notes: Vec::new(),
        }
    }

    fn column(mut self, name: &str, kind: ColumnKind, decimals: usize) -> Self {
        self.columns.push(Column {
            name: name.to_string(),
            kind,
            decimals,
        });
        self
    }

    /// Adds a label column.
    pub fn label(self, name: &str) -> Self {
        self.column(name, ColumnKind::Label, 0)
    }

    /// Adds a column of our numbers, compared by `--check` within `abs + rel * |committed|`.
    pub fn ours(self, name: &str, decimals: usize, abs: f64, rel: f64) -> Self {
        self.column(name, ColumnKind::Ours { abs, rel }, decimals)
    }

    /// Adds a column of the paper's reported figures.
    pub fn paper(self, name: &str, decimals: usize) -> Self {
        self.column(name, ColumnKind::Paper, decimals)
    }

    /// Adds a wall-time column (seconds), not compared by `--check`.
    pub fn timing(self, name: &str, decimals: usize) -> Self {
        self.column(name, ColumnKind::Timing, decimals)
    }

    /// Appends a row; it must have one value per column.
    pub fn push(&mut self, row: Vec<Value>) -> Result<()> {
        if row.len() != self.columns.len() {
            return Err(ReproError::Experiment {
                experiment: self.id.clone(),
                reason: format!(
                    "row has {} values, the table has {} columns",
                    row.len(),
                    self.columns.len()
                ),
            });
        }
        self.rows.push(row);
        Ok(())
    }

    /// Adds a note printed under the table.
    pub fn note(&mut self, note: impl Into<String>) {
        self.notes.push(note.into());
    }

    /// The value in row `row` of the column named `column`, if both exist.
    pub fn get(&self, row: usize, column: &str) -> Option<&Value> {
        let c = self.columns.iter().position(|c| c.name == column)?;
        self.rows.get(row)?.get(c)
    }

    /// The table as GitHub Markdown (title, table, notes).
    pub fn to_markdown(&self) -> String {
        let mut s = format!("### {}\n\n", self.title);
        let header: Vec<&str> = self.columns.iter().map(|c| c.name.as_str()).collect();
        let _ = writeln!(s, "| {} |", header.join(" | "));
        let align: Vec<&str> = self
            .columns
            .iter()
            .map(|c| match c.kind {
                ColumnKind::Label => "---",
                _ => "---:",
            })
            .collect();
        let _ = writeln!(s, "|{}|", align.join("|"));
        for row in &self.rows {
            let cells: Vec<String> = row
                .iter()
                .zip(&self.columns)
                .map(|(v, c)| format_cell(v, c.decimals))
                .collect();
            let _ = writeln!(s, "| {} |", cells.join(" | "));
        }
        if !self.notes.is_empty() {
            s.push('\n');
            for n in &self.notes {
                let _ = writeln!(s, "- {n}");
            }
        }
        s
    }

    /// The table as CSV text (full precision; missing values are empty).
    pub fn to_csv(&self) -> Result<String> {
        let mut w = csv::Writer::from_writer(Vec::new());
        let csv_err = |e: csv::Error| ReproError::Csv {
            path: PathBuf::from(format!("{}.csv", self.id)),
            reason: e.to_string(),
        };
        w.write_record(self.columns.iter().map(|c| c.name.as_str()))
            .map_err(csv_err)?;
        for row in &self.rows {
            w.write_record(row.iter().map(|v| match v {
                Value::Text(t) => t.clone(),
                Value::Num(x) => format!("{x:?}"),
                Value::Missing => String::new(),
            }))
            .map_err(csv_err)?;
        }
        let bytes = w.into_inner().map_err(|e| ReproError::Csv {
            path: PathBuf::from(format!("{}.csv", self.id)),
            reason: e.to_string(),
        })?;
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }
}

/// Formats a number with `decimals` decimals, or in scientific notation when it would
/// otherwise print as zero or is very large.
pub fn format_number(x: f64, decimals: usize) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    let small = 0.5 * 10f64.powi(-(decimals as i32));
    if x != 0.0 && (x.abs() < small || x.abs() >= 1e7) {
        format!("{x:.2e}")
    } else {
        format!("{x:.decimals$}")
    }
}

fn format_cell(v: &Value, decimals: usize) -> String {
    match v {
        Value::Text(t) => t.replace('|', "\\|"),
        Value::Num(x) => format_number(*x, decimals),
        Value::Missing => "—".to_string(),
    }
}

/// A figure: one chart, written as `<id>.svg` and `<id>.png`.
#[derive(Debug, Clone)]
pub struct Figure {
    /// File stem, unique within the paper, e.g. `fig4_snr`.
    pub id: String,
    /// What the figure shows (the caption in the Markdown).
    pub caption: String,
    /// The chart.
    pub chart: Chart,
}

/// A claim of the paper and whether our run supports it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Claim {
    /// The claim, in words, e.g. "MSTPM-GSKF has the lowest 3-D RMSE of the four methods".
    pub statement: String,
    /// Whether it holds in this run (computed from the run, not typed in).
    pub holds: bool,
    /// The numbers of this run that decide it.
    pub evidence: String,
}

/// Everything one paper's runner produced.
#[derive(Debug, Clone)]
pub struct PaperResult {
    /// The tables.
    pub tables: Vec<Table>,
    /// The figures.
    pub figures: Vec<Figure>,
    /// The paper's claims, checked against this run.
    pub claims: Vec<Claim>,
    /// Why our numbers differ from the paper's, and what was decided where the paper is silent.
    pub notes: Vec<String>,
    /// The data each experiment read (file paths, record counts) or generated.
    pub data: Vec<String>,
    /// Experiments that could not run because real data was missing, with what to download
    /// and where to put it.
    pub missing: Vec<String>,
}

impl PaperResult {
    /// An empty result.
    pub fn new() -> Self {
        Self {
            tables: Vec::new(),
            figures: Vec::new(),
            claims: Vec::new(),
            notes: Vec::new(),
            data: Vec::new(),
            missing: Vec::new(),
        }
    }

    /// Records a claim, deciding it by `holds`.
    pub fn claim(
        &mut self,
        statement: impl Into<String>,
        holds: bool,
        evidence: impl Into<String>,
    ) {
        self.claims.push(Claim {
            statement: statement.into(),
            holds,
            evidence: evidence.into(),
        });
    }
}

impl Default for PaperResult {
    fn default() -> Self {
        Self::new()
    }
}

/// How a run was made, written beside its results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// Paper slug (`gskf`, `kf-dynamic`, `mkpf`, `kfu-lstm`).
    pub paper: String,
    /// Paper title.
    pub title: String,
    /// Base seed of the run.
    pub seed: u64,
    /// Git revision of the code that ran.
    pub revision: String,
    /// Reduced (`--quick`) run.
    pub quick: bool,
    /// Wall time of the paper's run, seconds.
    pub wall_seconds: f64,
    /// Data sources.
    pub data: Vec<String>,
    /// Experiments skipped for missing data.
    pub missing: Vec<String>,
    /// Claims checked.
    pub claims: Vec<Claim>,
    /// Explanatory notes.
    pub notes: Vec<String>,
    /// Table ids and titles.
    pub tables: Vec<(String, String)>,
    /// Figure ids and captions.
    pub figures: Vec<(String, String)>,
}

static TEMP_SERIAL: AtomicU64 = AtomicU64::new(0);

/// The temporary file beside `path` that [`write_atomic_with`] writes first: hidden, in the same
/// folder (so the final rename stays on one file system), unique to this process and call, and
/// ending in the destination's extension (the plot writer chooses the format from it), e.g.
/// `.fig1.svg.tmp-4242-7.svg`. `.gitignore` ignores the pattern `.*.tmp-*`.
fn temp_path(path: &Path) -> Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| ReproError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file path"),
    })?;
    let ext = path
        .extension()
        .map_or_else(|| "tmp".into(), |e| e.to_string_lossy());
    let serial = TEMP_SERIAL.fetch_add(1, Ordering::Relaxed);
    Ok(path.with_file_name(format!(
        ".{}.tmp-{}-{serial}.{ext}",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Writes `path` atomically: `write` is handed a temporary path in the same folder and must
/// write the whole file there; the temporary file is then flushed to disk and renamed over
/// `path`. Readers (and a later run) see either the old file or the new one, never a partial
/// one. When `write`, the flush or the rename fails, the temporary file is removed, `path` keeps
/// its old content and the error is returned.
pub fn write_atomic_with<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&Path) -> Result<()>,
{
    let tmp = temp_path(path)?;
    let outcome = write(&tmp)
        .and_then(|()| {
            std::fs::OpenOptions::new()
                .write(true)
                .open(&tmp)
                .and_then(|f| f.sync_all())
                .map_err(io_err(&tmp))
        })
        .and_then(|()| std::fs::rename(&tmp, path).map_err(io_err(path)));
    if outcome.is_err() {
        // best effort: the temporary file may not exist if `write` failed before creating it
        let _ = std::fs::remove_file(&tmp);
    }
    outcome
}

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |tmp| std::fs::write(tmp, bytes).map_err(io_err(tmp)))
}

impl RunInfo {
    /// The names of the files [`write_paper`] writes for this run, in the paper's folder:
    /// `README.md`, `run.json`, `<table>.md` and `<table>.csv` per table, `<figure>.svg` and
    /// `<figure>.png` per figure.
    pub fn files(&self) -> Vec<String> {
        let mut files = vec!["README.md".to_string(), "run.json".to_string()];
        for (id, _) in &self.tables {
            files.push(format!("{id}.md"));
            files.push(format!("{id}.csv"));
        }
        for (id, _) in &self.figures {
            files.push(format!("{id}.svg"));
            files.push(format!("{id}.png"));
        }
        files
    }
}

/// Removes every regular file of `dir` whose name is not in `keep` (files of an earlier run, or
/// temporary files a killed run left behind), so that the folder holds exactly one run.
fn prune(dir: &Path, keep: &[String]) -> Result<()> {
    for entry in std::fs::read_dir(dir).map_err(io_err(dir))? {
        let entry = entry.map_err(io_err(dir))?;
        let path = entry.path();
        let is_file = entry.file_type().map_err(io_err(&path))?.is_file();
        let kept = keep
            .iter()
            .any(|k| entry.file_name().to_str() == Some(k.as_str()));
        if is_file && !kept {
            std::fs::remove_file(&path).map_err(io_err(&path))?;
        }
    }
    Ok(())
}

fn json_err(path: &Path) -> impl FnOnce(serde_json::Error) -> ReproError + '_ {
    move |e| ReproError::Csv {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

/// Reads the [`RunInfo`] of the run written in `dir` (its `run.json`).
pub fn read_run_info(dir: &Path) -> Result<RunInfo> {
    let path = dir.join("run.json");
    let text = std::fs::read_to_string(&path).map_err(io_err(&path))?;
    serde_json::from_str(&text).map_err(json_err(&path))
}

/// Replaces the run in `dest` with the run written in `fresh` (both a paper's folder): copies
/// every file the fresh run wrote (as listed by its `run.json`), each atomically, then removes
/// the files of `dest` the fresh run did not write. This is `--bless`.
pub fn replace_run(fresh: &Path, dest: &Path) -> Result<()> {
    let info = read_run_info(fresh)?;
    let files = info.files();
    std::fs::create_dir_all(dest).map_err(io_err(dest))?;
    for name in &files {
        let from = fresh.join(name);
        let bytes = std::fs::read(&from).map_err(io_err(&from))?;
        write_atomic(&dest.join(name), &bytes)?;
    }
    prune(dest, &files)
}

/// Writes one paper's results into `dir` (created if needed): `README.md` with every table,
/// figure, claim and note; `<table>.md` and `<table>.csv` per table; `<figure>.svg` and
/// `<figure>.png` per figure; `run.json` with the [`RunInfo`] (the list is
/// [`RunInfo::files`]). Every file is written atomically ([`write_atomic`]); files of `dir`
/// that this run did not write (an earlier run's) are removed afterwards.
pub fn write_paper(result: &PaperResult, info: &RunInfo, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    let mut md = format!("# {}\n\n", info.title);
    let _ = writeln!(
        md,
        "Generated by `cargo xtask reproduce --paper {}{}` at revision `{}`, seed {}, in {:.1} s. \
         Every number in the tables comes from that run, except the columns headed \"paper\", \
         which are the figures the paper reports.\n",
        info.paper,
        if info.quick { " --quick" } else { "" },
        info.revision,
        info.seed,
        info.wall_seconds
    );
    if !result.data.is_empty() {
        md.push_str("Data:\n\n");
        for d in &result.data {
            let _ = writeln!(md, "- {d}");
        }
        md.push('\n');
    }
    if !result.missing.is_empty() {
        md.push_str("Not run (data missing):\n\n");
        for d in &result.missing {
            let _ = writeln!(md, "- {d}");
        }
        md.push('\n');
    }
    if !result.claims.is_empty() {
        md.push_str(
            "## The paper's claims in this run\n\n| claim | holds | evidence |\n|---|---|---|\n",
        );
        for c in &result.claims {
            let _ = writeln!(
                md,
                "| {} | {} | {} |",
                c.statement,
                if c.holds { "yes" } else { "no" },
                c.evidence
            );
        }
        md.push('\n');
    }
    if !result.notes.is_empty() {
        md.push_str("## Why our numbers differ, and what we decided\n\n");
        for n in &result.notes {
            let _ = writeln!(md, "- {n}");
        }
        md.push('\n');
    }
    md.push_str("## Tables\n\n");
    for t in &result.tables {
        let table_md = t.to_markdown();
        write_atomic(&dir.join(format!("{}.md", t.id)), table_md.as_bytes())?;
        write_atomic(&dir.join(format!("{}.csv", t.id)), t.to_csv()?.as_bytes())?;
        md.push_str(&table_md);
        let _ = writeln!(md, "\n([CSV]({}.csv))\n", t.id);
    }
    if !result.figures.is_empty() {
        md.push_str("## Figures\n\n");
    }
    for f in &result.figures {
        for ext in ["svg", "png"] {
            write_atomic_with(&dir.join(format!("{}.{ext}", f.id)), |tmp| {
                Ok(write_chart(&f.chart, tmp)?)
            })?;
        }
        let _ = writeln!(
            md,
            "![{}]({}.svg)\n\n{} ([PNG]({}.png))\n",
            f.caption, f.id, f.caption, f.id
        );
    }
    write_atomic(&dir.join("README.md"), md.as_bytes())?;
    let json_path = dir.join("run.json");
    let json = serde_json::to_string_pretty(info).map_err(json_err(&json_path))?;
    write_atomic(&json_path, json.as_bytes())?;
    prune(dir, &info.files())
}

/// Rewrites `<root>/README.md`, the index over every paper's `run.json` found under `root`.
pub fn write_index(root: &Path, explanations: &[(&str, &str)]) -> Result<()> {
    let mut md = String::from(
        "# Reproduced results\n\n\
         Written by `cargo xtask reproduce` (see the top-level README; the copy under \
         `docs/results/` changes only with `--bless`). Each paper's folder \
         holds its tables (Markdown and CSV), figures (SVG and PNG) and a README with the run's \
         seed, revision, data and wall time. Claims are decided from the run's own numbers.\n\n",
    );
    for (slug, why) in explanations {
        let path = root.join(slug).join("run.json");
        let Ok(text) = std::fs::read_to_string(&path) else {
            let _ = writeln!(
                md,
                "## {slug}\n\nNot run yet: `cargo xtask reproduce --paper {slug}`.\n"
            );
            continue;
        };
        let info: RunInfo = serde_json::from_str(&text).map_err(json_err(&path))?;
        let _ = writeln!(
            md,
            "## [{}]({slug}/README.md)\n\nRevision `{}`, seed {}, {:.1} s{}.\n",
            info.title,
            info.revision,
            info.seed,
            info.wall_seconds,
            if info.quick { ", quick run" } else { "" }
        );
        for (id, title) in &info.tables {
            let _ = writeln!(md, "- [{title}]({slug}/{id}.md)");
        }
        for (id, caption) in &info.figures {
            let _ = writeln!(md, "- [{caption}]({slug}/{id}.svg)");
        }
        md.push('\n');
        if !info.claims.is_empty() {
            md.push_str("| claim | holds in our run | evidence |\n|---|---|---|\n");
            for c in &info.claims {
                let _ = writeln!(
                    md,
                    "| {} | {} | {} |",
                    c.statement,
                    if c.holds { "yes" } else { "no" },
                    c.evidence
                );
            }
            md.push('\n');
        }
        for m in &info.missing {
            let _ = writeln!(md, "- Not run: {m}");
        }
        let _ = writeln!(md, "{why}\n");
    }
    write_atomic(&root.join("README.md"), md.as_bytes())
}

mod check;
pub use check::{Difference, check_run, compare_run, compare_with_committed};
