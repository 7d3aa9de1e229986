//! The legend: a swatch per series, laid out in rows that fit the figure,
//! labels shortened to the space they have.

use super::*;

/// The symbol of a legend entry.
#[derive(Debug, Clone, Copy)]
pub enum Swatch {
    /// A line segment in a series' look (dash pattern and marker).
    Series(SeriesStyle),
    /// A series' marker alone (scatter plots).
    Point(SeriesStyle),
    /// A filled dot (not a series: a kind of mark).
    Dot(RGBColor),
    /// A cross (×).
    Cross(RGBColor),
    /// An open circle.
    Ring(RGBColor),
    /// A dashed line segment.
    Dashed(RGBColor),
    /// A shaded band, as translucent areas are drawn.
    Band(RGBColor),
    /// A solid block, as opaque areas (map cells) are drawn.
    Fill(RGBColor),
}

/// Swatch width, gap to its label, gap between entries, and row height (px).
const SWATCH: i32 = 28;
const SWATCH_PAD: i32 = 6;
const ENTRY_GAP: i32 = 24;
const LEGEND_ROW: i32 = 22;

fn draw_swatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    kind: Swatch,
) -> Result<(), PlotError> {
    let centre = (x + SWATCH / 2, y);
    let dashes = |area: &DrawingArea<DB, Shift>, c: RGBColor, on: i32, off: i32| {
        let mut dx = 0;
        while dx < SWATCH {
            let end = (dx + on).min(SWATCH);
            area.draw(&PathElement::new(
                vec![(x + dx, y), (x + end, y)],
                c.stroke_width(2),
            ))?;
            dx += on + off;
        }
        Ok::<(), PlotError>(())
    };
    match kind {
        Swatch::Series(s) => {
            match s.dash.pattern() {
                None => area.draw(&PathElement::new(
                    vec![(x, y), (x + SWATCH, y)],
                    s.colour.stroke_width(2),
                ))?,
                Some((on, off)) => dashes(area, s.colour, on as i32, off as i32)?,
            }
            if s.marker != Marker::None {
                area.draw(&(EmptyElement::at(centre) + marker(s.marker, 5, s.colour.filled())))?;
            }
        }
        Swatch::Point(s) => {
            area.draw(&(EmptyElement::at(centre) + marker(s.marker, 5, s.colour.filled())))?
        }
        Swatch::Dot(c) => area.draw(&Circle::new(centre, 5, c.filled()))?,
        Swatch::Cross(c) => area.draw(&Cross::new(centre, 5, c.stroke_width(2)))?,
        Swatch::Ring(c) => area.draw(&Circle::new(centre, 5, c.stroke_width(2)))?,
        Swatch::Dashed(c) => dashes(area, c, 8, 5)?,
        Swatch::Band(c) => area.draw(&Rectangle::new(
            [(x, y - 7), (x + SWATCH, y + 7)],
            c.mix(0.25).filled(),
        ))?,
        Swatch::Fill(c) => {
            area.draw(&Rectangle::new(
                [(x, y - 7), (x + SWATCH, y + 7)],
                c.filled(),
            ))?;
            // An outline, so that a pale block still reads on white.
            area.draw(&Rectangle::new(
                [(x, y - 7), (x + SWATCH, y + 7)],
                RGBColor(120, 120, 120).stroke_width(1),
            ))?;
        }
    }
    Ok(())
}

/// The label shortened with "…" until it is at most `max` pixels wide.
fn fit_label<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    label: &str,
    style: &TextStyle,
    max: i32,
) -> Result<(String, i32), PlotError> {
    let width = |t: &str| text_width(area, t, style);
    let full = width(label)?;
    if full <= max {
        return Ok((label.to_string(), full));
    }
    let mut chars: Vec<char> = label.chars().collect();
    while !chars.is_empty() {
        chars.pop();
        let t: String = chars.iter().collect::<String>() + "…";
        let w = width(&t)?;
        if w <= max {
            return Ok((t, w));
        }
    }
    Ok(("…".into(), width("…")?))
}

/// (label, width) per entry, the column width (0 for a single row) and the
/// number of rows.
type LegendLayout = (Vec<(String, i32)>, i32, usize);

/// How the entries of a legend sit across `area`: one centred row when they
/// fit, else a grid of equal columns (labels too wide for the figure are
/// shortened).
fn legend_layout<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Swatch)],
) -> Result<LegendLayout, PlotError> {
    let style = text(TICK);
    let width = area.dim_in_pixel().0 as i32 - 8;
    let max_label = width - SWATCH - SWATCH_PAD;
    let labels = entries
        .iter()
        .map(|(t, _)| fit_label(area, t, &style, max_label))
        .collect::<Result<Vec<_>, _>>()?;
    let item = |w: i32| SWATCH + SWATCH_PAD + w;
    let count = labels.len() as i32;
    let row: i32 =
        labels.iter().map(|(_, w)| item(*w)).sum::<i32>() + ENTRY_GAP * (count - 1).max(0);
    if row <= width {
        return Ok((labels, 0, 1));
    }
    let column = labels.iter().map(|(_, w)| item(*w)).max().unwrap_or(0) + ENTRY_GAP;
    let columns = ((width + ENTRY_GAP) / column).max(1) as usize;
    let rows = labels.len().div_ceil(columns);
    Ok((labels, column, rows))
}

/// Draw a legend across the top of `area`, one row or a grid of columns as
/// the width allows; returns the area below it. Legends stay out of the
/// plotting area, so they never hide data or run off the figure.
pub fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Swatch)],
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    if entries.is_empty() {
        return Ok(area.clone());
    }
    let (labels, column, rows) = legend_layout(area, entries)?;
    let (strip, rest) = area.split_vertically(rows as i32 * LEGEND_ROW + 8);
    let style = text(TICK);
    let (w, _) = strip.dim_in_pixel();
    let item = |w: i32| SWATCH + SWATCH_PAD + w;
    // Each row's entries as (x, y, index).
    let mut places = Vec::with_capacity(entries.len());
    if column == 0 {
        let total = labels.iter().map(|(_, w)| item(*w)).sum::<i32>()
            + ENTRY_GAP * (labels.len() as i32 - 1).max(0);
        let mut x = ((w as i32) - total).max(0) / 2;
        for (i, (_, lw)) in labels.iter().enumerate() {
            places.push((x, 4 + LEGEND_ROW / 2, i));
            x += item(*lw) + ENTRY_GAP;
        }
    } else {
        let columns = labels.len().div_ceil(rows);
        let used = columns as i32 * column - ENTRY_GAP;
        let left = ((w as i32) - used).max(0) / 2;
        // Column-major, so that a sorted list of series reads down the columns.
        for i in 0..labels.len() {
            let (c, r) = (i / rows, i % rows);
            places.push((
                left + c as i32 * column,
                4 + LEGEND_ROW / 2 + r as i32 * LEGEND_ROW,
                i,
            ));
        }
    }
    for (x, y, i) in places {
        let kind = entries[i].1;
        draw_swatch(&strip, (x, y), kind)?;
        strip.draw(&Text::new(
            labels[i].0.clone(),
            (x + SWATCH + SWATCH_PAD, y),
            style.pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        if let Swatch::Series(s) | Swatch::Point(s) = kind {
            note_series(entries[i].0.clone(), s);
        }
    }
    Ok(rest)
}
