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

mod axes;
mod legend;
mod text;

pub use axes::*;
pub use legend::*;
pub use text::*;

/// Font family name every figure uses; it resolves to the embedded font.
pub const FONT: &str = "sans-serif";

/// A subset of DejaVu Sans (Latin, Greek, arrows, mathematical operators);
/// licence and the command that made it in `fonts/LICENSE-DejaVu.txt`.
static FONT_BYTES: &[u8] = include_bytes!("../fonts/DejaVuSans-subset.ttf");

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
            crate::study::results::io::write_text(path, &svg)?;
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
            crate::study::results::io::move_into_place(&tmp, path)?;
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
