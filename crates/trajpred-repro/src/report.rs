//! Tables, figures and claims: what a paper's runner returns, and how it is written under
//! `docs/results/`.
//!
//! Every number in a [`Table`] comes from a run, except the cells of [`ColumnKind::Paper`]
//! columns, which hold the figure the paper itself reports (from SPEC), so that ours can be
//! read beside it.

use crate::error::{ReproError, Result, io_err};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
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

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(io_err(path))
}

/// Writes one paper's results into `dir` (created if needed): `README.md` with every table,
/// figure, claim and note; `<table>.md` and `<table>.csv` per table; `<figure>.svg` and
/// `<figure>.png` per figure; `run.json` with the [`RunInfo`].
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
        write(&dir.join(format!("{}.md", t.id)), &table_md)?;
        write(&dir.join(format!("{}.csv", t.id)), &t.to_csv()?)?;
        md.push_str(&table_md);
        let _ = writeln!(md, "\n([CSV]({}.csv))\n", t.id);
    }
    if !result.figures.is_empty() {
        md.push_str("## Figures\n\n");
    }
    for f in &result.figures {
        for ext in ["svg", "png"] {
            write_chart(&f.chart, &dir.join(format!("{}.{ext}", f.id)))?;
        }
        let _ = writeln!(
            md,
            "![{}]({}.svg)\n\n{} ([PNG]({}.png))\n",
            f.caption, f.id, f.caption, f.id
        );
    }
    write(&dir.join("README.md"), &md)?;
    let json = serde_json::to_string_pretty(info).map_err(|e| ReproError::Csv {
        path: dir.join("run.json"),
        reason: e.to_string(),
    })?;
    write(&dir.join("run.json"), &json)
}

/// Rewrites `<root>/README.md`, the index over every paper's `run.json` found under `root`.
pub fn write_index(root: &Path, explanations: &[(&str, &str)]) -> Result<()> {
    let mut md = String::from(
        "# Reproduced results\n\n\
         Regenerated by `cargo xtask reproduce` (see the top-level README). Each paper's folder \
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
        let info: RunInfo = serde_json::from_str(&text).map_err(|e| ReproError::Csv {
            path: path.clone(),
            reason: e.to_string(),
        })?;
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
    write(&root.join("README.md"), &md)
}

/// Compares the tables of a fresh run with the CSVs committed under `dir`. Returns the list of
/// differences (empty when everything agrees within each column's tolerance).
pub fn compare_with_committed(tables: &[Table], dir: &Path) -> Result<Vec<String>> {
    let mut diffs = Vec::new();
    for t in tables {
        let path = dir.join(format!("{}.csv", t.id));
        let text = match std::fs::read_to_string(&path) {
            Ok(s) => s,
            Err(_) => {
                diffs.push(format!("{}: no committed file", path.display()));
                continue;
            }
        };
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let header: Vec<String> = r
            .headers()
            .map_err(|e| ReproError::Csv {
                path: path.clone(),
                reason: e.to_string(),
            })?
            .iter()
            .map(str::to_string)
            .collect();
        let names: Vec<&str> = t.columns.iter().map(|c| c.name.as_str()).collect();
        if header != names {
            diffs.push(format!(
                "{}: columns {:?}, fresh run has {:?}",
                path.display(),
                header,
                names
            ));
            continue;
        }
        let mut committed_rows = 0;
        for (i, rec) in r.records().enumerate() {
            committed_rows += 1;
            let rec = rec.map_err(|e| ReproError::Csv {
                path: path.clone(),
                reason: e.to_string(),
            })?;
            let Some(row) = t.rows.get(i) else { continue };
            for ((cell, value), col) in rec.iter().zip(row).zip(&t.columns) {
                if let Some(d) = compare_cell(cell, value, col) {
                    diffs.push(format!(
                        "{} row {} column \"{}\": {d}",
                        path.display(),
                        i + 1,
                        col.name
                    ));
                }
            }
        }
        if committed_rows != t.rows.len() {
            diffs.push(format!(
                "{}: {} committed rows, fresh run has {}",
                path.display(),
                committed_rows,
                t.rows.len()
            ));
        }
    }
    Ok(diffs)
}

fn compare_cell(committed: &str, fresh: &Value, col: &Column) -> Option<String> {
    let fresh_text = match fresh {
        Value::Text(t) => t.clone(),
        Value::Num(x) => format!("{x:?}"),
        Value::Missing => String::new(),
    };
    match col.kind {
        ColumnKind::Timing => None,
        ColumnKind::Label | ColumnKind::Paper => {
            let same = match (committed.parse::<f64>(), fresh) {
                (Ok(a), Value::Num(b)) => a == *b,
                _ => committed == fresh_text,
            };
            (!same).then(|| format!("committed {committed:?}, fresh {fresh_text:?}"))
        }
        ColumnKind::Ours { abs, rel } => match (committed.parse::<f64>(), fresh) {
            (Ok(a), Value::Num(b)) => {
                let ok = (a - b).abs() <= abs + rel * a.abs() || (a.is_nan() && b.is_nan());
                (!ok).then(|| {
                    format!("committed {a}, fresh {b} (tolerance {abs} + {rel} x |committed|)")
                })
            }
            _ if committed.is_empty() && *fresh == Value::Missing => None,
            _ => Some(format!("committed {committed:?}, fresh {fresh_text:?}")),
        },
    }
}
