//! The one runner: a paper's computed numbers ([`Computed`]) plus its spec ([`Spec`]) become
//! the report ([`PaperResult`]): tables with the paper's figures beside ours, the claims
//! decided from the run, templates filled.

use crate::report::{ColumnKind, Figure, PaperResult, Table, Value};
use crate::spec::claim::Lookup;
use crate::spec::template::{Source, Var, render};
use crate::spec::{Kind, Spec, TableSpec};
use crate::{Context, ReproError, Result};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// One row the compute code produced: its key and its cells by column key.
#[derive(Debug, Clone, Default)]
pub struct Row {
    /// The row key (as in the spec's rows, or chosen by the compute code).
    pub key: String,
    /// Cells by column key (labels too when the spec does not list the rows).
    pub cells: BTreeMap<String, Value>,
}

impl Row {
    /// An empty row.
    pub fn new(key: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            cells: BTreeMap::new(),
        }
    }

    /// Sets the cell of column `key`.
    pub fn set(mut self, key: &str, v: impl Into<Value>) -> Self {
        self.cells.insert(key.to_string(), v.into());
        self
    }
}

/// One table's numbers.
#[derive(Debug, Clone, Default)]
pub struct Rows {
    /// The rows, in order (the spec's order wins when it lists them).
    pub rows: Vec<Row>,
    /// Variables of this table's templates (before the paper's).
    pub vars: BTreeMap<String, Var>,
    /// Notes placed before the spec's notes.
    pub notes: Vec<String>,
}

impl Rows {
    /// Sets a template variable of this table.
    pub fn var(&mut self, name: &str, v: impl Into<Value>) {
        self.vars.insert(name.to_string(), Var::from(v.into()));
    }
}

/// Everything a paper's compute code produced.
#[derive(Debug, Clone, Default)]
pub struct Computed {
    /// Tables by id.
    pub tables: BTreeMap<String, Rows>,
    /// The figures (charts are paper-specific code).
    pub figures: Vec<Figure>,
    /// Template variables.
    pub vars: BTreeMap<String, Var>,
    /// Named numbers claims may use (declared in the spec's `quantities`).
    pub quantities: BTreeMap<String, f64>,
    /// Notes before the spec's.
    pub notes: Vec<String>,
    /// Data read or generated.
    pub data: Vec<String>,
    /// Experiments not run for missing data.
    pub missing: Vec<String>,
}

impl Computed {
    /// Sets a template variable.
    pub fn var(&mut self, name: &str, v: impl Into<Value>) {
        self.vars.insert(name.to_string(), Var::from(v.into()));
    }

    /// The rows of table `id` (created empty).
    pub fn table(&mut self, id: &str) -> &mut Rows {
        self.tables.entry(id.to_string()).or_default()
    }

    /// The folder of dataset `key` of the spec when present (with its required file); else
    /// records the spec's "missing" message and returns `None`.
    pub fn locate(&mut self, spec: &Spec, ctx: &Context, key: &str) -> Result<Option<PathBuf>> {
        let d = spec.dataset(key)?;
        match ctx.data(&d.folder) {
            Some(dir) if d.file.as_ref().is_none_or(|f| dir.join(f).is_file()) => Ok(Some(dir)),
            _ => {
                let vars = spec_vars(spec, ctx.quick);
                let env = Env {
                    spec,
                    built: &[],
                    computed: self,
                    spec_vars: &vars,
                    local: None,
                };
                let what = render(&d.missing, &env).map_err(|e| spec_err(spec, e))?;
                self.missing.push(ctx.missing(&d.folder, &what));
                Ok(None)
            }
        }
    }
}

/// A table built, with its keys.
struct Built {
    table: Table,
    rows: Vec<String>,
    cols: Vec<String>,
}

/// Looks names up in the built tables, the quantities and the variables.
struct Env<'a> {
    spec: &'a Spec,
    built: &'a [Built],
    computed: &'a Computed,
    spec_vars: &'a BTreeMap<String, Var>,
    local: Option<&'a BTreeMap<String, Var>>,
}

fn matches(pattern: &str, key: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern.split(',').any(|p| p == key),
        Some((a, b)) => key.len() >= a.len() + b.len() && key.starts_with(a) && key.ends_with(b),
    }
}

impl Env<'_> {
    fn select(&self, reference: &str) -> Option<(&Built, usize, Vec<usize>)> {
        let mut parts = reference.splitn(3, '/');
        let (t, r, c) = (parts.next()?, parts.next()?, parts.next()?);
        let b = self.built.iter().find(|b| b.table.id == t)?;
        let col = b.cols.iter().position(|k| k == c)?;
        let rows: Vec<usize> = if r.contains('*') {
            (0..b.rows.len())
                .filter(|&i| matches(r, &b.rows[i]))
                .collect()
        } else {
            r.split(',')
                .map(|k| b.rows.iter().position(|x| x == k))
                .collect::<Option<_>>()?
        };
        (!rows.is_empty()).then_some((b, col, rows))
    }
}

impl Lookup for Env<'_> {
    fn numbers(&self, reference: &str) -> Option<Vec<f64>> {
        if !reference.contains('/') {
            return self.computed.quantities.get(reference).map(|&x| vec![x]);
        }
        // the paper's figures are known without the run
        let mut parts = reference.splitn(3, '/');
        if let (Some(t), Some(r), Some(c)) = (parts.next(), parts.next(), parts.next())
            && let Some(x) = self.spec.paper_figure(t, c, r)
        {
            return Some(vec![x]);
        }
        let (b, col, rows) = self.select(reference)?;
        rows.iter()
            .map(|&i| match b.table.rows[i][col] {
                Value::Num(x) => Some(x),
                _ => None,
            })
            .collect()
    }

    fn row_keys(&self, reference: &str) -> Option<Vec<String>> {
        let (b, _, rows) = self.select(reference)?;
        Some(rows.iter().map(|&i| b.rows[i].clone()).collect())
    }
}

impl Source for Env<'_> {
    fn var(&self, name: &str) -> Option<Var> {
        self.local
            .and_then(|l| l.get(name))
            .or_else(|| self.computed.vars.get(name))
            .or_else(|| self.spec_vars.get(name))
            .cloned()
    }
}

fn spec_err(spec: &Spec, reason: impl Into<String>) -> ReproError {
    ReproError::Spec {
        paper: spec.slug.clone(),
        reason: reason.into(),
    }
}

fn label_value(v: &toml::Value) -> Value {
    match v {
        toml::Value::String(s) => Value::Text(s.clone()),
        toml::Value::Integer(i) => Value::Num(*i as f64),
        toml::Value::Float(x) => Value::Num(*x),
        other => Value::Text(other.to_string()),
    }
}

fn build(spec: &Spec, t: &TableSpec, rows: &Rows, env: &Env<'_>) -> Result<Built> {
    let err = |reason: String| spec_err(spec, format!("table {}: {reason}", t.id));
    let env = Env {
        local: Some(&rows.vars),
        ..*env
    };
    let mut table = Table::new(&t.id, render(&t.title, &env).map_err(err)?);
    table.columns = t
        .columns
        .iter()
        .map(|c| crate::report::Column {
            name: c.name.clone(),
            kind: match c.kind {
                Kind::Label => ColumnKind::Label,
                Kind::Ours => ColumnKind::Ours {
                    abs: c.abs,
                    rel: c.rel,
                },
                Kind::Paper => ColumnKind::Paper,
                Kind::Timing => ColumnKind::Timing,
            },
            decimals: c.decimals,
        })
        .collect();
    // the rows: the spec's (those the run produced), or the run's own
    let ordered: Vec<(&Row, Option<&[toml::Value]>)> = match &t.rows {
        Some(spec_rows) => {
            if let Some(extra) = rows
                .rows
                .iter()
                .find(|r| !spec_rows.iter().any(|s| s.key == r.key))
            {
                return Err(err(format!("row `{}` is not in the spec", extra.key)));
            }
            spec_rows
                .iter()
                .filter_map(|s| {
                    let r = rows.rows.iter().find(|r| r.key == s.key)?;
                    Some((r, Some(s.labels.as_slice())))
                })
                .collect()
        }
        None => rows.rows.iter().map(|r| (r, None)).collect(),
    };
    let mut keys = Vec::new();
    for (row, labels) in ordered {
        let mut label_i = 0;
        let mut cells = Vec::with_capacity(t.columns.len());
        for c in &t.columns {
            let key = c.key();
            let v = match (c.kind, labels) {
                (Kind::Label, Some(l)) => {
                    label_i += 1;
                    l.get(label_i - 1).map(label_value)
                }
                (Kind::Paper, _) => Some(
                    spec.paper_figure(&t.id, key, &row.key)
                        .map_or(Value::Missing, Value::Num),
                ),
                _ => row.cells.get(key).cloned(),
            };
            cells.push(v.ok_or_else(|| err(format!("row `{}` has no cell `{key}`", row.key)))?);
        }
        table.push(cells)?;
        keys.push(row.key.clone());
    }
    Ok(Built {
        table,
        rows: keys,
        cols: t.columns.iter().map(|c| c.key().to_string()).collect(),
    })
}

/// The spec's parameters and this run's budget as template variables.
fn spec_vars(spec: &Spec, quick: bool) -> BTreeMap<String, Var> {
    spec.params
        .iter()
        .chain(spec.budget(quick))
        .map(|(k, v)| (k.clone(), Var::from(v)))
        .collect()
}

/// Builds the report of one paper from its spec and computed numbers: every table of the spec
/// the run produced (in the spec's order), the run's figures, every claim whose numbers are in
/// the run (decided by the spec's condition), data, notes (the run's, then the spec's).
pub fn assemble(spec: &Spec, ctx: &Context, computed: Computed) -> Result<PaperResult> {
    let sections = spec.expand()?;
    let vars = spec_vars(spec, ctx.quick);
    let mut built: Vec<Built> = Vec::new();
    let mut claims = Vec::new();
    for s in &sections {
        for t in &s.tables {
            if let Some(rows) = computed.tables.get(&t.id) {
                let env = Env {
                    spec,
                    built: &built,
                    computed: &computed,
                    spec_vars: &vars,
                    local: None,
                };
                let b = build(spec, t, rows, &env)?;
                built.push(b);
                // notes may cite the table's own cells
                let env = Env {
                    spec,
                    built: &built,
                    computed: &computed,
                    spec_vars: &vars,
                    local: Some(&rows.vars),
                };
                let mut notes = Vec::new();
                for n in rows.notes.iter().chain(&t.notes) {
                    let note = render(n, &env)
                        .map_err(|e| spec_err(spec, format!("table {}: {e}", t.id)))?;
                    if !note.is_empty() {
                        notes.push(note);
                    }
                }
                if let Some(b) = built.last_mut() {
                    b.table.notes = notes;
                }
            }
        }
        claims.extend(s.claims.iter());
    }
    if let Some(id) = computed
        .tables
        .keys()
        .find(|id| !built.iter().any(|b| &b.table.id == *id))
    {
        return Err(spec_err(
            spec,
            format!("the run produced table `{id}`, not in the spec"),
        ));
    }
    let env = Env {
        spec,
        built: &built,
        computed: &computed,
        spec_vars: &vars,
        local: None,
    };
    let mut result = PaperResult::new();
    for c in claims {
        if c.unless
            .iter()
            .any(|u| !u.is_empty() && built.iter().any(|b| &b.table.id == u))
        {
            continue;
        }
        let Some(holds) = c.holds.eval(&env) else {
            continue;
        };
        let err = |reason: String| spec_err(spec, format!("claim {}: {reason}", c.id));
        result
            .claim(
                render(&c.statement, &env).map_err(err)?,
                holds,
                render(&c.evidence, &env).map_err(err)?,
            )
            .wall_time = c.wall_time;
    }
    result.notes = computed.notes.clone();
    for n in &spec.notes {
        let note = render(n, &env).map_err(|e| spec_err(spec, format!("note: {e}")))?;
        if !note.is_empty() {
            result.notes.push(note);
        }
    }
    result.data = computed.data.clone();
    result.missing = computed.missing.clone();
    result.tables = built.into_iter().map(|b| b.table).collect();
    result.figures = computed.figures;
    Ok(result)
}
