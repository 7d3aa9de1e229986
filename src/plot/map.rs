//! The stability map of `study map` (seed 002's map over speed and unbalance):
//! one cell per grid point, coloured by what the linearisation says.

use super::PlotError;
use super::style::{self, Figure, Swatch, TICK, text};
use crate::study::results::io::read_parquet;
use crate::study::stability_map::MapPoint;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Balanced and stable: the auto-balancer works here.
const STABLE: RGBColor = RGBColor(0, 158, 115);
/// Balanced but unstable.
const UNSTABLE: RGBColor = RGBColor(213, 94, 0);
/// No balanced state: the unbalance exceeds what the balancers can cancel.
const UNBALANCEABLE: RGBColor = RGBColor(200, 200, 200);

/// Read the Parquet table written by `study map --out` (omega, unbalance, balanced, stable).
pub fn read_map(path: &Path) -> Result<Vec<MapPoint>, PlotError> {
    let shown = path.display().to_string();
    if !path.is_file() {
        return Err(PlotError::invalid(shown, "not found"));
    }
    let df = read_parquet(path).map_err(|e| PlotError::unreadable(path, e))?;
    let column = |name: &str| {
        df.column(name).map_err(|_| {
            PlotError::invalid(
                shown.clone(),
                format!("missing column '{name}' (expected omega, unbalance, balanced, stable)"),
            )
        })
    };
    let omega: Vec<f64> = column("omega")?
        .f64()?
        .iter()
        .map(|v| v.unwrap_or(f64::NAN))
        .collect();
    let unbalance: Vec<f64> = column("unbalance")?
        .f64()?
        .iter()
        .map(|v| v.unwrap_or(f64::NAN))
        .collect();
    let balanced: Vec<bool> = column("balanced")?
        .bool()?
        .iter()
        .map(|v| v.unwrap_or(false))
        .collect();
    let stable: Vec<Option<bool>> = column("stable")?.bool()?.iter().collect();
    if omega.iter().chain(&unbalance).any(|v| !v.is_finite()) {
        return Err(PlotError::invalid(
            shown,
            "omega and unbalance must be finite",
        ));
    }
    Ok((0..df.height())
        .map(|i| MapPoint {
            omega: omega[i],
            unbalance: unbalance[i],
            balanced: balanced[i],
            stable: stable[i],
            slowest_decay: None,
        })
        .collect())
}

/// Sorted distinct values (the grid lines of one axis).
fn grid(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// Half the spacing around each grid value, so cells tile the plane.
fn cell_edges(grid: &[f64], i: usize) -> (f64, f64) {
    let lo = if i == 0 {
        grid[0] - 0.5 * (grid.get(1).unwrap_or(&(grid[0] + 1.0)) - grid[0])
    } else {
        0.5 * (grid[i - 1] + grid[i])
    };
    let hi = if i + 1 == grid.len() {
        grid[i] + 0.5 * (grid[i] - if i > 0 { grid[i - 1] } else { grid[i] - 1.0 })
    } else {
        0.5 * (grid[i] + grid[i + 1])
    };
    (lo, hi)
}

struct MapFigure<'a> {
    points: &'a [MapPoint],
    title: &'a str,
}

/// What the map sampled: the grid's size and the ranges of ω and U.
fn grid_caption(ws: &[f64], us: &[f64]) -> String {
    let range = |v: &[f64]| {
        let (lo, hi) = (v[0], v[v.len() - 1]);
        format!("{}–{}", style::short(lo), style::short(hi))
    };
    format!(
        "{} speeds ω = {} rad/s × {} unbalances U = {} kg·m",
        ws.len(),
        range(ws),
        us.len(),
        range(us)
    )
}

/// Write the stability map of `points` to `path` (.svg or .png).
pub fn plot_stability_map(points: &[MapPoint], title: &str, path: &Path) -> Result<(), PlotError> {
    if points.is_empty() {
        return Err(PlotError::NoData("the map has no points".into()));
    }
    style::render(&MapFigure { points, title }, path)
}

impl Figure for MapFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1000, 760)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let body = style::titled(root, self.title)?;
        let legend = [
            ("balanced and stable".to_string(), Swatch::Fill(STABLE)),
            ("balanced, unstable".to_string(), Swatch::Fill(UNSTABLE)),
            (
                "cannot be balanced".to_string(),
                Swatch::Fill(UNBALANCEABLE),
            ),
        ];
        // The legend swatches are the cells' own opaque colours (they were
        // drawn as translucent bands, paler than any cell on the map).
        let ws = grid(self.points.iter().map(|p| p.omega));
        let us = grid(self.points.iter().map(|p| p.unbalance));
        // The title names the map; the caption says what was sampled, which
        // the title cannot know.
        let caption = grid_caption(&ws, &us);
        let area = style::panel_header(&body, &caption, &legend)?;
        let (x_lo, _) = cell_edges(&ws, 0);
        let (_, x_hi) = cell_edges(&ws, ws.len() - 1);
        let (y_lo, _) = cell_edges(&us, 0);
        let (_, y_hi) = cell_edges(&us, us.len() - 1);
        let mut chart = ChartBuilder::on(&area)
            .margin(12)
            .margin_top(4)
            .x_label_area_size(48)
            .y_label_area_size(96)
            .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)?;
        chart
            .configure_mesh()
            .x_desc("speed ω  (rad/s)")
            .y_desc("rotor unbalance U  (kg·m)")
            .axis_desc_style(text(style::AXIS))
            .label_style(text(TICK))
            .x_label_formatter(&style::fixed_decimals(x_lo, x_hi))
            .y_label_formatter(&style::fixed_decimals(y_lo, y_hi))
            .disable_mesh()
            .draw()?;
        chart.draw_series(self.points.iter().map(|p| {
            let i = ws.iter().position(|w| *w == p.omega).unwrap_or(0);
            let j = us.iter().position(|u| *u == p.unbalance).unwrap_or(0);
            let (x0, x1) = cell_edges(&ws, i);
            let (y0, y1) = cell_edges(&us, j);
            let colour = match (p.balanced, p.stable) {
                (true, Some(true)) => STABLE,
                (true, _) => UNSTABLE,
                _ => UNBALANCEABLE,
            };
            Rectangle::new([(x0, y0), (x1, y1)], colour.filled())
        }))?;
        Ok(())
    }
}
