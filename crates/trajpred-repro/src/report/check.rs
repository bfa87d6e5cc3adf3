//! `--check`: how a fresh run is compared with the committed results, cell by cell, with
//! every difference named.

pub use super::difference::Difference;
use super::{Claim, Column, ColumnKind, PaperResult, Table, Value, read_run_info};
use crate::error::{ReproError, Result, io_err};
use std::path::Path;

/// A cell as it is written to (and read back from) the CSV.
fn cell_text(v: &Value) -> String {
    match v {
        Value::Text(t) => t.clone(),
        Value::Num(x) => format!("{x:?}"),
        Value::Missing => String::new(),
    }
}

/// Names rows by their label cells when those name every row uniquely on both sides, else by
/// position.
fn row_names(
    committed: &[Vec<String>],
    fresh: &[Vec<String>],
    t: &Table,
) -> (Vec<String>, Vec<String>) {
    let labels: Vec<usize> = t
        .columns
        .iter()
        .enumerate()
        .filter(|(_, c)| c.kind == ColumnKind::Label)
        .map(|(i, _)| i)
        .collect();
    let by_label = |rows: &[Vec<String>]| -> Vec<String> {
        rows.iter()
            .map(|r| {
                labels
                    .iter()
                    .map(|&i| {
                        let value = r.get(i).map_or("", String::as_str);
                        format!("{} = {value}", t.columns[i].name)
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .collect()
    };
    let unique = |names: &[String]| {
        let mut sorted: Vec<&String> = names.iter().collect();
        sorted.sort();
        sorted.windows(2).all(|w| w[0] != w[1])
    };
    let (c, f) = (by_label(committed), by_label(fresh));
    if !labels.is_empty() && unique(&c) && unique(&f) {
        (c, f)
    } else {
        let position = |n: usize| (1..=n).map(|i| format!("#{i}")).collect();
        (position(committed.len()), position(fresh.len()))
    }
}

/// Compares one fresh table with its committed CSV text.
fn compare_table(t: &Table, path: &Path, text: &str, diffs: &mut Vec<Difference>) -> Result<()> {
    let csv_err = |e: csv::Error| ReproError::Csv {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let header: Vec<String> = r
        .headers()
        .map_err(csv_err)?
        .iter()
        .map(str::to_string)
        .collect();
    let names: Vec<String> = t.columns.iter().map(|c| c.name.clone()).collect();
    if header != names {
        diffs.push(Difference::Columns {
            table: t.id.clone(),
            committed: header,
            fresh: names,
        });
        return Ok(());
    }
    let committed: Vec<Vec<String>> = r
        .records()
        .map(|rec| rec.map(|rec| rec.iter().map(str::to_string).collect()))
        .collect::<std::result::Result<_, _>>()
        .map_err(csv_err)?;
    let fresh: Vec<Vec<String>> = t
        .rows
        .iter()
        .map(|row| row.iter().map(cell_text).collect())
        .collect();
    let (committed_names, fresh_names) = row_names(&committed, &fresh, t);
    for (name, row) in committed_names.iter().zip(&committed) {
        let Some(j) = fresh_names.iter().position(|n| n == name) else {
            diffs.push(Difference::MissingRow {
                table: t.id.clone(),
                row: name.clone(),
            });
            continue;
        };
        for ((cell, value), col) in row.iter().zip(&t.rows[j]).zip(&t.columns) {
            if let Some((fresh, allowed)) = compare_cell(cell, value, col) {
                diffs.push(Difference::Cell {
                    table: t.id.clone(),
                    row: name.clone(),
                    column: col.name.clone(),
                    committed: cell.clone(),
                    fresh,
                    allowed,
                });
            }
        }
    }
    for name in &fresh_names {
        if !committed_names.contains(name) {
            diffs.push(Difference::ExtraRow {
                table: t.id.clone(),
                row: name.clone(),
            });
        }
    }
    Ok(())
}

/// Compares the tables of a fresh run with the CSVs committed in `dir` (a paper's folder) and
/// returns every difference, in the order: per fresh table, its columns, rows and cells (or
/// [`Difference::ExtraTable`]); then the committed tables the fresh run lacks
/// ([`Difference::MissingTable`], every `<id>.csv` of `dir` counts as a committed table).
///
/// Rows are matched by their label cells when those name each row uniquely (else by
/// position); a committed row without a fresh counterpart is [`Difference::MissingRow`], and
/// the other way round [`Difference::ExtraRow`]. Cells are compared by their column's
/// [`ColumnKind`]:
///
/// - [`ColumnKind::Label`] and [`ColumnKind::Paper`]: equal (as text, or as numbers);
/// - [`ColumnKind::Ours`] `{ abs, rel }`: equal text, or both finite numbers with
///   `|committed - fresh| <= abs + rel * max(|committed|, |fresh|)` — the relative part scales
///   with the two values compared, and is the same whichever side is taken as the reference;
///   two NaNs or two equal infinities agree, a number never agrees with an empty (missing)
///   cell, and a non-finite value never agrees with a finite one;
/// - [`ColumnKind::Timing`]: not compared.
///
/// A missing `dir` is one [`Difference::NoCommittedRun`].
pub fn compare_with_committed(tables: &[Table], dir: &Path) -> Result<Vec<Difference>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(vec![Difference::NoCommittedRun {
                path: dir.to_path_buf(),
            }]);
        }
        Err(e) => {
            return Err(ReproError::Io {
                path: dir.to_path_buf(),
                source: e,
            });
        }
    };
    let mut committed_ids = Vec::new();
    for entry in entries {
        let path = entry.map_err(io_err(dir))?.path();
        let hidden = path
            .file_name()
            .and_then(|n| n.to_str())
            .is_none_or(|n| n.starts_with('.'));
        if !hidden
            && path.extension().is_some_and(|e| e == "csv")
            && path.is_file()
            && let Some(stem) = path.file_stem().and_then(|s| s.to_str())
        {
            committed_ids.push(stem.to_string());
        }
    }
    committed_ids.sort();
    let mut diffs = Vec::new();
    for t in tables {
        if !committed_ids.contains(&t.id) {
            diffs.push(Difference::ExtraTable {
                table: t.id.clone(),
            });
            continue;
        }
        let path = dir.join(format!("{}.csv", t.id));
        let text = std::fs::read_to_string(&path).map_err(io_err(&path))?;
        compare_table(t, &path, &text, &mut diffs)?;
    }
    for id in committed_ids {
        if !tables.iter().any(|t| t.id == id) {
            diffs.push(Difference::MissingTable { table: id });
        }
    }
    Ok(diffs)
}

/// Compares a whole fresh run with the run committed in `dir` (a paper's folder): its tables
/// as [`compare_with_committed`] does, then its figures and claims against the committed
/// `run.json` (a figure or claim on one side only is a difference, and so is a claim that
/// holds in one run and not in the other, unless the fresh claim is decided by wall times;
/// claims are matched by statement, their evidence is not compared). Titles, notes and wall
/// times are not compared.
pub fn compare_run(result: &PaperResult, dir: &Path) -> Result<Vec<Difference>> {
    let mut diffs = compare_with_committed(&result.tables, dir)?;
    if matches!(diffs.as_slice(), [Difference::NoCommittedRun { .. }]) {
        return Ok(diffs);
    }
    let json = dir.join("run.json");
    if !json.is_file() {
        diffs.push(Difference::NoCommittedRun { path: json });
        return Ok(diffs);
    }
    let info = read_run_info(dir)?;
    for (id, _) in &info.figures {
        if !result.figures.iter().any(|f| &f.id == id) {
            diffs.push(Difference::MissingFigure { figure: id.clone() });
        }
    }
    for f in &result.figures {
        if !info.figures.iter().any(|(id, _)| id == &f.id) {
            diffs.push(Difference::ExtraFigure {
                figure: f.id.clone(),
            });
        }
    }
    // claims are matched by statement, each fresh claim at most once
    let mut unmatched: Vec<&Claim> = result.claims.iter().collect();
    for c in &info.claims {
        match unmatched.iter().position(|f| f.statement == c.statement) {
            Some(i) => {
                let f = unmatched.remove(i);
                if f.holds != c.holds && !f.wall_time {
                    diffs.push(Difference::Verdict {
                        statement: c.statement.clone(),
                        committed: c.holds,
                        fresh: f.holds,
                    });
                }
            }
            None => diffs.push(Difference::MissingClaim {
                statement: c.statement.clone(),
            }),
        }
    }
    for f in unmatched {
        diffs.push(Difference::ExtraClaim {
            statement: f.statement.clone(),
        });
    }
    Ok(diffs)
}

/// `--check` of one paper: compares `result` with the run committed in `dir` ([`compare_run`])
/// and fails with [`ReproError::CheckFailed`], listing every difference, unless they agree.
pub fn check_run(paper: &str, result: &PaperResult, dir: &Path) -> Result<()> {
    let differences = compare_run(result, dir)?;
    if differences.is_empty() {
        Ok(())
    } else {
        Err(ReproError::CheckFailed {
            paper: paper.to_string(),
            committed: dir.to_path_buf(),
            differences,
        })
    }
}

/// Whether a committed cell and a fresh one agree under `col`'s kind (see
/// [`compare_with_committed`]); when they do not, the fresh cell's text and the allowed
/// difference (for a column of ours with two finite numbers).
fn compare_cell(committed: &str, fresh: &Value, col: &Column) -> Option<(String, Option<f64>)> {
    let fresh_text = cell_text(fresh);
    if col.kind == ColumnKind::Timing || committed == fresh_text {
        return None;
    }
    let numbers = match (committed.parse::<f64>(), fresh) {
        (Ok(a), Value::Num(b)) => Some((a, *b)),
        _ => None,
    };
    let Some((a, b)) = numbers else {
        return Some((fresh_text, None));
    };
    if a == b || (a.is_nan() && b.is_nan()) {
        return None;
    }
    match col.kind {
        ColumnKind::Ours { abs, rel } if a.is_finite() && b.is_finite() => {
            let allowed = abs + rel * a.abs().max(b.abs());
            ((a - b).abs() > allowed).then_some((fresh_text, Some(allowed)))
        }
        _ => Some((fresh_text, None)),
    }
}
