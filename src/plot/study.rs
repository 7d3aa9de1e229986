//! One study: settling-time distributions per design (box plots), the
//! settled fraction with its Wilson intervals, and settling time against the
//! unbalance as a fraction of capacity (scatter, one panel per geometry).

use super::style::{self, Figure, Swatch, TICK, colour, linear_label, log_ticks, short, text};
use super::{Format, PlotError};
use crate::stats::quantile::{Interpolation, quantile_sorted};
use crate::study::io::read_parquet;
use crate::study::record::{RunRecord, from_dataframe};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use polars::prelude::*;
use std::path::{Path, PathBuf};

/// One row of `summary.parquet`, as much of it as the figures use.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignStats {
    /// Design index in grid order.
    pub design_id: u32,
    /// Balancer kind.
    pub kind: String,
    /// Number of weights.
    pub n: u32,
    /// Radius ratio ρ.
    pub rho: f64,
    /// Drag coefficient β (N·s/m).
    pub drag: f64,
    /// Runs of this design.
    pub runs: u64,
    /// Fraction of runs that settled.
    pub settled_fraction: f64,
    /// Lower end of its Wilson 95 % interval.
    pub settled_lo: f64,
    /// Upper end of its Wilson 95 % interval.
    pub settled_hi: f64,
}

/// The rows of a summary DataFrame written by `study run`.
pub fn design_stats(summary: &DataFrame) -> Result<Vec<DesignStats>, PlotError> {
    let f64s = |name: &str| -> Result<Vec<f64>, PlotError> {
        let c = summary.column(name)?.cast(&DataType::Float64)?;
        c.f64()?
            .iter()
            .map(|v| v.ok_or_else(|| PlotError::invalid(name, "null value in summary")))
            .collect()
    };
    let ids = summary.column("design_id")?.cast(&DataType::UInt32)?;
    let ns = summary.column("n")?.cast(&DataType::UInt32)?;
    let runs = summary.column("runs")?.cast(&DataType::UInt64)?;
    let kinds = summary.column("kind")?.str()?.clone();
    let (rho, drag) = (f64s("rho")?, f64s("drag")?);
    let (frac, lo, hi) = (
        f64s("settled_fraction")?,
        f64s("settled_fraction_lo")?,
        f64s("settled_fraction_hi")?,
    );
    let (ids, ns, runs) = (ids.u32()?, ns.u32()?, runs.u64()?);
    (0..summary.height())
        .map(|i| {
            Ok(DesignStats {
                design_id: ids
                    .get(i)
                    .ok_or_else(|| PlotError::invalid("design_id", "null"))?,
                kind: kinds.get(i).unwrap_or_default().to_string(),
                n: ns.get(i).ok_or_else(|| PlotError::invalid("n", "null"))?,
                rho: rho[i],
                drag: drag[i],
                runs: runs.get(i).unwrap_or(0),
                settled_fraction: frac[i],
                settled_lo: lo[i],
                settled_hi: hi[i],
            })
        })
        .collect()
}

/// A study's runs and per-design statistics.
#[derive(Debug, Clone)]
pub struct StudyData {
    /// The study's name (its folder name), used in titles.
    pub name: String,
    /// Every run, from `runs.parquet`.
    pub runs: Vec<RunRecord>,
    /// One entry per design, from `summary.parquet`.
    pub designs: Vec<DesignStats>,
}

impl StudyData {
    /// Read `runs.parquet` and `summary.parquet` from a study's output folder.
    pub fn read(dir: &Path) -> Result<Self, PlotError> {
        let open = |file: &str| {
            let path = dir.join(file);
            if !path.is_file() {
                return Err(PlotError::invalid(
                    path.display().to_string(),
                    "not found: give the output folder of `study run`",
                ));
            }
            read_parquet(&path)
                .map_err(|e| PlotError::invalid(path.display().to_string(), e.to_string()))
        };
        let runs = from_dataframe(&open("runs.parquet")?)?;
        let designs = design_stats(&open("summary.parquet")?)?;
        let name = dir
            .canonicalize()
            .unwrap_or_else(|_| dir.to_path_buf())
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "study".into());
        Ok(StudyData {
            name,
            runs,
            designs,
        })
    }

    fn check(&self) -> Result<(), PlotError> {
        if self.designs.is_empty() {
            return Err(PlotError::NoData("the summary has no designs".into()));
        }
        if self.runs.is_empty() {
            return Err(PlotError::NoData("the study has no runs".into()));
        }
        Ok(())
    }

    /// Settling times (revolutions) of the settled runs of one design.
    fn settling_revs(&self, design_id: u32) -> Vec<f64> {
        self.runs
            .iter()
            .filter(|r| r.design_id == design_id && r.metrics.settled)
            .filter_map(|r| r.metrics.settling_revs)
            .filter(|v| v.is_finite())
            .collect()
    }
}

/// How designs are told apart: the parameters that vary, and those that do not.
struct Labels {
    per_design: Vec<String>,
    common: String,
}

fn labels(designs: &[DesignStats]) -> Labels {
    let varies = |f: &dyn Fn(&DesignStats) -> String| {
        let first = f(&designs[0]);
        designs.iter().any(|d| f(d) != first)
    };
    let weights = |d: &DesignStats| weight_count(d.n, &d.kind);
    let rho = |d: &DesignStats| format!("ρ = {}", short(d.rho));
    let drag = |d: &DesignStats| format!("β = {} N·s/m", short(d.drag));
    let parts: [&dyn Fn(&DesignStats) -> String; 3] = [&weights, &rho, &drag];
    let (vary, fixed): (Vec<_>, Vec<_>) = parts.iter().partition(|f| varies(**f));
    let per_design = designs
        .iter()
        .map(|d| {
            if vary.is_empty() {
                format!("design {}", d.design_id)
            } else {
                vary.iter()
                    .map(|f: &&dyn Fn(&DesignStats) -> String| f(d))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        })
        .collect();
    let common = fixed
        .iter()
        .map(|f| f(&designs[0]))
        .collect::<Vec<_>>()
        .join(", ");
    Labels { per_design, common }
}

/// "3 balls", "1 roller".
fn weight_count(n: u32, kind: &str) -> String {
    if n == 1 {
        format!("1 {kind}")
    } else {
        format!("{n} {kind}s")
    }
}

/// Index of each design's geometry (kind, n, ρ): designs sharing it share a colour or panel.
fn geometries(designs: &[DesignStats]) -> (Vec<usize>, Vec<String>) {
    let mut keys: Vec<(String, u32, f64)> = Vec::new();
    let index = designs
        .iter()
        .map(|d| {
            let key = (d.kind.clone(), d.n, d.rho);
            match keys.iter().position(|k| *k == key) {
                Some(i) => i,
                None => {
                    keys.push(key);
                    keys.len() - 1
                }
            }
        })
        .collect();
    let names = keys
        .iter()
        .map(|(kind, n, rho)| format!("{}, ρ = {}", weight_count(*n, kind), short(*rho)))
        .collect();
    (index, names)
}

/// Width in pixels to reserve for category labels of this many characters.
fn label_width(labels: &[String]) -> u32 {
    let longest = labels.iter().map(|l| l.chars().count()).max().unwrap_or(4) as u32;
    (longest * TICK * 58 / 100 + 24).max(60)
}

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

fn category_height(count: usize) -> u32 {
    (180 + 34 * count as u32).max(480)
}

/// Category axis: design i sits at y = count − 1 − i, so the first design is on top.
fn category_y(i: usize, count: usize) -> f64 {
    (count - 1 - i) as f64
}

fn category_label(labels: &[String]) -> impl Fn(&f64) -> String + '_ {
    move |v: &f64| {
        let count = labels.len();
        let k = v.round();
        if (v - k).abs() > 1e-6 || k < 0.0 || k as usize >= count {
            return String::new();
        }
        labels[count - 1 - k as usize].clone()
    }
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
        // Zoom in when every design settles nearly always, or the intervals vanish.
        let x_lo = ((lowest - 0.02) * 10.0).floor().max(0.0) / 10.0;
        let x_lo = if x_lo > 0.9 {
            ((lowest - 0.005) * 100.0).floor() / 100.0
        } else {
            x_lo
        };
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
        let body = root.titled(&title, text(style::TITLE))?;
        let key_points: Vec<f64> = (0..count).map(|i| i as f64).collect();
        let label = category_label(&self.labels.per_design);
        let mut chart = ChartBuilder::on(&body)
            .caption(caption, text(TICK))
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
        let (group, _) = geometries(designs);
        for (i, d) in designs.iter().enumerate() {
            let y = category_y(i, count);
            let c = colour(group[i]);
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
            chart.draw_series([Circle::new((d.settled_fraction, y), 5, c.filled())])?;
        }
        Ok(())
    }
}

/// Settling time against unbalance / capacity, one panel per geometry, colour by drag.
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
        let mut drags: Vec<f64> = designs.iter().map(|d| d.drag).collect();
        drags.sort_by(f64::total_cmp);
        drags.dedup();
        let geometry_of = |r: &RunRecord| {
            designs
                .iter()
                .position(|d| d.design_id == r.design_id)
                .map(|i| group[i])
        };
        let settled = runs
            .iter()
            .filter(|r| r.metrics.settled)
            .filter_map(|r| r.metrics.settling_revs)
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
        let body = root.titled(&title, text(style::TITLE))?;
        let (legend, body) = body.split_vertically(34);
        let red = RGBColor(200, 0, 0);
        let mut entries: Vec<(String, Swatch)> = drags
            .iter()
            .enumerate()
            .map(|(k, d)| (format!("β = {} N·s/m", short(*d)), Swatch::Dot(colour(k))))
            .collect();
        if any_unsettled {
            entries.push((
                "not settled (row above the data)".into(),
                Swatch::Cross(red),
            ));
        }
        style::legend_row(&legend, &entries)?;
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
                .y_desc("settling time t_s  (rev)")
                .axis_desc_style(text(style::AXIS))
                .label_style(text(TICK))
                .x_label_formatter(&linear_label)
                .y_label_formatter(&y_format)
                .light_line_style(WHITE.mix(0.0))
                .bold_line_style(BLACK.mix(0.08))
                .draw()?;
            for (k, drag) in drags.iter().enumerate() {
                let c = colour(k);
                chart.draw_series(
                    mine.iter()
                        .filter(|r| r.drag == *drag && r.metrics.settled)
                        .filter_map(|r| Some((r.unbalance_fraction, r.metrics.settling_revs?)))
                        .map(|p| Circle::new(p, 2, c.mix(0.55).filled())),
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

/// The three figures of a study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StudyFigure {
    /// Settling-time box plots per design.
    SettlingTime,
    /// Settled fraction per design with Wilson intervals.
    SettledFraction,
    /// Settling time against unbalance / capacity.
    SettlingVsUnbalance,
}

impl StudyFigure {
    /// All three, in the order [`plot_study`] writes them.
    pub const ALL: [StudyFigure; 3] = [
        StudyFigure::SettlingTime,
        StudyFigure::SettledFraction,
        StudyFigure::SettlingVsUnbalance,
    ];

    /// The file name without extension.
    pub fn file_stem(self) -> &'static str {
        match self {
            StudyFigure::SettlingTime => "settling_time",
            StudyFigure::SettledFraction => "settled_fraction",
            StudyFigure::SettlingVsUnbalance => "settling_vs_unbalance",
        }
    }

    /// Draw this figure of `data` into `path` (.svg or .png).
    pub fn plot(self, data: &StudyData, path: &Path) -> Result<(), PlotError> {
        match self {
            StudyFigure::SettlingTime => plot_settling_times(data, path),
            StudyFigure::SettledFraction => plot_settled_fraction(data, path),
            StudyFigure::SettlingVsUnbalance => plot_settling_vs_unbalance(data, path),
        }
    }
}

/// Write `figures` into `out_dir` as `<file_stem>.<format>`; returns their paths.
pub fn plot_study(
    data: &StudyData,
    out_dir: &Path,
    format: Format,
    figures: &[StudyFigure],
) -> Result<Vec<PathBuf>, PlotError> {
    figures
        .iter()
        .map(|figure| {
            let path = out_dir.join(format!("{}.{}", figure.file_stem(), format.extension()));
            figure.plot(data, &path).map(|()| path)
        })
        .collect()
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

    #[test]
    fn labels_name_only_what_varies() {
        let d = |id, rho, drag| DesignStats {
            design_id: id,
            kind: "ball".into(),
            n: 3,
            rho,
            drag,
            runs: 10,
            settled_fraction: 1.0,
            settled_lo: 0.7,
            settled_hi: 1.0,
        };
        let l = labels(&[d(0, 0.25, 2.0), d(1, 0.25, 5.0)]);
        assert_eq!(l.per_design, vec!["β = 2 N·s/m", "β = 5 N·s/m"]);
        assert_eq!(l.common, "3 balls, ρ = 0.25");
    }
}
