//! Which results table a Parquet file is (a study's runs or its summary):
//! a file of the wrong kind, or one missing a column the reader needs, is
//! the user's input and is refused naming the file and the column, before
//! any reader meets the gap as an internal "column not found".

use crate::study::results::io::{WRONG_TABLE, read_parquet};
use polars::prelude::{DataFrame, PolarsError, PolarsResult};
use std::path::Path;

/// The kinds of results table a verb may be given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableKind {
    /// `runs.parquet`: one row per run.
    Runs,
    /// `summary.parquet`: one row per design.
    Summary,
}

impl TableKind {
    /// The file name `study run` gives this table.
    pub fn file_name(self) -> &'static str {
        match self {
            TableKind::Runs => "runs.parquet",
            TableKind::Summary => "summary.parquet",
        }
    }

    /// Columns every reader of this kind needs (and the other kind lacks).
    pub fn required(self) -> &'static [&'static str] {
        match self {
            TableKind::Runs => &[
                "run_id",
                "design_id",
                "sample_id",
                "outcome",
                "settled",
                "settling_revs",
            ],
            TableKind::Summary => &["design_id", "rank", "rank_by", "settled_fraction"],
        }
    }

    fn other(self) -> Self {
        match self {
            TableKind::Runs => TableKind::Summary,
            TableKind::Summary => TableKind::Runs,
        }
    }
}

/// Refuse `columns` (those of the file at `path`) unless they hold every
/// column a table of `kind` needs; the message names the file, the missing
/// columns, and the other kind when the file is one.
pub fn check_columns<'a>(
    path: &Path,
    kind: TableKind,
    columns: impl IntoIterator<Item = &'a str> + Clone,
) -> PolarsResult<()> {
    let has = |c: &str| columns.clone().into_iter().any(|x| x == c);
    let missing: Vec<String> = kind
        .required()
        .iter()
        .filter(|c| !has(c))
        .map(|c| format!("\"{c}\""))
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    let other = kind.other();
    let looks = if other.required().iter().all(|c| has(c)) {
        format!(
            "; it is a study's {}: give its {}",
            other.file_name(),
            kind.file_name()
        )
    } else {
        String::new()
    };
    let (s, are) = if missing.len() == 1 {
        ("", "is")
    } else {
        ("s", "are")
    };
    Err(PolarsError::ComputeError(
        format!(
            "{}: {WRONG_TABLE}, a study's {}: column{s} {} {are} missing{looks}",
            path.display(),
            kind.file_name(),
            missing.join(", ")
        )
        .into(),
    ))
}

/// Read the table at `path`, refused as in [`check_columns`] unless it is
/// of `kind`.
pub fn read_table(path: &Path, kind: TableKind) -> PolarsResult<DataFrame> {
    let df = read_parquet(path)?;
    let names: Vec<&str> = df.get_column_names().iter().map(|n| n.as_str()).collect();
    check_columns(path, kind, names.iter().copied())?;
    Ok(df)
}
