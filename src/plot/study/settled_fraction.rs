//! Settled fraction per design with its Wilson 95 % interval.

use super::StudyData;
use super::labels::{
    Labels, category_height, category_label, category_y, label_width, labels, row_colours,
};
use crate::plot::PlotError;
use crate::plot::style::{self, Figure, TICK, linear_label, point_style, text};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Settled fraction per design with Wilson 95 % intervals.
struct SettledFraction<'a> {
    data: &'a StudyData,
    labels: Labels,
}

/// Write the settled fraction per design, with intervals, to `path` (.svg or .png).
pub fn plot_settled_fraction(data: &StudyData, path: &Path) -> Result<(), PlotError> {
    data.check()?;
    for d in &data.designs {
        let ok = |v: f64| (0.0..=1.0).contains(&v);
        if !(ok(d.settled_fraction) && ok(d.settled_lo) && ok(d.settled_hi)) {
            return Err(PlotError::invalid(
                format!("design {} settled_fraction", d.design_id),
                "fractions and their interval must lie in [0, 1]",
            ));
        }
    }
    let figure = SettledFraction {
        data,
        labels: labels(&data.designs),
    };
    style::render(&figure, path)
}

impl Figure for SettledFraction<'_> {
    fn size(&self) -> (u32, u32) {
        (1100, category_height(self.data.designs.len()))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let designs = &self.data.designs;
        let count = designs.len();
        let lowest = designs.iter().map(|d| d.settled_lo).fold(1.0f64, f64::min);
        // Zoom in when every design settles nearly always, or the intervals
        // vanish: the axis starts a step below the lowest interval, the step
        // fitting the spread (it started at 0.9 for intervals all above 0.97,
        // leaving most of the figure empty).
        let spread = 1.0 - lowest;
        let step = if spread > 0.3 {
            0.1
        } else if spread > 0.1 {
            0.05
        } else {
            0.01
        };
        let x_lo = (((lowest - 0.1 * spread - 0.002) / step).floor() * step).max(0.0);
        let runs: Vec<u64> = designs.iter().map(|d| d.runs).collect();
        let runs_text = if runs.iter().all(|r| *r == runs[0]) {
            format!("{} runs per design", runs[0])
        } else {
            "runs per design vary".to_string()
        };
        let caption = format!(
            "{}{}dot: fraction settled, bar: Wilson 95 % interval; {runs_text}",
            self.labels.common,
            if self.labels.common.is_empty() {
                ""
            } else {
                ";  "
            }
        );
        let title = format!("{}: fraction of runs that settled", self.data.name);
        let body = style::titled(root, &title)?;
        let body = style::text_block(&body, &caption, TICK)?;
        let key_points: Vec<f64> = (0..count).map(|i| i as f64).collect();
        let label = category_label(&self.labels.per_design);
        let mut chart = ChartBuilder::on(&body)
            .margin(16)
            .margin_right(30)
            .x_label_area_size(52)
            .y_label_area_size(label_width(&self.labels.per_design))
            .build_cartesian_2d(
                x_lo..1.0 + (1.0 - x_lo) * 0.02,
                style::fixed_ticks(-0.6..count as f64 - 0.4, key_points),
            )?;
        chart
            .configure_mesh()
            .x_desc("settled fraction  (–)")
            .y_desc("design")
            .axis_desc_style(text(style::AXIS))
            .label_style(text(TICK))
            .x_label_formatter(&|v| {
                if *v > 1.0 {
                    String::new()
                } else {
                    linear_label(v)
                }
            })
            .y_label_formatter(&label)
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .draw()?;
        let (group, names) = row_colours(designs);
        for (i, d) in designs.iter().enumerate() {
            let y = category_y(i, count);
            let look = point_style(group[i]);
            style::note_series(names[group[i]].clone(), look);
            let c = look.colour;
            let h = 0.22;
            chart.draw_series([
                PathElement::new(
                    vec![(d.settled_lo, y), (d.settled_hi, y)],
                    c.stroke_width(2),
                ),
                PathElement::new(
                    vec![(d.settled_lo, y - h), (d.settled_lo, y + h)],
                    c.stroke_width(2),
                ),
                PathElement::new(
                    vec![(d.settled_hi, y - h), (d.settled_hi, y + h)],
                    c.stroke_width(2),
                ),
            ])?;
            chart.draw_series([EmptyElement::at((d.settled_fraction, y))
                + style::marker(look.marker, 6, c.filled())])?;
        }
        Ok(())
    }
}
