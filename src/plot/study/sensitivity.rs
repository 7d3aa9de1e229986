//! Which input matters: each input's total Sobol index on the settling
//! time capped at the horizon, with its 95 % interval, per design that
//! `study sensitivity` analysed (its sensitivity.parquet).

use super::StudyData;
use super::labels::{category_height, category_label, category_y, label_width};
use crate::plot::PlotError;
use crate::plot::style::{self, Figure, Swatch, TICK, linear_label, point_style, text};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One design's total index of one input, as sensitivity.parquet holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct TotalIndex {
    /// The design.
    pub design_id: u32,
    /// The input's name.
    pub input: String,
    /// The total index and its 95 % interval (raw estimates).
    pub total: (f64, f64, f64),
}

/// Total indices per input, one marker and interval per design.
struct Sensitivity<'a> {
    data: &'a StudyData,
    inputs: Vec<String>,
    designs: Vec<u32>,
}

/// Write the total indices on the capped settling time to `path`.
pub fn plot_sensitivity(data: &StudyData, path: &Path) -> Result<(), PlotError> {
    let (inputs, designs) = sensitivity_data(data)?;
    style::render(
        &Sensitivity {
            data,
            inputs,
            designs,
        },
        path,
    )
}

/// The inputs and designs of the study's indices; an error when it has none.
pub(super) fn sensitivity_data(data: &StudyData) -> Result<(Vec<String>, Vec<u32>), PlotError> {
    let indices = &data.sensitivity;
    if indices.is_empty() {
        return Err(PlotError::NoData(
            "the folder has no sensitivity.parquet: run `study sensitivity` on the study first"
                .into(),
        ));
    }
    let mut inputs: Vec<String> = Vec::new();
    let mut designs: Vec<u32> = Vec::new();
    for i in indices {
        if !inputs.contains(&i.input) {
            inputs.push(i.input.clone());
        }
        if !designs.contains(&i.design_id) {
            designs.push(i.design_id);
        }
    }
    Ok((inputs, designs))
}

impl Figure for Sensitivity<'_> {
    fn size(&self) -> (u32, u32) {
        (1100, category_height(self.inputs.len()).max(360))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let count = self.inputs.len();
        let title = format!("{}: which input explains the settling time", self.data.name);
        let caption = "dot: total Sobol index S_T on the settling time capped at the horizon (the share of its variance the input accounts for, interactions included), bar: 95 % bootstrap interval, clipped to [0, 1]; one colour per design";
        let body = style::titled(root, &title)?;
        let body = style::text_block(&body, caption, TICK)?;
        let entries: Vec<(String, Swatch)> = self
            .designs
            .iter()
            .enumerate()
            .map(|(g, d)| (format!("design {d}"), Swatch::Point(point_style(g))))
            .collect();
        let body = style::legend(&body, &entries)?;
        let key_points: Vec<f64> = (0..count).map(|i| i as f64).collect();
        let label = category_label(&self.inputs);
        let mut chart = ChartBuilder::on(&body)
            .margin(16)
            .margin_right(30)
            .x_label_area_size(52)
            .y_label_area_size(label_width(&self.inputs))
            .build_cartesian_2d(
                0.0..1.02,
                style::fixed_ticks(-0.6..count as f64 - 0.4, key_points),
            )?;
        chart
            .configure_mesh()
            .x_desc("total index S_T  (–)")
            .y_desc("input")
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
        let clip = |x: f64| x.clamp(0.0, 1.0);
        let groups = self.designs.len() as f64;
        for (g, design) in self.designs.iter().enumerate() {
            let look = point_style(g);
            let c = look.colour;
            // Designs side by side within an input's row.
            let shift = (g as f64 - (groups - 1.0) / 2.0) * 0.5 / groups.max(1.0);
            for i in self
                .data
                .sensitivity
                .iter()
                .filter(|i| i.design_id == *design)
            {
                let Some(row) = self.inputs.iter().position(|n| *n == i.input) else {
                    continue;
                };
                let y = category_y(row, count) + shift;
                let (value, lo, hi) = i.total;
                chart.draw_series([PathElement::new(
                    vec![(clip(lo), y), (clip(hi), y)],
                    c.stroke_width(2),
                )])?;
                chart
                    .draw_series([EmptyElement::at((clip(value), y))
                        + style::marker(look.marker, 6, c.filled())])?;
            }
        }
        Ok(())
    }
}
