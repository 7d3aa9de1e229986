//! Decisions and tables as plain text, for a terminal or a file: aligned
//! tables that give up columns to fit a width, wrapping at words, and the
//! ranking of a study's summary ([`ranking`]). The library prints nothing;
//! its callers say how wide and how terse ([`Layout`]).

pub mod ranking;

/// How wide the text may run and how terse it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Columns text may fill; `None` for no limit.
    pub width: Option<usize>,
    /// Keep the exact terms and symbols (τ, 2α) that the default says in words.
    pub wide: bool,
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
