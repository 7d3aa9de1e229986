//! Settling-time distribution per design as horizontal box plots (log scale),
//! over every run: the box is the Kaplan–Meier quartiles and median with
//! unsettled runs censored, the same median `summary.parquet` reports.

use super::StudyData;
use super::labels::{
    Labels, category_height, category_label, category_y, label_width, labels, row_colours,
};
use crate::plot::PlotError;
use crate::plot::style::{self, Figure, TICK, draw_line, log_ticks, point_style, text};
use crate::stats::survival::{KaplanMeier, Observation};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Box-plot numbers over every run of a design. The quartiles and median
/// are Kaplan–Meier estimates, unsettled runs censored (`None`: beyond the
/// run); whiskers reach the furthest settled run within 1.5 IQR of the box,
/// and the settled runs beyond are outliers.
struct BoxStats {
    q1: Option<f64>,
    median: Option<f64>,
    q3: Option<f64>,
    low: Option<f64>,
    high: Option<f64>,
    outliers: Vec<f64>,
    runs: usize,
    unsettled: usize,
}

fn box_stats(runs: &[Observation]) -> Option<BoxStats> {
    let km = KaplanMeier::fit(runs)?;
    let (q1, median, q3) = (km.quantile(0.25), km.quantile(0.5), km.quantile(0.75));
    // With a quartile beyond the run the spread is unknown: no fence on that side.
    let iqr = q1.zip(q3).map(|(a, b)| b - a);
    let lo_fence = q1.zip(iqr).map_or(f64::NEG_INFINITY, |(a, r)| a - 1.5 * r);
    let hi_fence = q3.zip(iqr).map_or(f64::INFINITY, |(b, r)| b + 1.5 * r);
    let mut settled: Vec<f64> = runs.iter().filter(|o| o.settled).map(|o| o.time).collect();
    settled.sort_by(f64::total_cmp);
    let inside = || {
        settled
            .iter()
            .copied()
            .filter(|x| *x >= lo_fence && *x <= hi_fence)
    };
    Some(BoxStats {
        q1,
        median,
        q3,
        low: inside().next(),
        high: q3.and(inside().next_back()),
        outliers: settled
            .iter()
            .copied()
            .filter(|x| *x < lo_fence || *x > hi_fence)
            .collect(),
        runs: runs.len(),
        unsettled: runs.iter().filter(|o| !o.settled).count(),
    })
}

/// Settling-time distribution per design as horizontal box plots (log scale).
struct SettlingBoxes<'a> {
    data: &'a StudyData,
    labels: Labels,
}

/// Write the settling-time box plots of a study to `path` (.svg or .png).
pub fn plot_settling_times(data: &StudyData, path: &Path) -> Result<(), PlotError> {
    data.check()?;
    let figure = SettlingBoxes {
        data,
        labels: labels(&data.designs),
    };
    if data
        .designs
        .iter()
        .all(|d| data.settling_revs(d.design_id).is_empty())
    {
        return Err(PlotError::NoData("no run of any design settled".into()));
    }
    style::render(&figure, path)
}

impl SettlingBoxes<'_> {
    /// The labels every design shares, then how to read a box.
    fn caption(&self) -> String {
        format!(
            "{}{}box: quartiles, bar: median, by Kaplan–Meier over every run (unsettled runs censored)",
            self.labels.common,
            if self.labels.common.is_empty() {
                ""
            } else {
                ";  "
            }
        )
    }

    /// Each design's label, with its unsettled runs counted where it is named.
    fn row_labels(&self, boxes: &[Option<BoxStats>]) -> Vec<String> {
        self.labels
            .per_design
            .iter()
            .zip(boxes)
            .map(|(l, b)| match b {
                Some(b) if b.unsettled > 0 => {
                    format!("{l}  ({} of {} not settled)", b.unsettled, b.runs)
                }
                _ => l.clone(),
            })
            .collect()
    }
}

impl Figure for SettlingBoxes<'_> {
    fn size(&self) -> (u32, u32) {
        (1100, category_height(self.data.designs.len()) + 24)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let designs = &self.data.designs;
        let count = designs.len();
        let boxes: Vec<Option<BoxStats>> = designs
            .iter()
            .map(|d| box_stats(&self.data.settling_observations(d.design_id)))
            .collect();
        let settled = designs
            .iter()
            .flat_map(|d| self.data.settling_revs(d.design_id));
        let (lo, hi) = style::log_extent(settled, 1.05)
            .ok_or_else(|| PlotError::NoData("no positive settling time".into()))?;
        let x_format = style::log_formatter(lo, hi);
        let title = format!("{}: settling time per design", self.data.name);
        let caption = self.caption();
        let row_labels = self.row_labels(&boxes);
        let body = style::titled(root, &title)?;
        let body = style::text_block(&body, &caption, TICK)?;
        let body = style::text_block(
            &body,
            "open box, no bar: that quartile or the median lies beyond the run; whiskers: settled runs within 1.5 IQR; dots: settled runs beyond",
            TICK,
        )?;
        let key_points: Vec<f64> = (0..count).map(|i| i as f64).collect();
        let label = category_label(&row_labels);
        let mut chart = ChartBuilder::on(&body)
            .margin(16)
            .x_label_area_size(52)
            .y_label_area_size(label_width(&row_labels))
            .build_cartesian_2d(
                (lo..hi).log_scale().with_key_points(log_ticks(lo, hi)),
                style::fixed_ticks(-0.6..count as f64 - 0.4, key_points),
            )?;
        chart
            .configure_mesh()
            .x_desc(format!(
                "settling time t_s  ({}, log scale)",
                self.data.settling_axis()
            ))
            .y_desc("design")
            .axis_desc_style(text(style::AXIS))
            .label_style(text(TICK))
            .x_label_formatter(&x_format)
            .y_label_formatter(&label)
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .draw()?;
        let (group, names) = row_colours(designs);
        for (i, b) in boxes.iter().enumerate() {
            let y = category_y(i, count);
            let look = point_style(group[i]);
            let c = look.colour;
            let Some((b, q1)) = b.as_ref().and_then(|b| Some((b, b.q1?))) else {
                let why = if b.is_some() {
                    "fewer than a quarter of the runs settled"
                } else {
                    "no runs"
                };
                chart.draw_series([Text::new(
                    why,
                    (lo * 1.1, y),
                    text(TICK).pos(Pos::new(HPos::Left, VPos::Center)),
                )])?;
                continue;
            };
            let h = 0.32;
            // Past seven colour groups the colours come round again; the outlines
            // then turn dashed (outline_style), the outlier marks change shape.
            let outline_look = style::outline_style(group[i]);
            style::note_series(names[group[i]].clone(), outline_look);
            // Past the last settling the box runs off the right edge, open.
            let right = b.q3.unwrap_or(hi);
            let mut lines = Vec::new();
            if let Some(low) = b.low.filter(|l| *l < q1) {
                lines.push(vec![(low, y), (q1, y)]);
                lines.push(vec![(low, y - h / 2.0), (low, y + h / 2.0)]);
            }
            if let (Some(q3), Some(high)) = (b.q3, b.high.filter(|x| Some(*x) > b.q3)) {
                lines.push(vec![(q3, y), (high, y)]);
                lines.push(vec![(high, y - h / 2.0), (high, y + h / 2.0)]);
            }
            let mut outline = vec![(right, y + h), (q1, y + h), (q1, y - h), (right, y - h)];
            if b.q3.is_some() {
                outline.push((right, y + h));
            }
            lines.push(outline);
            chart.draw_series([Rectangle::new(
                [(q1, y - h), (right, y + h)],
                c.mix(0.25).filled(),
            )])?;
            for l in &lines {
                draw_line(&mut chart, l, outline_look, 2)?;
            }
            if let Some(median) = b.median {
                chart.draw_series([PathElement::new(
                    vec![(median, y - h), (median, y + h)],
                    BLACK.stroke_width(3),
                )])?;
            }
            chart.draw_series(b.outliers.iter().map(|&x| {
                EmptyElement::at((x, y)) + style::marker(look.marker, 3, c.mix(0.6).filled())
            }))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_stats_count_every_run() {
        let settled = |time| Observation {
            time,
            settled: true,
        };
        let censored = |time| Observation {
            time,
            settled: false,
        };
        // All settled: the Kaplan–Meier quartiles are the sample's (type 2).
        let runs = [1.0, 2.0, 3.0, 4.0, 5.0, 100.0].map(settled);
        let b = box_stats(&runs).unwrap();
        assert_eq!((b.q1, b.median, b.q3), (Some(2.0), Some(3.5), Some(5.0)));
        assert_eq!((b.low, b.high), (Some(1.0), Some(5.0)));
        assert_eq!((b.outliers, b.unsettled), (vec![100.0], 0));
        // Three of eight never settled: the quartile and median are those of
        // all eight with the unsettled ones last (2.5 and 4.5), not the settled
        // runs' (2 and 3), and the upper quartile lies beyond the run.
        let mut runs = [1.0, 2.0, 3.0, 4.0, 5.0].map(settled).to_vec();
        runs.extend([50.0; 3].map(censored));
        let b = box_stats(&runs).unwrap();
        assert_eq!((b.q1, b.median, b.q3), (Some(2.5), Some(4.5), None));
        assert_eq!(
            (b.low, b.high, b.unsettled, b.runs),
            (Some(1.0), None, 3, 8)
        );
        assert!(b.outliers.is_empty());
    }
}
