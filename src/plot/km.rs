//! The Kaplan–Meier figure of `study compare --plot`: for each design the
//! estimated fraction of runs settled by t, 1 − S(t), with its 95 % pointwise
//! band. Runs that never settled are censored where they were last seen, so
//! every run counts and a curve stops below 1 when some runs did not settle.

use super::PlotError;
use super::style::{
    self, Figure, REFERENCE, Swatch, TICK, draw_line, linear_label, log_ticks, series_style, text,
};
use crate::decide::verdict::{LEVEL, SettlingClock};
use crate::stats::survival::{Interval, KaplanMeier, Observation, Transform};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// The scale the band is built on: the one of the median interval that
/// `study compare` and `summary.parquet` report, so the figure and the
/// table agree on where the band crosses ½.
pub const BAND: Transform = Transform::LogLog;

/// One design's runs, as the figure draws them.
#[derive(Debug, Clone)]
pub struct KmCurve {
    /// Legend label, e.g. "A: ball n=3 ρ=0.250 β=10".
    pub label: String,
    /// Every run: settled at its time, or censored there.
    pub observations: Vec<Observation>,
    /// Latest settling time a run can show (revolutions): t_end − W.
    pub horizon: f64,
}

/// Vertices of the step curve 1 − S(t) from t = 0 to `until`: flat between
/// settling times and vertical at each (events after `until` are left out).
pub fn settled_steps(km: &KaplanMeier, until: f64) -> Vec<(f64, f64)> {
    let mut points = vec![(0.0, 0.0)];
    let mut level = 0.0;
    for step in km.steps().iter().take_while(|s| s.time <= until) {
        let next = 1.0 - step.survival;
        points.push((step.time, level));
        points.push((step.time, next));
        level = next;
    }
    points.push((until, level));
    points
}

/// The pointwise 95 % band of 1 − S(t) on [`BAND`]'s scale, as (from, to,
/// interval) for each stretch between settling times up to `until`; left
/// out before the first settling (the band is the point 0) and where S = 0
/// (it is undefined there).
pub fn settled_band(km: &KaplanMeier, until: f64) -> Vec<(f64, f64, Interval)> {
    let steps = km.steps();
    let band = km.confidence_band(LEVEL, BAND);
    steps
        .iter()
        .zip(band)
        .enumerate()
        .take_while(|(_, (s, _))| s.time <= until)
        .filter_map(|(i, (s, b))| {
            let to = steps.get(i + 1).map_or(until, |n| n.time.min(until));
            Some((s.time, to.max(s.time), b?.complement()))
        })
        .collect()
}

/// Distinct times at which runs were censored (one tick each).
fn censoring_times(observations: &[Observation]) -> Vec<f64> {
    let mut times: Vec<f64> = observations
        .iter()
        .filter(|o| !o.settled)
        .map(|o| o.time)
        .collect();
    times.sort_by(f64::total_cmp);
    times.dedup();
    times
}

/// A curve with its fit, checked.
struct Fitted<'a> {
    curve: &'a KmCurve,
    km: KaplanMeier,
    /// Where the curve is drawn to: the horizon, or a later observation.
    end: f64,
}

/// The log time axis: from below the first settling after t = 0 to past
/// every curve's end. Runs that settled at t = 0 (a run-up whose balancer
/// had settled by the operating speed) are drawn at the left edge; they
/// must not push the axis out to the horizon.
fn time_extent(fitted: &[Fitted]) -> Option<(f64, f64)> {
    let first = fitted
        .iter()
        .filter_map(|f| f.km.steps().iter().map(|s| s.time).find(|t| *t > 0.0));
    let ends = fitted.iter().map(|f| f.end);
    style::log_extent(first.chain(ends), 1.15)
}

/// Whether some run settled at t = 0, which the log axis draws at its left edge.
fn settled_at_zero(fitted: &[Fitted]) -> bool {
    fitted.iter().any(|f| {
        f.curve
            .observations
            .iter()
            .any(|o| o.settled && o.time == 0.0)
    })
}

/// A top axis giving the settling times in seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SecondsAxis {
    /// Seconds per revolution of the operating speed, the curves' unit.
    pub per_rev: f64,
    /// Whether the clock starts when the rotor reached the operating speed
    /// (a run-up) rather than at t = 0.
    pub from_operating_speed: bool,
}

impl SecondsAxis {
    /// The axis for settling times measured on `clock`, in revolutions of `rev_seconds`.
    pub fn for_clock(clock: SettlingClock, rev_seconds: f64) -> Self {
        SecondsAxis {
            per_rev: rev_seconds,
            from_operating_speed: matches!(clock, SettlingClock::FromOperatingSpeed(_)),
        }
    }

    fn description(self) -> &'static str {
        if self.from_operating_speed {
            "settling time t  (s after reaching the operating speed, log scale)"
        } else {
            "settling time t  (s at the constant speed, log scale)"
        }
    }
}

/// The Kaplan–Meier comparison figure.
struct KmFigure<'a> {
    fitted: Vec<Fitted<'a>>,
    title: &'a str,
    seconds: Option<SecondsAxis>,
}

/// Write the Kaplan–Meier curves of `curves` to `path` (.svg or .png); with
/// `seconds` (the same clock for every curve), a top axis in seconds.
pub fn plot_kaplan_meier(
    curves: &[KmCurve],
    title: &str,
    seconds: Option<SecondsAxis>,
    path: &Path,
) -> Result<(), PlotError> {
    if let Some(s) = seconds.map(|s| s.per_rev)
        && !(s.is_finite() && s > 0.0)
    {
        return Err(PlotError::invalid(
            "seconds per revolution",
            "must be finite and > 0",
        ));
    }
    if curves.is_empty() {
        return Err(PlotError::NoData("no design to draw".into()));
    }
    let fitted = curves
        .iter()
        .map(|curve| {
            if !(curve.horizon.is_finite() && curve.horizon > 0.0) {
                return Err(PlotError::invalid(
                    format!("{} horizon", curve.label),
                    "must be finite and > 0",
                ));
            }
            let km = KaplanMeier::fit(&curve.observations).ok_or_else(|| {
                PlotError::invalid(
                    curve.label.clone(),
                    "needs at least one run, every time finite and ≥ 0",
                )
            })?;
            let last = curve
                .observations
                .iter()
                .map(|o| o.time)
                .fold(0.0, f64::max);
            let end = curve.horizon.max(last);
            Ok(Fitted { curve, km, end })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    style::render(
        &KmFigure {
            fitted,
            title,
            seconds,
        },
        path,
    )
}

impl Figure for KmFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1100, 680)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        // Settling times span decades (a few to hundreds of revolutions):
        // a log axis, from below the first settling to past the horizon.
        let (lo, hi) = time_extent(&self.fitted)
            .ok_or_else(|| PlotError::NoData("no positive time".into()))?;
        let body = style::titled(root, self.title)?;
        let legend: Vec<(String, Swatch)> = self
            .fitted
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let n = f.km.n_observations();
                let unsettled = f.curve.observations.iter().filter(|o| !o.settled).count();
                let label = format!("{}  ({n} runs, {unsettled} not settled)", f.curve.label);
                (label, Swatch::Series(series_style(i)))
            })
            .collect();
        let caption = format!(
            "every run counted; shaded: {:.0} % pointwise band (log-log); ticks: runs censored unsettled; dashed: ½, where the median reads off{}",
            100.0 * LEVEL,
            if settled_at_zero(&self.fitted) {
                "; runs settled at t\u{a0}=\u{a0}0: the rise at the left edge"
            } else {
                ""
            }
        );
        let area = style::legend(&body, &legend)?;
        let area = style::text_block(&area, &caption, TICK)?;
        let mut chart = ChartBuilder::on(&area)
            .margin(16)
            .margin_top(4)
            .margin_right(30)
            .x_label_area_size(52)
            .top_x_label_area_size(if self.seconds.is_some() { 52 } else { 0 })
            .y_label_area_size(80)
            .build_cartesian_2d(
                (lo..hi).log_scale().with_key_points(log_ticks(lo, hi)),
                0.0..1.02,
            )?;
        match self.seconds {
            Some(axis) => {
                let s = axis.per_rev;
                // The same log axis scaled by a constant: its ticks line up
                // with the revolutions below. Set before the primary mesh,
                // which would otherwise label the top axis too.
                let (s_lo, s_hi) = (lo * s, hi * s);
                let mut dual = chart.set_secondary_coord(
                    (s_lo..s_hi)
                        .log_scale()
                        .with_key_points(log_ticks(s_lo, s_hi)),
                    0.0..1.02,
                );
                dual.configure_secondary_axes()
                    .x_desc(axis.description())
                    .axis_desc_style(text(style::AXIS))
                    .label_style(text(TICK))
                    .x_label_formatter(&style::log_formatter(s_lo, s_hi))
                    .draw()?;
                self.draw_curves(&mut dual, lo, hi)
            }
            None => self.draw_curves(&mut chart, lo, hi),
        }
    }
}

/// The figure's plotting coordinates: log settling time by fraction settled.
type KmCoord = Cartesian2d<
    plotters::coord::combinators::WithKeyPoints<LogCoord<f64>>,
    plotters::coord::types::RangedCoordf64,
>;

impl KmFigure<'_> {
    /// The mesh, bands, horizons, curves and censoring ticks on `chart`,
    /// spanning `lo`..`hi` revolutions.
    fn draw_curves<DB: DrawingBackend>(
        &self,
        chart: &mut ChartContext<'_, DB, KmCoord>,
        lo: f64,
        hi: f64,
    ) -> Result<(), PlotError> {
        chart
            .configure_mesh()
            .x_desc("settling time t  (revolutions, log scale)")
            .y_desc("settled by t, 1 − S(t)  (–)")
            .axis_desc_style(text(style::AXIS))
            .label_style(text(TICK))
            .x_label_formatter(&style::log_formatter(lo, hi))
            .y_label_formatter(&|v| {
                if *v > 1.0 {
                    String::new()
                } else {
                    linear_label(v)
                }
            })
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .draw()?;
        // Time 0 cannot sit on a log axis; the curve starts at its left edge.
        let x = |t: f64| t.clamp(lo, hi);
        for (i, f) in self.fitted.iter().enumerate() {
            let c = series_style(i).colour;
            chart.draw_series(settled_band(&f.km, f.end).into_iter().map(|(a, b, iv)| {
                Rectangle::new([(x(a), iv.lower), (x(b), iv.upper)], c.mix(0.18).filled())
            }))?;
        }
        chart.draw_series(DashedLineSeries::new(
            [(lo, 0.5), (hi, 0.5)],
            8,
            5,
            REFERENCE.stroke_width(1),
        ))?;
        let mut horizons: Vec<f64> = self.fitted.iter().map(|f| f.curve.horizon).collect();
        horizons.sort_by(f64::total_cmp);
        horizons.dedup();
        let first_horizon = horizons.first().copied().unwrap_or(hi);
        for (k, h) in horizons.iter().enumerate() {
            let h = *h;
            chart.draw_series([PathElement::new(
                vec![(x(h), 0.0), (x(h), 1.02)],
                REFERENCE.stroke_width(2),
            )])?;
            // Near the foot of the line, where curves are high by the horizon;
            // several horizons stack their labels instead of printing over each other.
            let label = if k == 0 {
                format!("horizon t_end − W = {} rev ", style::short(h))
            } else {
                format!("{} rev ", style::short(h))
            };
            // All left of the first line, so that no label crosses a line.
            chart.draw_series([Text::new(
                label,
                (x(first_horizon), 0.03 + 0.05 * k as f64),
                text(TICK).pos(Pos::new(HPos::Right, VPos::Bottom)),
            )])?;
        }
        for (i, f) in self.fitted.iter().enumerate() {
            let look = series_style(i);
            let c = look.colour;
            let steps: Vec<(f64, f64)> = settled_steps(&f.km, f.end)
                .into_iter()
                .map(|(t, y)| (x(t), y))
                .collect();
            draw_line(chart, &steps, look, 2)?;
            chart.draw_series(censoring_times(&f.curve.observations).into_iter().map(|t| {
                EmptyElement::at((x(t), f.km.settled_by(t)))
                    + PathElement::new(vec![(0, -6), (0, 6)], c.stroke_width(2))
            }))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_settled_at_zero_keep_the_axis_at_the_first_later_settling() {
        // A run-up: most runs had settled when the operating speed was
        // reached. The axis must still start below the first later settling
        // (it started near the horizon, hiding every step).
        let o = |time, settled| Observation { time, settled };
        let curve = KmCurve {
            label: "A".into(),
            observations: vec![
                o(0.0, true),
                o(0.0, true),
                o(0.0, true),
                o(2.0, true),
                o(7.0, true),
            ],
            horizon: 3000.0,
        };
        let fitted = [Fitted {
            curve: &curve,
            km: KaplanMeier::fit(&curve.observations).unwrap(),
            end: curve.horizon,
        }];
        let (lo, hi) = time_extent(&fitted).unwrap();
        assert!(lo < 2.0 && hi >= 3000.0, "{lo}..{hi}");
        assert!(settled_at_zero(&fitted));
    }

    #[test]
    fn censoring_times_are_distinct_and_sorted() {
        let o = |time, settled| Observation { time, settled };
        let obs = [o(3.0, false), o(1.0, true), o(3.0, false), o(2.0, false)];
        assert_eq!(censoring_times(&obs), vec![2.0, 3.0]);
    }
}
