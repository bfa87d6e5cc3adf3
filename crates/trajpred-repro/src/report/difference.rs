//! The differences `--check` reports between a fresh run and the committed one.

use std::path::PathBuf;

/// One way a fresh run differs from the committed one (`--check`).
#[derive(Debug, Clone, PartialEq)]
pub enum Difference {
    /// There is no committed run to compare with: the folder, or its `run.json`, is missing.
    NoCommittedRun {
        /// The missing folder or file.
        path: PathBuf,
    },
    /// A table is committed (`<table>.csv`) but the fresh run did not produce it.
    MissingTable {
        /// The table id.
        table: String,
    },
    /// The fresh run produced a table that is not committed.
    ExtraTable {
        /// The table id.
        table: String,
    },
    /// A table's columns differ (names or order).
    Columns {
        /// The table id.
        table: String,
        /// The committed headers.
        committed: Vec<String>,
        /// The fresh run's headers.
        fresh: Vec<String>,
    },
    /// A committed row has no counterpart in the fresh run.
    MissingRow {
        /// The table id.
        table: String,
        /// The row: its labels (`m = 2`), or its position (`#3`) when the labels do not name
        /// the rows uniquely.
        row: String,
    },
    /// A row of the fresh run has no counterpart in the committed table.
    ExtraRow {
        /// The table id.
        table: String,
        /// The row, named as in [`Difference::MissingRow`].
        row: String,
    },
    /// A cell differs by more than its column allows.
    Cell {
        /// The table id.
        table: String,
        /// The row, named as in [`Difference::MissingRow`].
        row: String,
        /// The column header.
        column: String,
        /// The committed cell, as in the CSV.
        committed: String,
        /// The fresh cell, as it would be written to the CSV.
        fresh: String,
        /// The largest difference the column allowed here (`abs + rel * max(|committed|,
        /// |fresh|)`), for a column of our numbers whose cells are both finite numbers.
        allowed: Option<f64>,
    },
    /// A figure is committed but the fresh run did not produce it.
    MissingFigure {
        /// The figure id.
        figure: String,
    },
    /// The fresh run produced a figure that is not committed.
    ExtraFigure {
        /// The figure id.
        figure: String,
    },
    /// A claim is committed but the fresh run did not check it.
    MissingClaim {
        /// The claim's statement.
        statement: String,
    },
    /// The fresh run checked a claim that is not committed.
    ExtraClaim {
        /// The claim's statement.
        statement: String,
    },
    /// A claim holds in one run and not in the other.
    Verdict {
        /// The claim's statement.
        statement: String,
        /// Whether it holds in the committed run.
        committed: bool,
        /// Whether it holds in the fresh run.
        fresh: bool,
    },
}

impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let yes_no = |b: bool| if b { "holds" } else { "does not hold" };
        match self {
            Difference::NoCommittedRun { path } => {
                write!(
                    f,
                    "{}: missing, no committed run to compare with",
                    path.display()
                )
            }
            Difference::MissingTable { table } => {
                write!(f, "table {table}: committed, missing from the fresh run")
            }
            Difference::ExtraTable { table } => {
                write!(f, "table {table}: in the fresh run, not committed")
            }
            Difference::Columns {
                table,
                committed,
                fresh,
            } => write!(
                f,
                "table {table}: committed columns {committed:?}, fresh run's {fresh:?}"
            ),
            Difference::MissingRow { table, row } => {
                write!(
                    f,
                    "table {table}, row {row}: committed, missing from the fresh run"
                )
            }
            Difference::ExtraRow { table, row } => {
                write!(
                    f,
                    "table {table}, row {row}: in the fresh run, not committed"
                )
            }
            Difference::Cell {
                table,
                row,
                column,
                committed,
                fresh,
                allowed,
            } => {
                write!(
                    f,
                    "table {table}, row {row}, column \"{column}\": committed {committed:?}, \
                     fresh {fresh:?}"
                )?;
                match allowed {
                    Some(a) => write!(f, " (allowed difference {a:e})"),
                    None => write!(f, " (must be equal)"),
                }
            }
            Difference::MissingFigure { figure } => {
                write!(f, "figure {figure}: committed, missing from the fresh run")
            }
            Difference::ExtraFigure { figure } => {
                write!(f, "figure {figure}: in the fresh run, not committed")
            }
            Difference::MissingClaim { statement } => {
                write!(
                    f,
                    "claim \"{statement}\": committed, missing from the fresh run"
                )
            }
            Difference::ExtraClaim { statement } => {
                write!(f, "claim \"{statement}\": in the fresh run, not committed")
            }
            Difference::Verdict {
                statement,
                committed,
                fresh,
            } => write!(
                f,
                "claim \"{statement}\": {} in the committed run, {} in the fresh run",
                yes_no(*committed),
                yes_no(*fresh)
            ),
        }
    }
}
