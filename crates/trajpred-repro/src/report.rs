//! Tables, figures and claims: what a paper's runner returns, how a run is written (every file
//! atomically, [`write_atomic`]), compared with the committed one ([`compare_run`], `--check`)
//! and copied over it ([`replace_run`], `--bless`).
//!
//! Every number in a [`Table`] comes from a run, except the cells of [`ColumnKind::Paper`]
//! columns, which hold the figure the paper itself reports (from `docs/papers.md`), so that ours
//! can be read beside it.

use crate::error::{ReproError, Result};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::PathBuf;
use trajpred::plot::Chart;

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
    /// Decided by this machine's wall times: `--check` compares that the claim is there, not
    /// its verdict, which can change with the machine's load.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub wall_time: bool,
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

    /// Records a claim, deciding it by `holds`, and returns it (to mark it
    /// [`wall_time`](Claim::wall_time)).
    pub fn claim(
        &mut self,
        statement: impl Into<String>,
        holds: bool,
        evidence: impl Into<String>,
    ) -> &mut Claim {
        self.claims.push(Claim {
            statement: statement.into(),
            holds,
            evidence: evidence.into(),
            wall_time: false,
        });
        let last = self.claims.len() - 1;
        &mut self.claims[last]
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

mod check;
mod difference;
mod write;
pub use check::{Difference, check_run, compare_run, compare_with_committed};
pub use write::{
    read_run_info, replace_run, write_atomic, write_atomic_with, write_index, write_paper,
};
