//! One run in three panels: r(t)/A_ref on a log scale with δ and t_s marked,
//! the cargo angles relative to the rotor, and the balancing error ε(t).

use super::PlotError;
use super::decimate::min_max;
use super::style::{
    self, Figure, Swatch, TICK, colour, draw_line, linear_label, log_ticks, series_style, text,
};
use crate::metrics::RunMetrics;
use crate::metrics::observer::Series;
use crate::simulation::{RunResult, Simulation};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::f64::consts::PI;
use std::path::Path;

/// Points per line after thinning: enough for a 1000-pixel-wide panel.
const MAX_POINTS: usize = 3000;

/// Everything the run figure shows.
#[derive(Debug, Clone, Copy)]
pub struct RunFigure<'a> {
    /// The sampled time history.
    pub series: &'a Series,
    /// The run's metrics (A_ref, t_s, t_s(ε), outcome).
    pub metrics: &'a RunMetrics,
    /// One revolution 2π/ω at the nominal speed (s): the time unit of the axes.
    pub revolution_s: f64,
    /// Settling band δ (fraction of A_ref, and of U for ε).
    pub delta: f64,
    /// Hold window W (revolutions).
    pub hold_revs: f64,
    /// Figure title.
    pub title: &'a str,
}

impl<'a> RunFigure<'a> {
    /// The figure of a run made by `simulation.run(true)`; errors when no series was recorded.
    pub fn new(
        simulation: &Simulation,
        result: &'a RunResult,
        title: &'a str,
    ) -> Result<Self, PlotError> {
        let series = result.series.as_ref().ok_or_else(|| {
            PlotError::NoData("the run was simulated without recording its series".into())
        })?;
        Ok(RunFigure {
            series,
            metrics: &result.metrics,
            revolution_s: 2.0 * PI / simulation.scene.speed.nominal_speed(),
            delta: simulation.metrics.delta,
            hold_revs: simulation.metrics.hold_revs,
            title,
        })
    }

    fn check(&self) -> Result<(), PlotError> {
        let s = self.series;
        if s.t.is_empty() {
            return Err(PlotError::NoData("the run's series has no samples".into()));
        }
        let n = s.t.len();
        if s.r.len() != n || s.eps.len() != n || s.psi.iter().any(|p| p.len() != n) {
            return Err(PlotError::invalid(
                "series",
                "t, r, ε and every ψ_j must have the same length",
            ));
        }
        for (what, v) in [
            ("revolution_s", self.revolution_s),
            ("delta", self.delta),
            ("A_ref", self.metrics.a_ref),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlotError::invalid(what, format!("{v} is not positive")));
            }
        }
        Ok(())
    }

    fn revs(&self, t: f64) -> f64 {
        t / self.revolution_s
    }
}

/// Write the three-panel figure of one run to `path` (.svg or .png).
pub fn plot_run(figure: &RunFigure, path: &Path) -> Result<(), PlotError> {
    figure.check()?;
    style::render(figure, path)
}

impl Figure for RunFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1100, 1200)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let body = style::titled(root, self.title)?;
        let panels = body.split_evenly((3, 1));
        let t_revs: Vec<f64> = self.series.t.iter().map(|&t| self.revs(t)).collect();
        let t_end = t_revs.last().copied().unwrap_or(1.0).max(1e-9);
        self.draw_amplitude(&panels[0], &t_revs, t_end)?;
        self.draw_angles(&panels[1], &t_revs, t_end)?;
        self.draw_error(&panels[2], &t_revs, t_end)?;
        Ok(())
    }
}

impl RunFigure<'_> {
    fn draw_amplitude<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        t: &[f64],
        t_end: f64,
    ) -> Result<(), PlotError> {
        let a_ref = self.metrics.a_ref;
        let rel: Vec<f64> = self.series.r.iter().map(|r| r / a_ref).collect();
        let ts = self.metrics.settling_time.map(|t| self.revs(t));
        // Scenes may be dimensionless, so A_ref is shown in the scene's own length unit.
        let a = style::short(a_ref);
        let caption = match ts {
            Some(ts) => format!(
                "Shaft amplitude r (A_ref = {a}): settles at t_s = {} rev",
                style::short(ts)
            ),
            None => format!("Shaft amplitude r (A_ref = {a}): did not settle"),
        };
        log_panel(
            area,
            LogPanel {
                caption: &caption,
                y_desc: "r / A_ref  (–, log scale)",
                t,
                t_end,
                y: &rel,
                line_label: "r / A_ref",
                look: 0,
                delta: self.delta,
                mark: ts,
                mark_label: "t_s (settling time)",
                hold_revs: self.hold_revs,
            },
        )
    }

    fn draw_error<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        t: &[f64],
        t_end: f64,
    ) -> Result<(), PlotError> {
        let ts = self.metrics.settling_time_eps.map(|t| self.revs(t));
        let caption = match ts {
            Some(ts) => format!("Balancing error ε: below δ from {} rev", style::short(ts)),
            None => "Balancing error ε: never held below δ".to_string(),
        };
        log_panel(
            area,
            LogPanel {
                caption: &caption,
                y_desc: "ε  (–, log scale)",
                t,
                t_end,
                y: &self.series.eps,
                line_label: "ε",
                look: 1,
                delta: self.delta,
                mark: ts,
                mark_label: "t_s(ε)",
                hold_revs: self.hold_revs,
            },
        )
    }

    fn draw_angles<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        t: &[f64],
        t_end: f64,
    ) -> Result<(), PlotError> {
        let legend: Vec<(String, Swatch)> = (0..self.series.psi.len())
            .map(|j| (format!("cargo {}", j + 1), Swatch::Series(cargo_style(j))))
            .collect();
        let area = style::panel_header(area, "Cargo angles ψ_j relative to the rotor", &legend)?;
        let mut chart = ChartBuilder::on(&area)
            .margin(12)
            .margin_top(4)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d(
                0f64..t_end,
                style::fixed_ticks(0.0..360.0, vec![0.0, 90.0, 180.0, 270.0, 360.0]),
            )?;
        chart
            .configure_mesh()
            .x_desc("time t  (revolutions)")
            .y_desc("ψ_j  (degrees)")
            .axis_desc_style(text(style::AXIS))
            .label_style(text(TICK))
            .x_label_formatter(&linear_label)
            .y_label_formatter(&|v| format!("{v:.0}°"))
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        for (j, psi) in self.series.psi.iter().enumerate() {
            let deg: Vec<f64> = unwrap_degrees(psi);
            let thin = min_max(t, &deg, MAX_POINTS);
            for segment in wrap_segments(&thin) {
                draw_line(&mut chart, &segment, cargo_style(j), 2)?;
            }
        }
        Ok(())
    }
}

/// The look of cargo j: the series after r/A_ref's and ε's, so that no two
/// lines of the figure look alike.
fn cargo_style(j: usize) -> style::SeriesStyle {
    series_style(j + 2)
}

/// Inputs of one log-scale time panel with a δ band and a settling mark.
struct LogPanel<'a> {
    caption: &'a str,
    y_desc: &'a str,
    t: &'a [f64],
    t_end: f64,
    y: &'a [f64],
    line_label: &'a str,
    /// Index of the line's look in [`series_style`].
    look: usize,
    delta: f64,
    mark: Option<f64>,
    mark_label: &'a str,
    hold_revs: f64,
}

fn log_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: LogPanel,
) -> Result<(), PlotError> {
    // Values at or below zero cannot be shown on a log axis; they sit on its floor.
    let (lo, hi) = style::log_extent(p.y.iter().copied().chain([p.delta]), 1.1)
        .ok_or_else(|| PlotError::NoData(format!("{}: no positive values", p.line_label)))?;
    let lo = lo.max(hi * 1e-9);
    let floor_y: Vec<f64> = p.y.iter().map(|v| v.max(lo)).collect();
    // The threshold is grey, the reference colour, so that it is not taken for a series.
    let (look, threshold, band) = (series_style(p.look), style::REFERENCE, colour(2));
    let mut legend = vec![
        (p.line_label.to_string(), Swatch::Series(look)),
        (
            format!("δ = {}", style::short(p.delta)),
            Swatch::Dashed(threshold),
        ),
    ];
    if let Some(ts) = p.mark {
        legend.push((
            format!("{} = {} rev", p.mark_label, style::short(ts)),
            Swatch::Dashed(BLACK),
        ));
        legend.push((
            format!("hold window W = {} rev", style::short(p.hold_revs)),
            Swatch::Band(band),
        ));
    }
    let area = style::panel_header(area, p.caption, &legend)?;
    let mut chart = ChartBuilder::on(&area)
        .margin(12)
        .margin_top(4)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(
            0f64..p.t_end,
            (lo..hi).log_scale().with_key_points(log_ticks(lo, hi)),
        )?;
    chart
        .configure_mesh()
        .x_desc("time t  (revolutions)")
        .y_desc(p.y_desc)
        .axis_desc_style(text(style::AXIS))
        .label_style(text(TICK))
        .x_label_formatter(&linear_label)
        .y_label_formatter(&style::log_formatter(lo, hi))
        .light_line_style(WHITE.mix(0.0))
        .draw()?;
    if let Some(ts) = p.mark {
        let end = (ts + p.hold_revs).min(p.t_end);
        chart.draw_series([Rectangle::new(
            [(ts, lo), (end, hi)],
            band.mix(0.12).filled(),
        )])?;
    }
    draw_line(&mut chart, &min_max(p.t, &floor_y, MAX_POINTS), look, 2)?;
    chart.draw_series(DashedLineSeries::new(
        [(0.0, p.delta), (p.t_end, p.delta)],
        8,
        5,
        threshold.stroke_width(2),
    ))?;
    if let Some(ts) = p.mark {
        chart.draw_series(DashedLineSeries::new(
            [(ts, lo), (ts, hi)],
            8,
            5,
            BLACK.stroke_width(2),
        ))?;
    }
    Ok(())
}

/// Angles in radians as a continuous curve in degrees (no 2π jumps).
fn unwrap_degrees(psi: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(psi.len());
    let mut offset = 0.0;
    let mut prev: Option<f64> = None;
    for &a in psi {
        if let Some(p) = prev {
            let jump = a - p;
            if jump > PI {
                offset -= 2.0 * PI;
            } else if jump < -PI {
                offset += 2.0 * PI;
            }
        }
        prev = Some(a);
        out.push((a + offset).to_degrees());
    }
    out
}

/// A continuous angle curve (degrees) cut into pieces within [0, 360), each
/// piece ending and the next starting exactly on the boundary it crosses.
fn wrap_segments(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let turn = |v: f64| (v / 360.0).floor();
    let mut segments: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    for (i, &(t, v)) in points.iter().enumerate() {
        if i > 0 {
            let (t0, v0) = points[i - 1];
            let (k0, k1) = (turn(v0), turn(v));
            if k0 != k1 {
                if (k1 - k0).abs() == 1.0 {
                    let boundary = k0.max(k1) * 360.0;
                    let tc = t0 + (t - t0) * (boundary - v0) / (v - v0);
                    let (end, start) = if k1 > k0 { (360.0, 0.0) } else { (0.0, 360.0) };
                    current.push((tc, end));
                    segments.push(std::mem::take(&mut current));
                    current.push((tc, start));
                } else {
                    // More than a turn between two kept points: leave a gap.
                    segments.push(std::mem::take(&mut current));
                }
            }
        }
        current.push((t, v - turn(v) * 360.0));
    }
    segments.push(current);
    segments.retain(|s| !s.is_empty());
    segments
}

#[cfg(test)]
mod tests {
    use super::{unwrap_degrees, wrap_segments};

    #[test]
    fn angles_wrap_into_one_turn_without_vertical_jumps() {
        let deg = unwrap_degrees(&[6.0, 6.2, 0.1, 0.3]);
        assert!(deg.windows(2).all(|w| (w[1] - w[0]).abs() < 20.0));
        let pts: Vec<(f64, f64)> = deg
            .iter()
            .enumerate()
            .map(|(i, d)| (i as f64, *d))
            .collect();
        let segs = wrap_segments(&pts);
        assert_eq!(segs.len(), 2);
        assert_eq!(segs[0].last().unwrap().1, 360.0);
        assert_eq!(segs[1][0].1, 0.0);
        assert!(segs.iter().flatten().all(|p| (0.0..=360.0).contains(&p.1)));
    }
}
