//! Axes: fixed and logarithmic ticks, their labels, and the extents and
//! padding of a plotted range.

use super::*;

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
