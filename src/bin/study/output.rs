//! Output formats shared by the verbs: the terminal's width and `--wide`,
//! JSON and CSV; aligned tables and wrapping are the library's
//! ([`autobal::text`]), re-exported here.

pub use autobal::text::{Layout, dropped_note, fitted_table, p_value_text, text_table, wrap};

use serde::Serialize;
use std::sync::OnceLock;

/// `--wide`, set once by `main`.
static WIDE: OnceLock<bool> = OnceLock::new();

/// Record `--wide` (the first call wins).
pub fn set_wide(wide: bool) {
    let _ = WIDE.set(wide);
}

/// Whether `--wide` was given: notes then keep the exact terms and symbols
/// (τ, 2α) that the default output says in words.
pub fn wide() -> bool {
    WIDE.get().copied().unwrap_or(false)
}

/// Columns text output may fill: `None` (no limit) with `--wide`, else the
/// terminal's width on a terminal, else `$COLUMNS`, else 80.
pub fn text_width() -> Option<usize> {
    if wide() {
        return None;
    }
    Some(terminal_columns())
}

/// The terminal's width on a terminal, else `$COLUMNS`, else 80 (at least 40).
pub fn terminal_columns() -> usize {
    let from_terminal = terminal_size::terminal_size_of(std::io::stdout())
        .map(|(terminal_size::Width(w), _)| usize::from(w));
    let from_env = || std::env::var("COLUMNS").ok().and_then(|c| c.parse().ok());
    from_terminal.or_else(from_env).unwrap_or(80).max(40)
}

/// The layout `--wide` and the terminal ask for.
pub fn layout() -> Layout {
    Layout {
        width: text_width(),
        wide: wide(),
    }
}

/// Print `text` and a newline on stdout, wrapped to [`text_width`].
pub fn say(text: &str) {
    print!("{}", wrap(text, text_width()));
}

/// Print `text` and a newline on stderr, wrapped to [`text_width`].
pub fn say_err(text: &str) {
    eprint!("{}", wrap(text, text_width()));
}

/// How a verb should print its rows.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Aligned, human-readable columns.
    Table,
    /// A JSON array of objects.
    Json,
    /// Comma-separated values with a header line.
    Csv,
}

impl Format {
    /// Pick the format from the `--json` / `--csv` flags (clap makes them exclusive).
    pub fn from_flags(json: bool, csv: bool) -> Self {
        match (json, csv) {
            (true, _) => Format::Json,
            (_, true) => Format::Csv,
            _ => Format::Table,
        }
    }
}

/// Serialise rows as a pretty JSON array.
pub fn json<T: Serialize>(rows: &[T]) -> Result<String, serde_json::Error> {
    serde_json::to_string_pretty(rows)
}

/// Serialise rows as CSV with a header taken from the field names.
pub fn csv<T: Serialize>(rows: &[T]) -> Result<String, Box<dyn std::error::Error>> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    for row in rows {
        writer.serialize(row)?;
    }
    Ok(String::from_utf8(writer.into_inner()?)?)
}
