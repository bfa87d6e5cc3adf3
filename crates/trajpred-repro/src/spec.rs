//! A paper as data: its spec (`crates/trajpred-repro/papers/<slug>.toml`, embedded in the
//! binary) holds the paper's title and `docs/papers.md` anchor, the datasets it reads, its
//! protocol parameters and run budgets, its methods, every table (columns with their kind,
//! unit and `--check` tolerance, rows, notes), the figures the paper itself reports, and every
//! claim with the comparison and tolerance that decides it.
//!
//! A paper's compute code ([`crate::papers`]) only produces numbers ([`crate::runner::Computed`]);
//! [`crate::runner::assemble`] turns them and the spec into the report's tables and claims.
//!
//! Sections group tables and claims; a section with `instances` is repeated once per instance,
//! with `${name}` replaced by the instance's value of `name` in every string of the section
//! (ids, titles, notes, claim statements, references). Templates (`{name}`, `{table/rows/column}`,
//! with an optional `:format`) are filled at run time, see [`template`].

pub mod claim;
mod expand;
pub mod template;
mod validate;

use expand::spec_err;
pub use expand::substitute;

use crate::Result;
use claim::Cond;
use serde::Deserialize;
use std::collections::BTreeMap;

/// One paper's spec, as written in its TOML file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// The command-line slug (`gskf`, `kf-dynamic`, `mkpf`, `kfu-lstm`).
    pub slug: String,
    /// The paper's title as the results show it.
    pub title: String,
    /// The section of `docs/papers.md` that describes the experiment, e.g. `C.2`.
    pub anchor: String,
    /// Why this paper's numbers and ours differ (the results index).
    pub explanation: String,
    /// Its claims compare wall times, so it runs with no other paper at once
    /// ([`crate::run_papers`]).
    #[serde(default)]
    pub runs_alone: bool,
    /// The real datasets the paper reads.
    #[serde(default)]
    pub datasets: Vec<DatasetSpec>,
    /// Protocol parameters (typed by the paper's compute code; also template variables).
    #[serde(default)]
    pub params: toml::Table,
    /// Run sizes of the full run and of `--quick` (typed by the compute code; also template
    /// variables).
    #[serde(default)]
    pub budget: Budgets,
    /// The methods compared.
    #[serde(default)]
    pub methods: Vec<MethodSpec>,
    /// Named numbers the compute code produces that are not table cells (claims may use them).
    #[serde(default)]
    pub quantities: Vec<String>,
    /// Tables and claims, in the order of the results.
    #[serde(default)]
    pub sections: Vec<Section>,
    /// The figures the paper reports, by table and column.
    #[serde(default)]
    pub paper: Vec<PaperFigures>,
    /// Notes on the whole paper (templates), after the compute code's own.
    #[serde(default)]
    pub notes: Vec<String>,
}

/// A real dataset read from `Context::data_dir`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetSpec {
    /// Name used by the compute code.
    pub key: String,
    /// Folder under the data directory.
    pub folder: String,
    /// A file inside the folder that must exist, if any.
    #[serde(default)]
    pub file: Option<String>,
    /// What cannot run without it (the "missing" message).
    pub missing: String,
}

/// The parameters of a full and of a quick run.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Budgets {
    /// The full run.
    #[serde(default)]
    pub full: toml::Table,
    /// `--quick`.
    #[serde(default)]
    pub quick: toml::Table,
}

/// A method of the comparison.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MethodSpec {
    /// Key used in row keys and by the compute code.
    pub key: String,
    /// The label in tables.
    pub label: String,
    /// A short label (figures, evidence), if other than the label.
    #[serde(default)]
    pub short: Option<String>,
    /// The name of the method in trajpred's registry (or the paper's own kind).
    #[serde(default)]
    pub registry: Option<String>,
    /// Parameters of the method.
    #[serde(default)]
    pub params: toml::Table,
}

/// Tables and claims, repeated per instance when `instances` is given (every field may be
/// left out).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Section {
    /// Each instance's variables (`id` names it, for `only`).
    pub instances: Vec<BTreeMap<String, String>>,
    /// The tables.
    pub tables: Vec<TableSpec>,
    /// The claims.
    pub claims: Vec<ClaimSpec>,
    /// Named numbers of the run this section's claims use (with the instance's variables).
    pub quantities: Vec<String>,
}

/// A table: id, title, columns, rows (when known before the run) and notes.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableSpec {
    /// File stem, unique within the paper.
    pub id: String,
    /// Title (template).
    pub title: String,
    /// Columns, in order.
    pub columns: Vec<ColumnSpec>,
    /// Rows with their label cells; absent when the run decides the rows.
    #[serde(default)]
    pub rows: Option<Vec<RowSpec>>,
    /// Notes under the table (templates; one that renders empty is dropped).
    #[serde(default)]
    pub notes: Vec<String>,
    /// Only in these instances (by `id`).
    #[serde(default)]
    pub only: Option<Vec<String>>,
}

/// What a column holds (decides how `--check` compares it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// A label.
    Label,
    /// A number of ours, compared within `abs + rel * |value|`.
    Ours,
    /// The paper's figure.
    Paper,
    /// Wall time: not compared.
    Timing,
}

/// A column; `each` repeats it once per value, with `#` in `key` and `name` replaced by it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnSpec {
    /// Key in references and in the compute code's rows (default: the name).
    #[serde(default)]
    pub key: Option<String>,
    /// Header.
    pub name: String,
    /// What it holds.
    pub kind: Kind,
    /// Decimals shown in Markdown.
    #[serde(default)]
    pub decimals: usize,
    /// Absolute tolerance of `--check` (kind `ours`).
    #[serde(default)]
    pub abs: f64,
    /// Relative tolerance of `--check` (kind `ours`).
    #[serde(default)]
    pub rel: f64,
    /// Repeat the column per value.
    #[serde(default)]
    pub each: Option<Vec<toml::Value>>,
}

impl ColumnSpec {
    /// The key of the column.
    pub fn key(&self) -> &str {
        self.key.as_deref().unwrap_or(&self.name)
    }
}

/// A row known before the run: its key and its label cells (one per label column).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RowSpec {
    /// Key in references and in the compute code's rows.
    pub key: String,
    /// The label cells, in the order of the label columns.
    #[serde(default)]
    pub labels: Vec<toml::Value>,
}

/// Figures the paper reports in one column of one table, by row key.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaperFigures {
    /// The table id (after instance expansion).
    pub table: String,
    /// The column key (a column of kind `paper`).
    pub column: String,
    /// Row key to the paper's figure.
    pub values: BTreeMap<String, f64>,
}

/// A claim of the paper and how the run decides it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClaimSpec {
    /// Identifier, unique within the paper after expansion.
    pub id: String,
    /// The claim in words (template; `--check` matches claims by it).
    pub statement: String,
    /// What makes it hold.
    pub holds: Cond,
    /// The numbers shown as evidence (template).
    pub evidence: String,
    /// Only in these instances (by `id`).
    #[serde(default)]
    pub only: Option<Vec<String>>,
    /// Not checked when any of these tables is in the run.
    #[serde(default)]
    pub unless: Vec<String>,
    /// Decided by wall times of this machine: `--check` does not compare its verdict.
    #[serde(default)]
    pub wall_time: bool,
}

/// A section after instance expansion.
#[derive(Debug, Clone)]
pub struct Expanded {
    /// The tables with `${…}` replaced and `each` columns repeated.
    pub tables: Vec<TableSpec>,
    /// The claims with `${…}` replaced.
    pub claims: Vec<ClaimSpec>,
    /// The quantities with `${…}` replaced.
    pub quantities: Vec<String>,
}

impl Spec {
    /// Parses a spec from TOML text.
    pub fn parse(text: &str) -> Result<Spec> {
        toml::from_str(text).map_err(|e| spec_err("?", e.to_string()))
    }

    /// The budget of this run (`quick` or full).
    pub fn budget(&self, quick: bool) -> &toml::Table {
        if quick {
            &self.budget.quick
        } else {
            &self.budget.full
        }
    }

    /// The protocol parameters as the compute code's type.
    pub fn params<T: serde::de::DeserializeOwned>(&self) -> Result<T> {
        toml::Value::Table(self.params.clone())
            .try_into()
            .map_err(|e: toml::de::Error| spec_err(&self.slug, format!("params: {e}")))
    }

    /// The budget of this run as the compute code's type.
    pub fn budget_as<T: serde::de::DeserializeOwned>(&self, quick: bool) -> Result<T> {
        toml::Value::Table(self.budget(quick).clone())
            .try_into()
            .map_err(|e: toml::de::Error| spec_err(&self.slug, format!("budget: {e}")))
    }

    /// The method with this key.
    pub fn method(&self, key: &str) -> Result<&MethodSpec> {
        self.methods
            .iter()
            .find(|m| m.key == key)
            .ok_or_else(|| spec_err(&self.slug, format!("no method `{key}`")))
    }

    /// The dataset with this key.
    pub fn dataset(&self, key: &str) -> Result<&DatasetSpec> {
        self.datasets
            .iter()
            .find(|d| d.key == key)
            .ok_or_else(|| spec_err(&self.slug, format!("no dataset `{key}`")))
    }

    /// The paper's figure in `table`/`column` for `row`, if it reports one.
    pub fn paper_figure(&self, table: &str, column: &str, row: &str) -> Option<f64> {
        self.paper
            .iter()
            .find(|p| p.table == table && p.column == column)
            .and_then(|p| p.values.get(row).copied())
    }

    /// Every inconsistency of the spec (empty when it is consistent); see `spec::validate`.
    pub fn problems(&self) -> Vec<String> {
        validate::problems(self)
    }
}

impl MethodSpec {
    /// The short label (the label when none is given).
    pub fn short(&self) -> &str {
        self.short.as_deref().unwrap_or(&self.label)
    }
}
