//! Settling time against unbalance / capacity, one panel per geometry,
//! colour by drive and damping (β, and M_s where it varies); runs that never settled form a row of crosses above.

use super::StudyData;
use super::labels::{drives, geometries};
use crate::plot::PlotError;
use crate::plot::style::{self, Figure, Swatch, TICK, linear_label, log_ticks, point_style, text};
use crate::study::results::record::RunRecord;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Settling time against unbalance / capacity, one panel per geometry,
/// colour by (β, M_s).
struct SettlingScatter<'a> {
    data: &'a StudyData,
}

/// Write settling time vs unbalance fraction of capacity to `path` (.svg or .png).
pub fn plot_settling_vs_unbalance(data: &StudyData, path: &Path) -> Result<(), PlotError> {
    data.check()?;
    if !data.runs.iter().any(|r| r.metrics.settled) {
        return Err(PlotError::NoData("no run of any design settled".into()));
    }
    style::render(&SettlingScatter { data }, path)
}

impl SettlingScatter<'_> {
    fn grid(&self) -> (usize, usize) {
        let (_, names) = geometries(&self.data.designs);
        let k = names.len().max(1);
        let cols = (k as f64).sqrt().ceil() as usize;
        (k.div_ceil(cols), cols)
    }
}

impl Figure for SettlingScatter<'_> {
    fn size(&self) -> (u32, u32) {
        let (rows, cols) = self.grid();
        (
            (560 * cols as u32).clamp(900, 1800),
            110 + 440 * rows as u32,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let designs = &self.data.designs;
        let runs = &self.data.runs;
        let (group, names) = geometries(designs);
        let (drive, drive_names) = drives(designs);
        let drive_of = |r: &RunRecord| {
            designs
                .iter()
                .position(|d| d.design_id == r.design_id)
                .map(|i| drive[i])
        };
        let geometry_of = |r: &RunRecord| {
            designs
                .iter()
                .position(|d| d.design_id == r.design_id)
                .map(|i| group[i])
        };
        let settled = runs
            .iter()
            .filter_map(|r| self.data.settled_revs(r))
            .filter(|v| *v > 0.0);
        let (lo, data_hi) = style::extent(settled)
            .ok_or_else(|| PlotError::NoData("no positive settling time".into()))?;
        let any_unsettled = runs.iter().any(|r| !r.metrics.settled);
        // Unsettled runs have no settling time: they get a row of crosses above the data.
        let cross_y = data_hi * 1.5;
        let top = if any_unsettled {
            data_hi * 2.0
        } else {
            data_hi
        };
        let (lo, hi) = style::log_extent([lo, top], 1.05)
            .ok_or_else(|| PlotError::NoData("no positive settling time".into()))?;
        let y_format = style::log_formatter(lo, hi);
        let (x_lo, x_hi) = style::extent(runs.iter().map(|r| r.unbalance_fraction))
            .map(|(a, b)| style::padded(a, b, 0.03))
            .unwrap_or((0.0, 1.0));
        let title = format!(
            "{}: settling time vs unbalance (fraction of capacity)",
            self.data.name
        );
        let body = style::titled(root, &title)?;
        // Grey, outside the palette: no drive's colour is mistaken for it.
        let red = style::REFERENCE;
        let mut entries: Vec<(String, Swatch)> = drive_names
            .iter()
            .enumerate()
            .map(|(k, name)| (name.clone(), Swatch::Point(point_style(k))))
            .collect();
        if any_unsettled {
            entries.push((
                "not settled (row above the data)".into(),
                Swatch::Cross(red),
            ));
        }
        let body = style::legend(&body, &entries)?;
        let (rows, cols) = self.grid();
        let panels = body.split_evenly((rows, cols));
        for (g, (panel, name)) in panels.iter().zip(&names).enumerate() {
            let mine: Vec<&RunRecord> = runs.iter().filter(|r| geometry_of(r) == Some(g)).collect();
            let unsettled: Vec<f64> = mine
                .iter()
                .filter(|r| !r.metrics.settled)
                .map(|r| r.unbalance_fraction)
                .collect();
            let caption = if unsettled.is_empty() {
                name.clone()
            } else {
                format!("{name}  ({} not settled)", unsettled.len())
            };
            let mut chart = ChartBuilder::on(panel)
                .caption(caption, text(style::CAPTION))
                .margin(12)
                .x_label_area_size(48)
                .y_label_area_size(72)
                .build_cartesian_2d(
                    x_lo..x_hi,
                    (lo..hi).log_scale().with_key_points(log_ticks(lo, hi)),
                )?;
            chart
                .configure_mesh()
                .x_desc("unbalance U / capacity S  (–)")
                .y_desc(format!(
                    "settling time t_s  ({})",
                    self.data.settling_axis()
                ))
                .axis_desc_style(text(style::AXIS))
                .label_style(text(TICK))
                .x_label_formatter(&linear_label)
                .y_label_formatter(&y_format)
                .light_line_style(WHITE.mix(0.0))
                .bold_line_style(BLACK.mix(0.08))
                .draw()?;
            for k in 0..drive_names.len() {
                let look = point_style(k);
                // Opaque, as in the legend: a translucent mark reads as another colour.
                chart.draw_series(
                    mine.iter()
                        .filter(|r| drive_of(r) == Some(k) && r.metrics.settled)
                        .filter_map(|r| Some((r.unbalance_fraction, self.data.settled_revs(r)?)))
                        .map(|p| {
                            EmptyElement::at(p)
                                + style::marker(look.marker, 3, look.colour.filled())
                        }),
                )?;
            }
            chart.draw_series(
                unsettled
                    .iter()
                    .map(|&x| Cross::new((x, cross_y), 4, red.stroke_width(2))),
            )?;
        }
        Ok(())
    }
}
