//! Output formats shared by the verbs: aligned text tables, JSON and CSV.

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

/// `text` with every line wrapped at words to `width` (continuation lines
/// indented by two spaces); lines kept whole for `None`. Every line ends in
/// a newline either way.
pub fn wrap(text: &str, width: Option<usize>) -> String {
    // Every line ends in a newline at any width: at full width too, or a
    // text without one runs into the next ("failures 0wrote results/…").
    let options = width.map(|w| textwrap::Options::new(w).subsequent_indent("  "));
    let mut out = String::new();
    for line in text.lines() {
        match &options {
            Some(options) => out.push_str(&textwrap::fill(line, options)),
            None => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

/// Print `text` and a newline on stdout, wrapped to [`text_width`].
pub fn say(text: &str) {
    print!("{}", wrap(text, text_width()));
}

/// Print `text` and a newline on stderr, wrapped to [`text_width`].
pub fn say_err(text: &str) {
    eprint!("{}", wrap(text, text_width()));
}

/// The line that says which columns [`fitted_table`] left out (empty when none).
pub fn dropped_note(dropped: &[String]) -> String {
    if dropped.is_empty() {
        String::new()
    } else {
        format!(
            "(left out at this width: {}; --wide shows every column)\n",
            dropped.join(", ")
        )
    }
}

/// A [`text_table`] that fits `width`: while it is too wide, the column of
/// the highest `priority` goes (ties: the rightmost). Returns the table and
/// the headers left out.
pub fn fitted_table(
    header: &[&str],
    rows: &[Vec<String>],
    priority: &[u8],
    width: Option<usize>,
) -> (String, Vec<String>) {
    let mut keep: Vec<usize> = (0..header.len()).collect();
    let table_of = |keep: &[usize]| {
        let h: Vec<&str> = keep.iter().map(|&c| header[c]).collect();
        let r: Vec<Vec<String>> = rows
            .iter()
            .map(|row| keep.iter().map(|&c| row[c].clone()).collect())
            .collect();
        text_table(&h, &r)
    };
    let widest = |t: &str| t.lines().map(|l| l.chars().count()).max().unwrap_or(0);
    let mut table = table_of(&keep);
    let mut dropped = Vec::new();
    if let Some(width) = width {
        while widest(&table) > width {
            let Some(at) = (0..keep.len())
                .filter(|&k| priority[keep[k]] > 0)
                .max_by_key(|&k| (priority[keep[k]], k))
            else {
                break;
            };
            dropped.push(header[keep[at]].replace('\n', " "));
            keep.remove(at);
            table = table_of(&keep);
        }
    }
    (table, dropped)
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

/// Right-aligned text table: a header (a "\n" in a header cell stacks
/// it on two lines, so that a narrow column keeps a narrow header), a rule,
/// then one line per row.
pub fn text_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let header_lines = header.iter().map(|h| h.lines().count()).max().unwrap_or(1);
    // Each header cell's lines, bottom-aligned.
    let stacked: Vec<Vec<&str>> = header
        .iter()
        .map(|h| {
            let lines: Vec<&str> = h.lines().collect();
            let mut cell = vec![""; header_lines - lines.len()];
            cell.extend(lines);
            cell
        })
        .collect();
    let mut widths: Vec<usize> = stacked
        .iter()
        .map(|c| c.iter().map(|l| l.chars().count()).max().unwrap_or(0))
        .collect();
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let line = |cells: Vec<&str>| {
        cells
            .iter()
            .zip(&widths)
            .map(|(c, w)| format!("{c:>w$}", w = *w))
            .collect::<Vec<_>>()
            .join("  ")
            .trim_end()
            .to_string()
    };
    let mut out = String::new();
    for l in 0..header_lines {
        out.push_str(&line(stacked.iter().map(|c| c[l]).collect()));
        out.push('\n');
    }
    out.push_str(&"-".repeat(widths.iter().sum::<usize>() + 2 * (widths.len() - 1)));
    out.push('\n');
    for row in rows {
        out.push_str(&line(row.iter().map(String::as_str).collect()));
        out.push('\n');
    }
    out
}

/// A p-value as printed: four decimals, or "< 0.0001" below what they show.
pub fn p_value_text(p: f64) -> String {
    if p < 1e-4 {
        "< 0.0001".to_string()
    } else {
        format!("{p:.4}")
    }
}

#[cfg(test)]
mod tests {
    use super::wrap;

    #[test]
    fn every_line_ends_in_a_newline_at_any_width() {
        let text = "finished: 8 runs, failures 0";
        assert_eq!(wrap(text, None), format!("{text}\n"));
        assert_eq!(wrap("a\n\nb\n", None), "a\n\nb\n");
        assert_eq!(wrap("one two three", Some(40)), "one two three\n");
    }
}
