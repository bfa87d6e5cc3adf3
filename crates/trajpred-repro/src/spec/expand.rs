//! Instance expansion: a section repeated once per instance, `${name}` replaced by the
//! instance's value in every string, `each` columns repeated per value.

use super::{ClaimSpec, ColumnSpec, Expanded, RowSpec, Spec, TableSpec};
use crate::{ReproError, Result};
use std::collections::BTreeMap;

pub(super) fn spec_err(slug: &str, reason: impl Into<String>) -> ReproError {
    ReproError::Spec {
        paper: slug.to_string(),
        reason: reason.into(),
    }
}

/// Replaces every `${name}` of `s` by `vars[name]`; an unknown name is an error.
pub fn substitute(s: &str, vars: &BTreeMap<String, String>) -> std::result::Result<String, String> {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find("${") {
        out.push_str(&rest[..i]);
        let after = &rest[i + 2..];
        let end = after
            .find('}')
            .ok_or_else(|| format!("unclosed ${{ in {s:?}"))?;
        let name = &after[..end];
        let value = vars
            .get(name)
            .ok_or_else(|| format!("no instance variable `{name}` for {s:?}"))?;
        out.push_str(value);
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

fn expand_value(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

impl Spec {
    /// The sections with their instances expanded, in order.
    pub fn expand(&self) -> Result<Vec<Expanded>> {
        let err = |reason: String| spec_err(&self.slug, reason);
        let mut out = Vec::new();
        let single = [BTreeMap::new()];
        for section in &self.sections {
            let instances: &[BTreeMap<String, String>] = if section.instances.is_empty() {
                &single
            } else {
                &section.instances
            };
            for vars in instances {
                let id = vars.get("id").map(String::as_str);
                let keep = |only: &Option<Vec<String>>| match (only, id) {
                    (Some(list), Some(id)) => list.iter().any(|x| x == id),
                    _ => true,
                };
                let sub = |s: &str| substitute(s, vars).map_err(err);
                let mut tables = Vec::new();
                for t in section.tables.iter().filter(|t| keep(&t.only)) {
                    tables.push(self.expand_table(t, &sub)?);
                }
                let mut claims = Vec::new();
                for c in section.claims.iter().filter(|c| keep(&c.only)) {
                    claims.push(ClaimSpec {
                        id: sub(&c.id)?,
                        statement: sub(&c.statement)?,
                        holds: c.holds.map_refs(&mut |r| sub(r))?,
                        evidence: sub(&c.evidence)?,
                        only: None,
                        unless: c.unless.iter().map(|u| sub(u)).collect::<Result<_>>()?,
                        wall_time: c.wall_time,
                    });
                }
                let quantities = section
                    .quantities
                    .iter()
                    .map(|q| sub(q))
                    .collect::<Result<_>>()?;
                out.push(Expanded {
                    tables,
                    claims,
                    quantities,
                });
            }
        }
        Ok(out)
    }

    fn expand_table(
        &self,
        t: &TableSpec,
        sub: &dyn Fn(&str) -> Result<String>,
    ) -> Result<TableSpec> {
        let mut columns = Vec::new();
        for c in &t.columns {
            let values: Vec<Option<String>> = match &c.each {
                Some(each) => each.iter().map(|v| Some(expand_value(v))).collect(),
                None => vec![None],
            };
            for v in values {
                let put = |s: &str| -> Result<String> {
                    let s = sub(s)?;
                    Ok(match &v {
                        Some(v) => s.replace('#', v),
                        None => s,
                    })
                };
                columns.push(ColumnSpec {
                    key: Some(put(c.key())?),
                    name: put(&c.name)?,
                    each: None,
                    ..c.clone()
                });
            }
        }
        let rows = match &t.rows {
            Some(rows) => Some(
                rows.iter()
                    .map(|r| {
                        let labels = r
                            .labels
                            .iter()
                            .map(|l| match l {
                                toml::Value::String(s) => sub(s).map(toml::Value::String),
                                other => Ok(other.clone()),
                            })
                            .collect::<Result<_>>()?;
                        Ok(RowSpec {
                            key: sub(&r.key)?,
                            labels,
                        })
                    })
                    .collect::<Result<Vec<_>>>()?,
            ),
            None => None,
        };
        Ok(TableSpec {
            id: sub(&t.id)?,
            title: sub(&t.title)?,
            columns,
            rows,
            notes: t.notes.iter().map(|n| sub(n)).collect::<Result<_>>()?,
            only: None,
        })
    }
}
