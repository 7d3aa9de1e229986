//! The trade-off study's work–precision diagram: settling-time error against
//! cost (RHS calls and wall time), one line per fidelity through its
//! tolerances, each point the median error over the runs with a whisker up
//! to the largest.

use super::PlotError;
use super::style::{self, Figure, Swatch, TICK, draw_line, log_ticks, series_style, text};
use crate::stats::quantile::{Interpolation, quantile_sorted};
use crate::study::results::io::read_parquet;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use polars::prelude::*;
use std::path::Path;

/// One (fidelity, tolerance) point of the trade-off study.
#[derive(Debug, Clone, PartialEq)]
pub struct TradeoffPoint {
    /// Model or method fidelity, e.g. "dp5" or "reduced"; one line per value.
    pub fidelity: String,
    /// Relative tolerance of the solve.
    pub rtol: f64,
    /// Upper median of the settling-time errors against the reference over
    /// the runs (revolutions), as in the trade-off table.
    pub median_error_revs: f64,
    /// Largest settling-time error over the runs (revolutions): the figure a budget is checked against.
    pub max_error_revs: f64,
    /// Right-hand-side evaluations (the machine-independent cost).
    pub rhs_calls: f64,
    /// Wall-clock time (s).
    pub wall_time_s: f64,
}

/// Read trade-off points from a Parquet file.
///
/// Expected columns (any other column is ignored):
/// - `fidelity`: string
/// - `rtol`: float
/// - `settling_error_revs`: float, the settling-time error in revolutions (≥ 0)
/// - `rhs_calls`: integer or float
/// - `wall_time_s`: float, seconds
/// - `method` (optional): string; when present the series are "fidelity/method".
///
/// Rows without a settling error (the run's outcome differs from the
/// reference) and rows without integration cost (the `analytic` and `linear`
/// estimates, 0 RHS calls) have no place on a work–precision diagram and are left out.
pub fn read_tradeoff(path: &Path) -> Result<Vec<TradeoffPoint>, PlotError> {
    if !path.is_file() {
        return Err(PlotError::invalid(path.display().to_string(), "not found"));
    }
    let df = read_parquet(path).map_err(|e| PlotError::unreadable(path, e))?;
    let shown = path.display();
    let column = |name: &str| {
        df.column(name).map_err(|_| {
            PlotError::invalid(
                format!("{shown}"),
                format!("missing column '{name}' (expected fidelity, rtol, settling_error_revs, rhs_calls, wall_time_s)"),
            )
        })
    };
    let floats = |name: &str| -> Result<Vec<f64>, PlotError> {
        let c = column(name)?
            .cast(&DataType::Float64)
            .map_err(|e| PlotError::invalid(format!("{shown}: column '{name}'"), e.to_string()))?;
        c.f64()?
            .iter()
            .map(|v| {
                v.ok_or_else(|| {
                    PlotError::invalid(format!("{shown}: column '{name}'"), "null value")
                })
            })
            .collect()
    };
    let optional_floats = |name: &str| -> Result<Vec<Option<f64>>, PlotError> {
        let c = column(name)?
            .cast(&DataType::Float64)
            .map_err(|e| PlotError::invalid(format!("{shown}: column '{name}'"), e.to_string()))?;
        Ok(c.f64()?.iter().collect())
    };
    let method: Option<Vec<String>> = df.column("method").ok().and_then(|c| {
        c.str().ok().map(|s| {
            s.iter()
                .map(|v| v.unwrap_or_default().to_string())
                .collect()
        })
    });
    // Runs kept on Radau5 once handed over are a series of their own (a
    // table written before the column existed has none).
    let kept: Option<Vec<bool>> = df.column("return_when_dearer").ok().and_then(|c| {
        c.bool()
            .ok()
            .map(|b| b.iter().map(|v| v == Some(false)).collect())
    });
    let fidelity: Vec<String> = column("fidelity")?
        .str()
        .map_err(|_| PlotError::invalid(format!("{shown}: column 'fidelity'"), "must be text"))?
        .iter()
        .map(|v| v.unwrap_or_default().to_string())
        .collect();
    let (rtol, error, rhs, wall) = (
        floats("rtol")?,
        optional_floats("settling_error_revs")?,
        floats("rhs_calls")?,
        floats("wall_time_s")?,
    );
    let rows: Vec<TradeoffPoint> = (0..df.height())
        .filter(|&i| rhs[i] > 0.0)
        .filter_map(|i| {
            Some(TradeoffPoint {
                fidelity: match (&method, kept.as_ref().is_some_and(|k| k[i])) {
                    (Some(m), true) => format!("{}/{} kept on radau5", fidelity[i], m[i]),
                    (Some(m), false) => format!("{}/{}", fidelity[i], m[i]),
                    (None, _) => fidelity[i].clone(),
                },
                rtol: rtol[i],
                median_error_revs: error[i]?,
                max_error_revs: error[i]?,
                rhs_calls: rhs[i],
                wall_time_s: wall[i],
            })
        })
        .collect();
    Ok(aggregate(rows))
}

/// One point per series and tolerance at the mean cost: the upper median of
/// the runs' errors (as the trade-off table reports it) and the largest (the
/// figure a budget is checked against). Tables with one row per setting pass
/// through unchanged.
fn aggregate(rows: Vec<TradeoffPoint>) -> Vec<TradeoffPoint> {
    let mut out: Vec<(TradeoffPoint, Vec<f64>)> = Vec::new();
    for r in rows {
        match out
            .iter_mut()
            .find(|(p, _)| p.fidelity == r.fidelity && p.rtol == r.rtol)
        {
            Some((p, errors)) => {
                errors.push(r.max_error_revs);
                p.rhs_calls += r.rhs_calls;
                p.wall_time_s += r.wall_time_s;
            }
            None => {
                let first = r.max_error_revs;
                out.push((r, vec![first]));
            }
        }
    }
    out.into_iter()
        .map(|(mut p, mut errors)| {
            if errors.len() > 1 {
                errors.sort_by(f64::total_cmp);
                p.median_error_revs = quantile_sorted(&errors, 0.5, Interpolation::Higher)
                    .unwrap_or(p.max_error_revs);
                p.max_error_revs = errors[errors.len() - 1];
            }
            let n = errors.len() as f64;
            p.rhs_calls /= n;
            p.wall_time_s /= n;
            p
        })
        .collect()
}

/// How to read a point (written under its legend).
const READING: &str = "marker: median |Δt_s| over the measured runs, on the line; whisker: up to the largest (what a budget is checked against)";

/// What the figure does not show, and why (written under its legend).
const LEFT_OUT: &str = "not shown: the analytic and linear rungs (no RHS calls: no place on a log cost axis) and runs whose outcome differs from the reference's";

/// The work–precision figure: error vs RHS calls and error vs wall time.
struct WorkPrecision<'a> {
    points: &'a [TradeoffPoint],
    fidelities: Vec<String>,
    title: &'a str,
}

/// Write the work–precision diagram of `points` to `path` (.svg or .png).
///
/// Errors of exactly zero cannot sit on a log axis: they are drawn as open
/// markers on the axis floor.
pub fn plot_work_precision(
    points: &[TradeoffPoint],
    title: &str,
    path: &Path,
) -> Result<(), PlotError> {
    if points.is_empty() {
        return Err(PlotError::NoData("the trade-off table has no rows".into()));
    }
    for p in points {
        let bad = |v: f64| !v.is_finite() || v < 0.0;
        if bad(p.median_error_revs)
            || bad(p.max_error_revs)
            || bad(p.wall_time_s)
            || bad(p.rhs_calls)
            || p.rhs_calls == 0.0
        {
            return Err(PlotError::invalid(
                format!("{} at rtol {}", p.fidelity, p.rtol),
                "errors and wall time must be finite and ≥ 0, RHS calls > 0",
            ));
        }
        if p.median_error_revs > p.max_error_revs {
            return Err(PlotError::invalid(
                format!("{} at rtol {}", p.fidelity, p.rtol),
                "the median error exceeds the largest",
            ));
        }
    }
    if !points.iter().any(|p| p.max_error_revs > 0.0) {
        return Err(PlotError::NoData(
            "every error is zero: nothing to show on a log axis".into(),
        ));
    }
    let mut fidelities: Vec<String> = Vec::new();
    for p in points {
        if !fidelities.contains(&p.fidelity) {
            fidelities.push(p.fidelity.clone());
        }
    }
    style::render(
        &WorkPrecision {
            points,
            fidelities,
            title,
        },
        path,
    )
}

impl Figure for WorkPrecision<'_> {
    fn size(&self) -> (u32, u32) {
        (1300, 620)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let body = style::titled(root, self.title)?;
        let mut entries: Vec<(String, Swatch)> = self
            .fidelities
            .iter()
            .enumerate()
            .map(|(k, f)| (f.clone(), Swatch::Series(series_style(k))))
            .collect();
        if self.points.iter().any(|p| p.median_error_revs == 0.0) {
            entries.push(("error 0 (drawn on the floor)".into(), Swatch::Ring(BLACK)));
        }
        let body = style::legend(&body, &entries)?;
        // read_tradeoff drops them before the figure sees them: say so, so
        // that a reader does not take their absence for a missing result.
        let body = style::text_block(&body, READING, TICK)?;
        let body = style::text_block(&body, LEFT_OUT, TICK)?;
        let panels = body.split_evenly((1, 2));
        self.panel(
            &panels[0],
            "cost in RHS evaluations",
            "RHS calls  (count, log scale)",
            |p| p.rhs_calls,
        )?;
        self.panel(
            &panels[1],
            "cost in wall-clock time",
            "wall time  (s, log scale)",
            |p| p.wall_time_s,
        )?;
        Ok(())
    }
}

impl WorkPrecision<'_> {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        caption: &str,
        x_desc: &str,
        cost: impl Fn(&TradeoffPoint) -> f64,
    ) -> Result<(), PlotError> {
        let (x_lo, x_hi) = style::log_extent(self.points.iter().map(&cost), 1.1)
            .ok_or_else(|| PlotError::NoData(format!("{caption}: no positive cost")))?;
        let errors = || {
            self.points
                .iter()
                .flat_map(|p| [p.median_error_revs, p.max_error_revs])
        };
        let smallest = errors().filter(|e| *e > 0.0).fold(f64::INFINITY, f64::min);
        // Zero errors get a floor a factor of four below the smallest real one.
        let floor = smallest / 4.0;
        let with_floor = errors().chain(errors().any(|e| e == 0.0).then_some(floor));
        let (y_lo, y_hi) = style::log_extent(with_floor, 1.3)
            .ok_or_else(|| PlotError::NoData("no positive error".into()))?;
        let area = style::panel_header(area, &format!("Error vs {caption} (labels: rtol)"), &[])?;
        let mut chart = ChartBuilder::on(&area)
            .margin(14)
            .margin_top(4)
            // Room for half the last x tick label, which is centred on the axis end.
            .margin_right(30)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d(
                (x_lo..x_hi)
                    .log_scale()
                    .with_key_points(log_ticks(x_lo, x_hi)),
                (y_lo..y_hi)
                    .log_scale()
                    .with_key_points(log_ticks(y_lo, y_hi)),
            )?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc("|Δt_s| over the measured runs  (rev, log scale)")
            .axis_desc_style(text(style::AXIS))
            .label_style(text(TICK))
            .x_label_formatter(&style::log_formatter(x_lo, x_hi))
            .y_label_formatter(&style::log_formatter(y_lo, y_hi))
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .draw()?;
        let mut placer = style::LabelPlacer::new();
        let bounds = style::plot_bounds(&chart);
        let label_style = text(TICK - 3);
        let mut labels = Vec::new();
        for (k, fidelity) in self.fidelities.iter().enumerate() {
            let look = series_style(k);
            let c = look.colour;
            let mut mine: Vec<&TradeoffPoint> = self
                .points
                .iter()
                .filter(|p| &p.fidelity == fidelity)
                .collect();
            // Loose to tight tolerance: the line walks towards higher cost.
            mine.sort_by(|a, b| b.rtol.total_cmp(&a.rtol));
            let xy = |p: &TradeoffPoint| (cost(p).max(x_lo), p.median_error_revs.max(floor));
            let line: Vec<(f64, f64)> = mine.iter().map(|p| xy(p)).collect();
            // Every point is marked here, so the line itself carries no markers.
            let plain = style::SeriesStyle {
                marker: style::Marker::None,
                ..look
            };
            draw_line(&mut chart, &line, plain, 2)?;
            let marker = match look.marker {
                style::Marker::None => style::Marker::Circle,
                m => m,
            };
            for p in &mine {
                let (x, median) = xy(p);
                if p.max_error_revs > median {
                    let top = p.max_error_revs;
                    chart.draw_series([PathElement::new(
                        vec![(x, median), (x, top)],
                        c.stroke_width(1),
                    )])?;
                    chart.draw_series([EmptyElement::at((x, top))
                        + PathElement::new(vec![(-4, 0), (4, 0)], c.stroke_width(1))])?;
                    // No rtol label may cover a whisker either.
                    let (low, high) = (
                        chart.backend_coord(&(x, median)),
                        chart.backend_coord(&(x, top)),
                    );
                    placer.reserve((high.0 - 4, high.1 - 1, high.0 + 4, low.1));
                }
                if p.median_error_revs > 0.0 {
                    chart.draw_series([
                        EmptyElement::at(xy(p)) + style::marker(marker, 5, c.filled())
                    ])?;
                } else {
                    chart.draw_series([EmptyElement::at(xy(p))
                        + Circle::new((0, 0), 5, WHITE.filled())
                        + Circle::new((0, 0), 5, c.stroke_width(2))])?;
                }
                let at = chart.backend_coord(&xy(p));
                placer.reserve((at.0 - 6, at.1 - 6, at.0 + 6, at.1 + 6));
                labels.push((xy(p), at, format!("{:.0e}", p.rtol)));
            }
        }
        // Labels after every marker is known, so that none covers a marker.
        for (point, at, label) in labels {
            let size = area.estimate_text_size(&label, &label_style)?;
            if let Some(offset) = placer.place(at, size, bounds) {
                chart.draw_series([EmptyElement::at(point)
                    + Text::new(
                        label,
                        offset,
                        label_style.pos(Pos::new(HPos::Left, VPos::Top)),
                    )])?;
            }
        }
        Ok(())
    }
}
