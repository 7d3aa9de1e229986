//! The shared look of every figure (font, sizes, colours, log axes) and the
//! backend chosen from the file extension.

use super::{Format, PlotError};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;
use plotters::style::text_anchor::{HPos, Pos, VPos};
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

/// Okabe–Ito colours ordered for contrast on white, with brown for their
/// yellow, which is too faint for thin lines.
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(140, 86, 75),
];

/// The i-th categorical colour (the palette repeats after eight).
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Grey for reference lines (thresholds, markers).
pub const REFERENCE: RGBColor = RGBColor(90, 90, 90);

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
    /// A line segment.
    Line(RGBColor),
    /// A filled dot.
    Dot(RGBColor),
    /// A cross (×).
    Cross(RGBColor),
    /// An open circle.
    Ring(RGBColor),
    /// A dashed line segment.
    Dashed(RGBColor),
    /// A shaded band.
    Band(RGBColor),
}

/// Legend entries in one centred row across `area`, for figures whose panels
/// share one legend (inside a panel it would hide data).
pub fn legend_row<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Swatch)],
) -> Result<(), PlotError> {
    let style = text(TICK);
    let (swatch, pad, gap) = (22, 6, 26);
    let widths = entries
        .iter()
        .map(|(t, _)| area.estimate_text_size(t, &style).map(|(w, _)| w as i32))
        .collect::<Result<Vec<_>, _>>()?;
    let count = entries.len() as i32;
    let total = widths.iter().sum::<i32>() + count * (swatch + pad) + gap * (count - 1).max(0);
    let (w, h) = area.dim_in_pixel();
    let (mut x, y) = (((w as i32) - total).max(0) / 2, h as i32 / 2);
    for ((label, kind), width) in entries.iter().zip(widths) {
        let centre = (x + swatch / 2, y);
        match *kind {
            Swatch::Line(c) => area.draw(&PathElement::new(
                vec![(x, y), (x + swatch, y)],
                c.stroke_width(2),
            ))?,
            Swatch::Dot(c) => area.draw(&Circle::new(centre, 5, c.filled()))?,
            Swatch::Cross(c) => area.draw(&Cross::new(centre, 5, c.stroke_width(2)))?,
            Swatch::Ring(c) => area.draw(&Circle::new(centre, 5, c.stroke_width(2)))?,
            Swatch::Dashed(c) => {
                for dx in [0, 9, 18] {
                    let end = (dx + 5).min(swatch);
                    area.draw(&PathElement::new(
                        vec![(x + dx, y), (x + end, y)],
                        c.stroke_width(2),
                    ))?;
                }
            }
            Swatch::Band(c) => area.draw(&Rectangle::new(
                [(x, y - 7), (x + swatch, y + 7)],
                c.mix(0.25).filled(),
            ))?,
        }
        area.draw(&Text::new(
            label.clone(),
            (x + swatch + pad, y),
            style.pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        x += swatch + pad + width + gap;
    }
    Ok(())
}

/// A panel's caption and, when given, its legend in a row beneath; returns
/// the area left for the chart. Keeping legends out of the plotting area
/// means they never hide data.
pub fn panel_header<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    legend: &[(String, Swatch)],
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    let height = if legend.is_empty() { 34 } else { 64 };
    let (head, rest) = area.split_vertically(height);
    let (w, _) = head.dim_in_pixel();
    head.draw(&Text::new(
        caption.to_string(),
        (w as i32 / 2, 6),
        text(CAPTION).pos(Pos::new(HPos::Center, VPos::Top)),
    ))?;
    if !legend.is_empty() {
        let (_, strip) = head.split_vertically(32);
        legend_row(&strip, legend)?;
    }
    Ok(rest)
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
