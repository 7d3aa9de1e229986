//! The shared look of every figure (font, sizes, colours, log axes) and the
//! backend chosen from the file extension.

use super::{Format, PlotError};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::cell::RefCell;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Font family name every figure uses; it resolves to the embedded font.
pub const FONT: &str = "sans-serif";

/// A subset of DejaVu Sans (Latin, Greek, arrows, mathematical operators);
/// licence and the command that made it in `fonts/LICENSE-DejaVu.txt`.
static FONT_BYTES: &[u8] = include_bytes!("fonts/DejaVuSans-subset.ttf");

/// Figure title size (px).
pub const TITLE: u32 = 26;
/// Panel caption size (px).
pub const CAPTION: u32 = 20;
/// Axis description size (px).
pub const AXIS: u32 = 18;
/// Tick label and legend size (px).
pub const TICK: u32 = 15;

/// Okabe–Ito colours, told apart with every common colour-vision
/// deficiency, ordered for contrast on white; their yellow is left out, too
/// faint for thin lines.
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// The i-th palette colour, for things that are not one of many series
/// (a panel's own line, a threshold); series take [`series_style`].
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// How a line is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dash {
    /// Unbroken.
    Solid,
    /// Medium dashes.
    Dashed,
    /// Dots.
    Dotted,
    /// Long dashes.
    LongDash,
}

impl Dash {
    /// Dash and gap length in pixels, or `None` for a solid line.
    pub fn pattern(self) -> Option<(u32, u32)> {
        match self {
            Dash::Solid => None,
            Dash::Dashed => Some((8, 5)),
            Dash::Dotted => Some((2, 4)),
            Dash::LongDash => Some((18, 6)),
        }
    }
}

/// The mark drawn at points of a series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// No mark (lines only).
    None,
    /// A filled disc.
    Circle,
    /// A filled square.
    Square,
    /// A filled triangle, point up.
    Triangle,
    /// A filled diamond.
    Diamond,
    /// A filled × shape.
    Cross,
}

/// The look of one series: every figure takes it from [`series_style`] or
/// [`point_style`] so that no two series of a figure look alike.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SeriesStyle {
    /// Stroke and fill colour.
    pub colour: RGBColor,
    /// Line pattern (ignored for point series).
    pub dash: Dash,
    /// Mark at the points.
    pub marker: Marker,
}

const DASHES: [Dash; 4] = [Dash::Solid, Dash::Dashed, Dash::Dotted, Dash::LongDash];
const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::Triangle,
    Marker::Diamond,
    Marker::Cross,
];

/// The look of the i-th line series: the seven colours first, then again
/// with each marker, then all of those dashed, dotted and long-dashed, so
/// a figure's first 42 series differ in colour or marker alone (a dash is
/// hard to see in a short legend swatch) and its first 168 in some way.
pub fn series_style(i: usize) -> SeriesStyle {
    let n = PALETTE.len();
    let round = i / n;
    let marker = match round % (MARKERS.len() + 1) {
        0 => Marker::None,
        k => MARKERS[k - 1],
    };
    SeriesStyle {
        colour: PALETTE[i % n],
        dash: DASHES[(round / (MARKERS.len() + 1)) % DASHES.len()],
        marker,
    }
}

/// The look of the i-th outline (a box, no marks): the seven colours, then
/// again dashed, dotted and long-dashed; 28 different looks.
pub fn outline_style(i: usize) -> SeriesStyle {
    let n = PALETTE.len();
    SeriesStyle {
        colour: PALETTE[i % n],
        dash: DASHES[(i / n) % DASHES.len()],
        marker: Marker::None,
    }
}

/// The look of the i-th point series (scatter): the seven colours as discs,
/// then as squares, triangles, diamonds and crosses; 35 different looks.
pub fn point_style(i: usize) -> SeriesStyle {
    let n = PALETTE.len();
    SeriesStyle {
        colour: PALETTE[i % n],
        dash: Dash::Solid,
        marker: MARKERS[(i / n) % MARKERS.len()],
    }
}

/// Outline of a marker of radius `r` around the origin, in pixels; the
/// circle is a 16-gon so that every marker is one polygon.
fn marker_outline(marker: Marker, r: i32) -> Vec<(i32, i32)> {
    let rf = r as f64;
    let at = |a: f64, k: f64| ((k * a.cos()).round() as i32, (k * a.sin()).round() as i32);
    match marker {
        Marker::None => Vec::new(),
        Marker::Circle => (0..16)
            .map(|k| at(k as f64 * std::f64::consts::PI / 8.0, rf))
            .collect(),
        Marker::Square => {
            let s = (rf * 0.85).round() as i32;
            vec![(-s, -s), (s, -s), (s, s), (-s, s)]
        }
        Marker::Triangle => vec![(0, -r - 1), (r + 1, r - 1), (-r - 1, r - 1)],
        Marker::Diamond => vec![(0, -r - 1), (r, 0), (0, r + 1), (-r, 0)],
        Marker::Cross => {
            let (a, b) = (r, (rf * 0.35).round().max(1.0) as i32);
            vec![
                (-a, -a + b),
                (-a + b, -a),
                (0, -b),
                (a - b, -a),
                (a, -a + b),
                (b, 0),
                (a, a - b),
                (a - b, a),
                (0, b),
                (-a + b, a),
                (-a, a - b),
                (-b, 0),
            ]
        }
    }
}

/// A marker `r` pixels in radius, filled in `style`, as pixel offsets: add
/// it to `EmptyElement::at(point)` to place it.
pub fn marker(marker: Marker, r: i32, style: impl Into<ShapeStyle>) -> Polygon<(i32, i32)> {
    Polygon::new(marker_outline(marker, r), style)
}

/// Most markers drawn along one line: enough to name it, few enough not to
/// turn a dense curve into a band of symbols.
const MARKERS_PER_LINE: usize = 8;

/// Draw `points` as one line in `style` (its dash pattern, and its marker at
/// up to eight points spread along it), `width` pixels wide.
pub fn draw_line<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    points: &[(X::ValueType, Y::ValueType)],
    style: SeriesStyle,
    width: u32,
) -> Result<(), PlotError>
where
    DB: DrawingBackend,
    X: Ranged,
    Y: Ranged,
    X::ValueType: Clone + 'static,
    Y::ValueType: Clone + 'static,
{
    let stroke = style.colour.stroke_width(width);
    match style.dash.pattern() {
        None => {
            chart.draw_series(LineSeries::new(points.iter().cloned(), stroke))?;
        }
        Some((on, off)) => {
            chart.draw_series(DashedLineSeries::new(
                points.iter().cloned(),
                on as i32,
                off as i32,
                stroke,
            ))?;
        }
    }
    if style.marker != Marker::None && !points.is_empty() {
        let step = points.len().div_ceil(MARKERS_PER_LINE).max(1);
        // Offset by half a step so that lines sharing a start do not stack marks there.
        let first = (step / 2).min(points.len() - 1);
        chart.draw_series(points.iter().skip(first).step_by(step).map(|p| {
            EmptyElement::at(p.clone()) + marker(style.marker, 5, style.colour.filled())
        }))?;
    }
    Ok(())
}

/// Grey for reference lines (thresholds, markers).
pub const REFERENCE: RGBColor = RGBColor(90, 90, 90);

thread_local! {
    /// Series looks of the figure being drawn on this thread (legends and noted series).
    static LEGEND_STYLES: RefCell<Vec<(String, SeriesStyle)>> = const { RefCell::new(Vec::new()) };
}

/// The label and look of every series of the last figure rendered on this
/// thread (legend entries and directly labelled series), so that a test can
/// check that no two different series look alike.
pub fn legend_styles() -> Vec<(String, SeriesStyle)> {
    LEGEND_STYLES.with(|l| l.borrow().clone())
}

/// Note a series that is labelled on the plot rather than in a legend, so
/// that [`legend_styles`] sees it too.
pub fn note_series(label: impl Into<String>, look: SeriesStyle) {
    LEGEND_STYLES.with(|l| l.borrow_mut().push((label.into(), look)));
}

/// Register the embedded font with plotters once per process.
fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// A text style of the shared font at `size` pixels.
pub fn text(size: u32) -> TextStyle<'static> {
    (FONT, size).into_font().into()
}

/// Something that draws itself on any plotters backend.
pub trait Figure {
    /// Width and height in pixels.
    fn size(&self) -> (u32, u32);
    /// Draw on a white root area.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// Draw `figure` into `path` as SVG or PNG (by extension), atomically.
pub fn render(figure: &impl Figure, path: &Path) -> Result<(), PlotError> {
    let format = Format::from_path(path)?;
    let parent = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(PlotError::NoFolder(parent.display().to_string()));
    }
    ensure_font()?;
    LEGEND_STYLES.with(|l| l.borrow_mut().clear());
    let size = figure.size();
    match format {
        Format::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                root.fill(&WHITE)?;
                figure.draw(&root.margin(8, 4, 4, 4))?;
                root.present()?;
            }
            crate::study::io::write_text(path, &svg)?;
        }
        Format::Png => {
            // The encoder picks the format from the extension, so the
            // temporary file must end in .png too.
            let tmp = temp_png(path);
            let drawn = (|| {
                let root = BitMapBackend::new(&tmp, size).into_drawing_area();
                root.fill(&WHITE)?;
                figure.draw(&root.margin(8, 4, 4, 4))?;
                root.present()?;
                Ok::<(), PlotError>(())
            })();
            if let Err(e) = drawn {
                let _ = std::fs::remove_file(&tmp);
                return Err(e);
            }
            crate::study::io::move_into_place(&tmp, path)?;
        }
    }
    Ok(())
}

fn temp_png(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{stem}.tmp-{}.png", std::process::id()))
}

/// A linear f64 axis with ticks exactly where the caller says (categories,
/// whole numbers of weights, angles in quarter turns).
pub struct FixedTicks {
    inner: RangedCoordf64,
    ticks: Vec<f64>,
}

/// A linear axis over `range` with ticks at `ticks`.
pub fn fixed_ticks(range: Range<f64>, ticks: Vec<f64>) -> FixedTicks {
    FixedTicks {
        inner: range.into(),
        ticks,
    }
}

impl Ranged for FixedTicks {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, _hint: Hint) -> Vec<f64> {
        self.ticks.clone()
    }

    fn range(&self) -> Range<f64> {
        self.inner.range()
    }
}

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

/// The pixel rectangle (x0, y0, x1, y1) of a chart's plotting area.
pub fn plot_bounds<DB: DrawingBackend, X: Ranged, Y: Ranged>(
    chart: &ChartContext<'_, DB, Cartesian2d<X, Y>>,
) -> (i32, i32, i32, i32) {
    let area = chart.plotting_area();
    let (x, y) = area.get_base_pixel();
    let (w, h) = area.dim_in_pixel();
    (x, y, x + w as i32, y + h as i32)
}

/// Tick positions for a log axis over [lo, hi]: decades, with 2 and 5 added
/// when the range spans less than two decades.
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let (a, b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let step = ((b - a) / 8).max(1);
    let mut ticks: Vec<f64> = (a..=b)
        .filter(|k| (k - a) % step == 0)
        .map(|k| 10f64.powi(k))
        .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
        .collect();
    if ticks.len() < 3 {
        ticks = (a..=b)
            .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
            .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
            .collect();
    }
    ticks
}

/// Tick labels for a log axis over [lo, hi]: plain numbers when every tick
/// lies between 0.01 and 10 000, m×10ᵏ for all of them otherwise.
pub fn log_formatter(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let plain = lo >= 0.01 * (1.0 - 1e-9) && hi <= 1e4 * (1.0 + 1e-9);
    move |v: &f64| log_label(*v, plain)
}

fn log_label(v: f64, plain: bool) -> String {
    if !(v.is_finite() && v > 0.0) {
        return String::new();
    }
    let k = v.log10().floor() as i32;
    let mantissa = (v / 10f64.powi(k)).round() as i64;
    if plain {
        let digits = (-k).max(0) as usize;
        return format!("{v:.digits$}");
    }
    let power = format!("10{}", superscript(k));
    if mantissa == 1 {
        power
    } else {
        format!("{mantissa}×{power}")
    }
}

/// Tick labels of a linear axis over [lo, hi]: every label with the same
/// number of decimals, enough for ticks a tenth of the span apart, so that
/// one axis never mixes 0.001 and 5.00e-4.
pub fn fixed_decimals(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let span = (hi - lo).abs();
    let decimals = if span > 0.0 && span.is_finite() {
        (-(span / 10.0).log10().floor()).clamp(0.0, 9.0) as usize
    } else {
        2
    };
    move |v: &f64| format!("{v:.decimals$}")
}

/// The tick label of a linear axis: short numbers, no trailing zeros.
pub fn linear_label(v: &f64) -> String {
    if v.abs() < 1e-12 {
        "0".into()
    } else {
        short(*v)
    }
}

fn superscript(k: i32) -> String {
    k.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

/// A range [lo, hi] widened by `pad` of its span on each side (or ±pad·|lo|, or ±1, when flat).
pub fn padded(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    let span = hi - lo;
    let d = if span > 0.0 {
        span * pad
    } else if lo != 0.0 {
        lo.abs() * pad.max(0.05)
    } else {
        1.0
    };
    (lo - d, hi + d)
}

/// A log range around the positive finite values, widened by `factor` and
/// snapped outwards to 1, 2, 3 or 5 × 10ᵏ; at least one decade wide.
pub fn log_extent(values: impl IntoIterator<Item = f64>, factor: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values {
        if v.is_finite() && v > 0.0 {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if hi <= 0.0 {
        return None;
    }
    let (mut lo, mut hi) = (lo / factor, hi * factor);
    if hi / lo < 10.0 {
        let mid = (lo * hi).sqrt();
        (lo, hi) = (mid / 10f64.sqrt(), mid * 10f64.sqrt());
    }
    Some((snap(lo, false), snap(hi, true)))
}

/// The nearest 1, 2, 3 or 5 × 10ᵏ below (or above, with `up`) a positive value.
fn snap(v: f64, up: bool) -> f64 {
    let k = v.log10().floor();
    let base = 10f64.powf(k);
    let steps = [1.0, 2.0, 3.0, 5.0, 10.0];
    let m = v / base;
    let pick = if up {
        steps.iter().copied().find(|s| *s >= m * (1.0 - 1e-12))
    } else {
        steps
            .iter()
            .rev()
            .copied()
            .find(|s| *s <= m * (1.0 + 1e-12))
    };
    pick.unwrap_or(1.0) * base
}

/// The finite extent of some values, if any.
pub fn extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// A number with about three significant digits, without trailing noise.
pub fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let k = v.abs().log10().floor() as i32;
    if (-3..=4).contains(&k) {
        let digits = (2 - k).max(0) as usize;
        let s = format!("{v:.digits$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_are_decades_or_125() {
        assert_eq!(log_ticks(1e-4, 1.0), vec![1e-4, 1e-3, 1e-2, 1e-1, 1.0]);
        assert_eq!(log_ticks(3.0, 40.0), vec![5.0, 10.0, 20.0]);
    }

    #[test]
    fn series_looks_do_not_repeat() {
        let lines: Vec<SeriesStyle> = (0..168).map(series_style).collect();
        let points: Vec<SeriesStyle> = (0..35).map(point_style).collect();
        for looks in [lines, points] {
            for (i, a) in looks.iter().enumerate() {
                assert!(!looks[i + 1..].contains(a), "{i}: {a:?} repeats");
            }
        }
        // The first seven are the plain palette, as before.
        assert_eq!(series_style(3).colour, PALETTE[3]);
        assert_eq!(
            (series_style(3).dash, series_style(3).marker),
            (Dash::Solid, Marker::None)
        );
        // The next seven keep the line solid and add a marker: a colour and
        // marker tell the first 42 apart even in a short legend swatch.
        assert_eq!(
            (series_style(8).dash, series_style(8).marker),
            (Dash::Solid, Marker::Circle)
        );
        let marks: Vec<(RGBColor, Marker)> = (0..42)
            .map(|i| (series_style(i).colour, series_style(i).marker))
            .collect();
        for (i, a) in marks.iter().enumerate() {
            assert!(!marks[i + 1..].contains(a), "{i}: {a:?} repeats");
        }
        let outlines: Vec<SeriesStyle> = (0..28).map(outline_style).collect();
        for (i, a) in outlines.iter().enumerate() {
            assert!(!outlines[i + 1..].contains(a), "{i}: {a:?} repeats");
        }
    }

    #[test]
    fn decimals_are_the_same_along_an_axis() {
        let f = fixed_decimals(0.0, 0.003);
        assert_eq!((f(&0.0005), f(&0.002)), ("0.0005".into(), "0.0020".into()));
        assert_eq!(fixed_decimals(0.0, 500.0)(&50.0), "50");
    }

    #[test]
    fn labels_read_well() {
        let wide = log_formatter(1e-5, 10.0);
        assert_eq!(wide(&1e-5), "10⁻⁵");
        assert_eq!(wide(&2e-3), "2×10⁻³");
        let narrow = log_formatter(1.0, 5000.0);
        assert_eq!(narrow(&1000.0), "1000");
        assert_eq!(narrow(&2.0), "2");
        assert_eq!(log_extent([1.3, 2000.0], 1.1), Some((1.0, 3000.0)));
        assert_eq!(short(0.36380), "0.364");
        assert_eq!(short(20.0), "20");
        assert_eq!(short(1234.4), "1234");
    }
}
