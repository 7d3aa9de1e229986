//! Design curves of seed 000: capacity s(ρ) for each n with the Table-1
//! optima marked, and the transient measure ã(n) at those optima (Fig. 7).

use super::PlotError;
use super::style::{self, Figure, Swatch, TICK, colour, draw_line, series_style, short, text};
use crate::design::Shape;
use crate::design::capacity::dimensionless_capacity;
use crate::design::geometry::rho_max;
use crate::design::table::{DesignRow, optimal_row};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Points per s(ρ) curve.
const CURVE_POINTS: usize = 300;

/// One shape's curves: s(ρ) per n and the Table-1 rows.
struct ShapeCurves {
    shape: Shape,
    curves: Vec<(u32, Vec<(f64, f64)>)>,
    rows: Vec<DesignRow>,
}

fn curves(shape: Shape, ns: &[u32]) -> Result<ShapeCurves, PlotError> {
    let mut curves = Vec::with_capacity(ns.len());
    let mut rows = Vec::with_capacity(ns.len());
    for &n in ns {
        // n = 1 is defined for every ρ < 1, but not at 1 itself.
        let upper = if n == 1 { 0.995 } else { rho_max(n)? };
        let points = (1..=CURVE_POINTS)
            .map(|i| {
                let rho = upper * i as f64 / CURVE_POINTS as f64;
                Ok((rho, dimensionless_capacity(shape, n, rho)?))
            })
            .collect::<Result<Vec<_>, PlotError>>()?;
        curves.push((n, points));
        rows.push(optimal_row(shape, n)?);
    }
    Ok(ShapeCurves {
        shape,
        curves,
        rows,
    })
}

/// The design figure: one row of two panels per shape.
struct DesignFigure {
    shapes: Vec<ShapeCurves>,
}

/// Write s(ρ) per n with the Table-1 optima, and ã(n), for each shape to `path` (.svg or .png).
pub fn plot_design(shapes: &[Shape], ns: &[u32], path: &Path) -> Result<(), PlotError> {
    if shapes.is_empty() {
        return Err(PlotError::NoData("no weight shape given".into()));
    }
    if ns.is_empty() {
        return Err(PlotError::NoData("no weight count n given".into()));
    }
    let mut ns = ns.to_vec();
    ns.sort_unstable();
    ns.dedup();
    let shapes = shapes
        .iter()
        .map(|&s| curves(s, &ns))
        .collect::<Result<Vec<_>, _>>()?;
    style::render(&DesignFigure { shapes }, path)
}

fn plural(shape: Shape) -> &'static str {
    match shape {
        Shape::Ball => "balls",
        Shape::Roller => "rollers",
    }
}

impl Figure for DesignFigure {
    fn size(&self) -> (u32, u32) {
        (1300, 60 + 520 * self.shapes.len() as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let body = style::titled(
            root,
            "Design curves (seed 000): capacity and speed of balancing",
        )?;
        let rows = body.split_evenly((self.shapes.len(), 1));
        for (row, shape) in rows.iter().zip(&self.shapes) {
            let (left, right) = row.split_horizontally(row.dim_in_pixel().0 * 58 / 100);
            draw_capacity(&left, shape)?;
            draw_a_tilde(&right, shape)?;
        }
        Ok(())
    }
}

fn draw_capacity<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: &ShapeCurves,
) -> Result<(), PlotError> {
    let x_hi = c
        .curves
        .iter()
        .filter_map(|(_, p)| p.last().map(|q| q.0))
        .fold(0.0f64, f64::max);
    let y_hi = c
        .curves
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.1))
        .fold(0.0f64, f64::max)
        * 1.15;
    let caption = format!("Capacity s(ρ) of n {} (eq 9)", plural(c.shape));
    let legend = [(
        "Table-1 optimum, labelled with n".to_string(),
        Swatch::Dot(BLACK),
    )];
    let area = style::panel_header(area, &caption, &legend)?;
    let mut chart = ChartBuilder::on(&area)
        .margin(12)
        .margin_top(4)
        .x_label_area_size(48)
        .y_label_area_size(76)
        .build_cartesian_2d(0.0..(x_hi * 1.03).min(1.0), 0.0..y_hi)?;
    chart
        .configure_mesh()
        .x_desc("radius ratio ρ = r/R  (–)")
        .y_desc(format!(
            "dimensionless capacity s_{}  (–)",
            &c.shape.name()[..1]
        ))
        .axis_desc_style(text(style::AXIS))
        .label_style(text(TICK))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.08))
        .draw()?;
    let mut placer = style::LabelPlacer::left_first();
    let bounds = style::plot_bounds(&chart);
    for (i, (n, points)) in c.curves.iter().enumerate() {
        draw_line(&mut chart, points, series_style(i), 2)?;
        style::note_series(format!("n = {n}"), series_style(i));
    }
    // Direct labels: a legend of eight colours is slower to read than "n" at
    // each peak. The optima of large n crowd together, so each label takes a
    // free spot beside its dot, or is left out (its dot and colour remain).
    let optima: Vec<_> = c
        .curves
        .iter()
        .zip(&c.rows)
        .enumerate()
        .map(|(i, ((n, _), row))| (i, *n, (row.rho_opt, row.s)))
        .collect();
    for &(_, _, at) in &optima {
        let p = chart.backend_coord(&at);
        placer.reserve((p.0 - 6, p.1 - 6, p.0 + 6, p.1 + 6));
    }
    let label_style = text(TICK);
    for (i, n, at) in optima {
        let col = series_style(i).colour;
        chart.draw_series([EmptyElement::at(at)
            + Circle::new((0, 0), 5, col.filled())
            + Circle::new((0, 0), 5, BLACK.stroke_width(1))])?;
        let label = n.to_string();
        let size = area.estimate_text_size(&label, &label_style)?;
        if let Some(offset) = placer.place(chart.backend_coord(&at), size, bounds) {
            chart.draw_series([EmptyElement::at(at)
                + Text::new(
                    label,
                    offset,
                    label_style.pos(Pos::new(HPos::Left, VPos::Top)),
                )])?;
        }
    }
    Ok(())
}

fn draw_a_tilde<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: &ShapeCurves,
) -> Result<(), PlotError> {
    let (n_lo, n_hi) = (
        c.rows.first().map_or(1, |r| r.n),
        c.rows.last().map_or(1, |r| r.n),
    );
    let y_hi = c.rows.iter().map(|r| r.a_tilde).fold(0.0f64, f64::max);
    let y_hi = if y_hi > 0.0 { y_hi * 1.3 } else { 1.0 };
    let caption = format!("ã(n) at the Table-1 ρ, {} (Fig. 7)", plural(c.shape));
    let col = colour(0);
    let mut legend = vec![("no excess weights".to_string(), Swatch::Dot(col))];
    if c.rows.iter().any(|r| r.excess > 0) {
        legend.push((
            "excess weights: ã overstated".to_string(),
            Swatch::Ring(col),
        ));
    }
    let area = style::panel_header(area, &caption, &legend)?;
    let mut chart = ChartBuilder::on(&area)
        .margin(12)
        .margin_top(4)
        .x_label_area_size(48)
        .y_label_area_size(76)
        .build_cartesian_2d(
            style::fixed_ticks(
                (n_lo as f64 - 0.5)..(n_hi as f64 + 0.5),
                (n_lo..=n_hi).map(f64::from).collect(),
            ),
            0.0..y_hi,
        )?;
    chart
        .configure_mesh()
        .x_desc("number of weights n")
        .y_desc("transient measure ã  (–, larger is faster)")
        .axis_desc_style(text(style::AXIS))
        .label_style(text(TICK))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.08))
        .draw()?;
    let points: Vec<(f64, f64)> = c.rows.iter().map(|r| (r.n as f64, r.a_tilde)).collect();
    chart.draw_series(LineSeries::new(points.iter().copied(), col.stroke_width(2)))?;
    chart.draw_series(c.rows.iter().map(|r| {
        let at = (r.n as f64, r.a_tilde);
        let fill = if r.excess == 0 { col } else { WHITE };
        EmptyElement::at(at)
            + Circle::new((0, 0), 6, fill.filled())
            + Circle::new((0, 0), 6, col.stroke_width(2))
    }))?;
    if let Some(best) = c
        .rows
        .iter()
        .filter(|r| r.a_tilde > 0.0)
        .max_by(|a, b| a.a_tilde.total_cmp(&b.a_tilde))
    {
        // Anchor the label so that it stays inside the panel at either end.
        let h = if best.n == n_hi && n_hi > n_lo {
            HPos::Right
        } else if best.n == n_lo {
            HPos::Left
        } else {
            HPos::Center
        };
        chart.draw_series([Text::new(
            format!("max: n = {}, ã = {}", best.n, short(best.a_tilde)),
            (best.n as f64, best.a_tilde + y_hi * 0.05),
            text(TICK).pos(Pos::new(h, VPos::Bottom)),
        )])?;
    }
    Ok(())
}
