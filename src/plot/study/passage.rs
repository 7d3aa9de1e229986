//! Passage through resonance (the Sommerfeld effect): each run's spin rate
//! at its end against the motor's stall torque, one colour per kind; runs
//! held below the operating speed sit low, those that passed near ω_sync,
//! which a dashed line marks.

use super::StudyData;
use crate::plot::PlotError;
use crate::plot::style::{
    self, Dash, Figure, Marker, SeriesStyle, Swatch, TICK, draw_line, linear_label, point_style,
    text,
};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The operating-speed line: grey and dashed, apart from every kind's colour.
const OPERATING: SeriesStyle = SeriesStyle {
    colour: style::REFERENCE,
    dash: Dash::Dashed,
    marker: Marker::None,
};

/// Final spin rate against stall torque, colour by kind.
struct Passage<'a> {
    data: &'a StudyData,
}

/// Write the final spin rate against the stall torque to `path` (.svg or
/// .png); only for a study that sweeps `designs.stall_torque`.
pub fn plot_passage(data: &StudyData, path: &Path) -> Result<(), PlotError> {
    passage_data(data)?;
    style::render(&Passage { data }, path)
}

/// Whether the study has what the passage figure shows (checked before any
/// figure is written).
pub fn passage_data(data: &StudyData) -> Result<(), PlotError> {
    data.check()?;
    if !data
        .runs
        .iter()
        .any(|r| r.stall_torque.is_some() && r.metrics.final_spin_rate.is_some())
    {
        return Err(PlotError::NoData(
            "no run has a stall torque and a final spin rate: the study does not sweep designs.stall_torque".into(),
        ));
    }
    Ok(())
}

impl Figure for Passage<'_> {
    fn size(&self) -> (u32, u32) {
        (900, 560)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let points: Vec<(&str, f64, f64, bool)> = self
            .data
            .runs
            .iter()
            .filter_map(|r| {
                Some((
                    r.kind.as_str(),
                    r.stall_torque?,
                    r.metrics.final_spin_rate?,
                    r.metrics.operating_time.is_some(),
                ))
            })
            .collect();
        let mut kinds: Vec<&str> = points.iter().map(|p| p.0).collect();
        kinds.sort_unstable();
        kinds.dedup();
        let (x_lo, x_hi) = style::extent(points.iter().map(|p| p.1))
            .map(|(a, b)| style::padded(a, b, 0.06))
            .unwrap_or((0.0, 1.0));
        let omega_op = self.data.operating_speed;
        let y_hi = points
            .iter()
            .map(|p| p.2)
            .chain(omega_op)
            .fold(0.0, f64::max)
            * 1.05;
        // Kinds side by side at each torque, so their points do not cover each other.
        let offset =
            |k: usize| (k as f64 - 0.5 * (kinds.len() as f64 - 1.0)) * 0.012 * (x_hi - x_lo);
        let title = format!(
            "{}: spin rate at the end of the run-up vs motor stall torque",
            self.data.name
        );
        let body = style::titled(root, &title)?;
        let mut entries: Vec<(String, Swatch)> = kinds
            .iter()
            .enumerate()
            .map(|(k, kind)| ((*kind).to_string(), Swatch::Point(point_style(k))))
            .collect();
        entries.push((
            "held below the operating speed (cross)".into(),
            Swatch::Cross(style::REFERENCE),
        ));
        if let Some(w) = omega_op {
            entries.push((
                format!("operating speed ω_op = {} rad/s", style::short(w)),
                Swatch::Series(OPERATING),
            ));
        }
        let body = style::legend(&body, &entries)?;
        let mut chart = ChartBuilder::on(&body)
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d(x_lo..x_hi, 0.0..y_hi)?;
        chart
            .configure_mesh()
            .x_desc("motor stall torque M_s  (N·m)")
            .y_desc("final spin rate dφ/dt  (rad/s)")
            .axis_desc_style(text(style::AXIS))
            .label_style(text(TICK))
            .x_label_formatter(&linear_label)
            .y_label_formatter(&linear_label)
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .draw()?;
        // The line the runs that passed resonance end on, and those held do not.
        if let Some(w) = omega_op {
            draw_line(&mut chart, &[(x_lo, w), (x_hi, w)], OPERATING, 2)?;
        }
        for (k, kind) in kinds.iter().enumerate() {
            let look = point_style(k);
            let mine = points.iter().filter(|p| p.0 == *kind);
            chart.draw_series(mine.clone().filter(|p| p.3).map(|p| {
                EmptyElement::at((p.1 + offset(k), p.2))
                    + style::marker(look.marker, 4, look.colour.filled())
            }))?;
            chart.draw_series(
                mine.filter(|p| !p.3)
                    .map(|p| Cross::new((p.1 + offset(k), p.2), 5, look.colour.stroke_width(2))),
            )?;
        }
        Ok(())
    }
}
