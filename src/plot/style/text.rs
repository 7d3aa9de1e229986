//! Text on a figure: widths, wrapping, blocks, titles, panel headers and
//! labels placed where they do not collide.

use super::*;

/// Width of `text` in pixels: the font's measure, but no less than 0.49 em
/// a character, since SVG viewers substitute their own sans-serif and the
/// layout test allows 0.6 of the SVG's font size (the size / 1.24) each.
pub fn text_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle,
) -> Result<i32, PlotError> {
    let (w, _) = area.estimate_text_size(text, style)?;
    let floor = 0.49 * style.font.get_size() * text.chars().count() as f64;
    Ok((w as i32).max(floor.ceil() as i32))
}

/// `words` broken into lines of at most `max` pixels in `style`.
pub fn wrap<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    words: &str,
    style: &TextStyle,
    max: i32,
) -> Result<Vec<String>, PlotError> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in words.split(' ').filter(|w| !w.is_empty()) {
        let candidate = if line.is_empty() {
            word.to_string()
        } else {
            format!("{line} {word}")
        };
        if text_width(area, &candidate, style)? <= max || line.is_empty() {
            line = candidate;
        } else {
            lines.push(std::mem::replace(&mut line, word.to_string()));
        }
    }
    if !line.is_empty() {
        lines.push(line);
    }
    Ok(lines)
}

/// Centred text at the top of `area`, wrapped to its width; returns the
/// area below. Long captions wrap instead of running off the figure.
pub fn text_block<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    words: &str,
    size: u32,
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    let style = text(size);
    let (w, _) = area.dim_in_pixel();
    let lines = wrap(area, words, &style, w as i32 - 16)?;
    let line_height = (size as i32 * 13) / 10;
    let (head, rest) = area.split_vertically(line_height * lines.len() as i32 + 8);
    for (k, line) in lines.into_iter().enumerate() {
        head.draw(&Text::new(
            line,
            (w as i32 / 2, 4 + k as i32 * line_height),
            style.pos(Pos::new(HPos::Center, VPos::Top)),
        ))?;
    }
    Ok(rest)
}

/// The figure's title across the top of `root`, wrapped when it is wider
/// than the figure; returns the area below.
pub fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    text_block(root, title, TITLE)
}

/// A panel's caption and, when given, its legend beneath; returns the area
/// left for the chart. Keeping legends out of the plotting area means they
/// never hide data.
pub fn panel_header<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    legend_entries: &[(String, Swatch)],
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    let rest = text_block(area, caption, CAPTION)?;
    legend(&rest, legend_entries)
}

/// Puts short labels beside points where they cover no other label: each
/// label tries four spots around its point and is left out when none is free,
/// so crowded series lose labels instead of printing them over each other.
#[derive(Debug, Default)]
pub struct LabelPlacer {
    taken: Vec<(i32, i32, i32, i32)>,
    left_first: bool,
}

impl LabelPlacer {
    /// A placer with nothing placed yet that tries right of a point first
    /// (for lines that fall to the right, like work–precision curves).
    pub fn new() -> Self {
        Self::default()
    }

    /// A placer that tries up-left of a point first (for labelled peaks,
    /// where the curve falls away on the right).
    pub fn left_first() -> Self {
        LabelPlacer {
            left_first: true,
            ..Self::default()
        }
    }

    /// Mark a pixel rectangle (x0, y0, x1, y1) as taken.
    pub fn reserve(&mut self, rect: (i32, i32, i32, i32)) {
        self.taken.push(rect);
    }

    /// The offset from `at` (backend pixels) of the top-left corner of a free
    /// `size` box that lies within `bounds`, now taken; `None` when no spot is free.
    pub fn place(
        &mut self,
        at: (i32, i32),
        size: (u32, u32),
        bounds: (i32, i32, i32, i32),
    ) -> Option<(i32, i32)> {
        let (w, h) = (size.0 as i32, size.1 as i32);
        let gap = 6;
        let mut offsets = [(gap, -h - 2), (gap, 2), (-w - gap, -h - 2), (-w - gap, 2)];
        if self.left_first {
            offsets = [offsets[2], offsets[0], offsets[3], offsets[1]];
        }
        for (dx, dy) in offsets {
            let r = (at.0 + dx, at.1 + dy, at.0 + dx + w, at.1 + dy + h);
            let inside = r.0 >= bounds.0 && r.1 >= bounds.1 && r.2 <= bounds.2 && r.3 <= bounds.3;
            let free = self
                .taken
                .iter()
                .all(|t| r.2 <= t.0 || t.2 <= r.0 || r.3 <= t.1 || t.3 <= r.1);
            if inside && free {
                self.taken.push(r);
                return Some((dx, dy));
            }
        }
        None
    }
}
