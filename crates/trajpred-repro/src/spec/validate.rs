//! The consistency check of a spec: every table, row and column a claim or a template refers
//! to exists, every paper figure sits in a `paper` column of a table that exists, ids and keys
//! are unique, every listed row has one label per label column, every quantity used is
//! declared.

use super::template::names;
use super::{Kind, Spec, TableSpec};
use std::collections::BTreeSet;

fn duplicates<'a>(what: &str, items: impl Iterator<Item = &'a str>, out: &mut Vec<String>) {
    let mut seen = BTreeSet::new();
    for i in items {
        if !seen.insert(i) {
            out.push(format!("{what} `{i}` appears twice"));
        }
    }
}

/// Checks a reference (`table/rows/column` or a quantity) against the expanded tables.
fn check_ref(known: &Known<'_>, r: &str, where_: &str, out: &mut Vec<String>) {
    let tables = known.tables;
    let mut parts = r.splitn(3, '/');
    let (Some(t), Some(rows), Some(c)) = (parts.next(), parts.next(), parts.next()) else {
        if !known.quantities.iter().any(|q| q == r) {
            out.push(format!(
                "{where_}: `{r}` is neither a table reference nor a quantity"
            ));
        }
        return;
    };
    let Some(table) = tables.iter().find(|x| x.id == t) else {
        out.push(format!("{where_}: no table `{t}` (in `{r}`)"));
        return;
    };
    if !table.columns.iter().any(|x| x.key() == c) {
        out.push(format!(
            "{where_}: table `{t}` has no column `{c}` (in `{r}`)"
        ));
    }
    if let Some(spec_rows) = &table.rows
        && !rows.contains('*')
    {
        for k in rows.split(',') {
            if !spec_rows.iter().any(|x| x.key == k) {
                out.push(format!("{where_}: table `{t}` has no row `{k}` (in `{r}`)"));
            }
        }
    }
}

fn check_template(known: &Known<'_>, text: &str, where_: &str, out: &mut Vec<String>) {
    for n in names(text) {
        if n.contains('/') {
            check_ref(known, &n, where_, out);
        }
    }
}

/// What references may name: the expanded tables and the declared quantities.
struct Known<'a> {
    tables: &'a [TableSpec],
    quantities: Vec<String>,
}

/// Every problem of `spec`, one sentence each.
pub fn problems(spec: &Spec) -> Vec<String> {
    let mut out = Vec::new();
    let sections = match spec.expand() {
        Ok(s) => s,
        Err(e) => return vec![e.to_string()],
    };
    let tables: Vec<TableSpec> = sections.iter().flat_map(|s| s.tables.clone()).collect();
    let known = Known {
        tables: &tables,
        quantities: spec
            .quantities
            .iter()
            .chain(sections.iter().flat_map(|s| &s.quantities))
            .cloned()
            .collect(),
    };
    duplicates("table", tables.iter().map(|t| t.id.as_str()), &mut out);
    duplicates(
        "claim",
        sections
            .iter()
            .flat_map(|s| s.claims.iter().map(|c| c.id.as_str())),
        &mut out,
    );
    duplicates(
        "method",
        spec.methods.iter().map(|m| m.key.as_str()),
        &mut out,
    );
    duplicates(
        "dataset",
        spec.datasets.iter().map(|d| d.key.as_str()),
        &mut out,
    );
    for t in &tables {
        duplicates(
            &format!("table `{}`: column", t.id),
            t.columns.iter().map(|c| c.key()),
            &mut out,
        );
        let labels = t.columns.iter().filter(|c| c.kind == Kind::Label).count();
        if let Some(rows) = &t.rows {
            duplicates(
                &format!("table `{}`: row", t.id),
                rows.iter().map(|r| r.key.as_str()),
                &mut out,
            );
            for r in rows.iter().filter(|r| r.labels.len() != labels) {
                out.push(format!(
                    "table `{}`, row `{}`: {} labels for {labels} label columns",
                    t.id,
                    r.key,
                    r.labels.len()
                ));
            }
        }
        for n in &t.notes {
            check_template(&known, n, &format!("table `{}` note", t.id), &mut out);
        }
    }
    for p in &spec.paper {
        let Some(t) = tables.iter().find(|t| t.id == p.table) else {
            out.push(format!("paper figures: no table `{}`", p.table));
            continue;
        };
        match t.columns.iter().find(|c| c.key() == p.column) {
            Some(c) if c.kind == Kind::Paper => {}
            Some(_) => out.push(format!(
                "paper figures: column `{}` of `{}` is not a paper column",
                p.column, p.table
            )),
            None => out.push(format!(
                "paper figures: `{}` has no column `{}`",
                p.table, p.column
            )),
        }
        if let Some(rows) = &t.rows {
            for k in p
                .values
                .keys()
                .filter(|k| !rows.iter().any(|r| &r.key == *k))
            {
                out.push(format!("paper figures: `{}` has no row `{k}`", p.table));
            }
        }
    }
    for c in sections.iter().flat_map(|s| &s.claims) {
        let where_ = format!("claim `{}`", c.id);
        for r in c.holds.refs() {
            check_ref(&known, &r, &where_, &mut out);
        }
        if let super::claim::Cond::Argmin { of, is } = &c.holds
            && let Some(t) = tables
                .iter()
                .find(|t| of.starts_with(&format!("{}/", t.id)))
            && let Some(rows) = &t.rows
            && !rows.iter().any(|r| &r.key == is)
        {
            out.push(format!("{where_}: table `{}` has no row `{is}`", t.id));
        }
        for u in c
            .unless
            .iter()
            .filter(|u| !u.is_empty() && !tables.iter().any(|t| &t.id == *u))
        {
            out.push(format!("{where_}: no table `{u}` (in unless)"));
        }
        check_template(&known, &c.statement, &where_, &mut out);
        check_template(&known, &c.evidence, &where_, &mut out);
    }
    for n in &spec.notes {
        check_template(&known, n, "note", &mut out);
    }
    out
}
