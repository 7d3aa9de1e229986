//! Settling-time distribution per design as horizontal box plots (log scale).

use super::StudyData;
use super::labels::{
    Labels, category_height, category_label, category_y, geometries, label_width, labels,
};
use crate::plot::PlotError;
use crate::plot::style::{self, Figure, TICK, colour, log_ticks, text};
use crate::stats::quantile::{Interpolation, quantile_sorted};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Box-plot numbers: whiskers to the furthest point within 1.5 IQR, and the outliers.
struct BoxStats {
    q1: f64,
    median: f64,
    q3: f64,
    low: f64,
    high: f64,
    outliers: Vec<f64>,
}

fn box_stats(values: &[f64]) -> Option<BoxStats> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let quartile = |q| quantile_sorted(&v, q, Interpolation::Linear);
    let (q1, median, q3) = (quartile(0.25)?, quartile(0.5)?, quartile(0.75)?);
    let iqr = q3 - q1;
    let (lo_fence, hi_fence) = (q1 - 1.5 * iqr, q3 + 1.5 * iqr);
    let inside = || {
        v.iter()
            .copied()
            .filter(|x| *x >= lo_fence && *x <= hi_fence)
    };
    Some(BoxStats {
        q1,
        median,
        q3,
        low: inside().fold(f64::INFINITY, f64::min),
        high: inside().fold(f64::NEG_INFINITY, f64::max),
        outliers: v
            .iter()
            .copied()
            .filter(|x| *x < lo_fence || *x > hi_fence)
            .collect(),
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

impl Figure for SettlingBoxes<'_> {
    fn size(&self) -> (u32, u32) {
        (1100, category_height(self.data.designs.len()))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let designs = &self.data.designs;
        let count = designs.len();
        let values: Vec<Vec<f64>> = designs
            .iter()
            .map(|d| self.data.settling_revs(d.design_id))
            .collect();
        let (lo, hi) = style::log_extent(values.iter().flatten().copied(), 1.05)
            .ok_or_else(|| PlotError::NoData("no positive settling time".into()))?;
        let x_format = style::log_formatter(lo, hi);
        let title = format!("{}: settling time per design", self.data.name);
        let caption = format!(
            "{}{}box: quartiles and median, whiskers: 1.5 IQR, dots: outliers; settled runs only",
            self.labels.common,
            if self.labels.common.is_empty() {
                ""
            } else {
                ";  "
            }
        );
        let body = root.titled(&title, text(style::TITLE))?;
        let key_points: Vec<f64> = (0..count).map(|i| i as f64).collect();
        let label = category_label(&self.labels.per_design);
        let mut chart = ChartBuilder::on(&body)
            .caption(caption, text(TICK))
            .margin(16)
            .x_label_area_size(52)
            .y_label_area_size(label_width(&self.labels.per_design))
            .build_cartesian_2d(
                (lo..hi).log_scale().with_key_points(log_ticks(lo, hi)),
                style::fixed_ticks(-0.6..count as f64 - 0.4, key_points),
            )?;
        chart
            .configure_mesh()
            .x_desc("settling time t_s  (revolutions, log scale)")
            .y_desc("design")
            .axis_desc_style(text(style::AXIS))
            .label_style(text(TICK))
            .x_label_formatter(&x_format)
            .y_label_formatter(&label)
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .draw()?;
        let (group, _) = geometries(designs);
        for (i, v) in values.iter().enumerate() {
            let y = category_y(i, count);
            let c = colour(group[i]);
            let Some(b) = box_stats(v) else {
                chart.draw_series([Text::new(
                    "no run settled",
                    (lo * 1.1, y),
                    text(TICK).pos(Pos::new(HPos::Left, VPos::Center)),
                )])?;
                continue;
            };
            let h = 0.32;
            let whisker = c.stroke_width(2);
            chart.draw_series([
                PathElement::new(vec![(b.low, y), (b.q1, y)], whisker),
                PathElement::new(vec![(b.q3, y), (b.high, y)], whisker),
                PathElement::new(vec![(b.low, y - h / 2.0), (b.low, y + h / 2.0)], whisker),
                PathElement::new(vec![(b.high, y - h / 2.0), (b.high, y + h / 2.0)], whisker),
            ])?;
            chart.draw_series([
                Rectangle::new([(b.q1, y - h), (b.q3, y + h)], c.mix(0.25).filled()),
                Rectangle::new([(b.q1, y - h), (b.q3, y + h)], c.stroke_width(2)),
            ])?;
            chart.draw_series([PathElement::new(
                vec![(b.median, y - h), (b.median, y + h)],
                BLACK.stroke_width(3),
            )])?;
            chart.draw_series(
                b.outliers
                    .iter()
                    .map(|&x| Circle::new((x, y), 2, c.mix(0.6).filled())),
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_stats_match_hand_values() {
        let b = box_stats(&[1.0, 2.0, 3.0, 4.0, 5.0, 100.0]).unwrap();
        assert_eq!((b.q1, b.median, b.q3), (2.25, 3.5, 4.75));
        assert_eq!((b.low, b.high), (1.0, 5.0));
        assert_eq!(b.outliers, vec![100.0]);
    }
}
