//! One study's figures, one file per figure: settling-time distributions
//! per design over every run ([`settling_time`]), the settled fraction with its Wilson
//! intervals ([`settled_fraction`]), and settling time against the unbalance
//! as a fraction of capacity ([`settling_vs_unbalance`]). This file reads the
//! study's data and lists the figures; `labels.rs` names and groups designs.

mod labels;
pub mod passage;
pub mod sensitivity;
pub mod settled_fraction;
pub mod settling_time;
pub mod settling_vs_unbalance;

pub use passage::plot_passage;
pub use sensitivity::{TotalIndex, plot_sensitivity};
pub use settled_fraction::plot_settled_fraction;
pub use settling_time::plot_settling_times;
pub use settling_vs_unbalance::plot_settling_vs_unbalance;

use super::{Format, PlotError};
use crate::stats::survival::Observation;
use crate::study::results::record::{RunRecord, from_dataframe};
use crate::study::results::results_table::{TableKind, read_table};
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
    /// Every balancer plane's (kind, n, ρ, β) when the planes have designs
    /// of their own (`kind_plane0`, … columns of the summary); empty otherwise.
    pub planes: Vec<PlaneDesignStats>,
    /// The motor's stall torque M_s (N·m) when the design drives the rotor
    /// through a motor (`designs.stall_torque`); `None` otherwise.
    pub stall_torque: Option<f64>,
}

/// One balancer plane's design as the summary names it.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneDesignStats {
    /// Balancer kind.
    pub kind: String,
    /// Number of weights.
    pub n: u32,
    /// Radius ratio ρ.
    pub rho: f64,
    /// Drag coefficient β (N·s/m).
    pub drag: f64,
}

/// Each row's per-plane designs, from the `kind_plane{p}` … columns.
fn plane_designs(summary: &DataFrame) -> Result<Vec<Vec<PlaneDesignStats>>, PlotError> {
    let mut rows = vec![Vec::new(); summary.height()];
    let mut p = 0;
    while summary.column(&format!("n_plane{p}")).is_ok() {
        let kinds = summary.column(&format!("kind_plane{p}"))?.str()?.clone();
        let ns = summary.column(&format!("n_plane{p}"))?.u32()?.clone();
        let rho = summary.column(&format!("rho_plane{p}"))?.f64()?.clone();
        let drag = summary.column(&format!("drag_plane{p}"))?.f64()?.clone();
        for (i, row) in rows.iter_mut().enumerate() {
            row.push(PlaneDesignStats {
                kind: kinds.get(i).unwrap_or_default().to_string(),
                n: ns.get(i).unwrap_or_default(),
                rho: rho.get(i).unwrap_or(f64::NAN),
                drag: drag.get(i).unwrap_or(f64::NAN),
            });
        }
        p += 1;
    }
    Ok(rows)
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
    let mut planes = plane_designs(summary)?.into_iter();
    // Older summaries have no stall_torque column: no design had a motor.
    let stall: Vec<Option<f64>> = match summary.column("stall_torque") {
        Ok(c) => c.cast(&DataType::Float64)?.f64()?.iter().collect(),
        Err(_) => vec![None; summary.height()],
    };
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
                planes: planes.next().unwrap_or_default(),
                stall_torque: stall[i],
            })
        })
        .collect()
}

/// The operating speed of the study in `dir`, from its `study.toml`; a
/// figure only marks it, so a folder without a readable plan goes without.
fn operating_speed(dir: &Path) -> Option<f64> {
    use crate::study::plan::config::StudyFile;
    let shown = dir.display().to_string();
    let text = std::fs::read_to_string(dir.join("study.toml")).ok()?;
    let plan = StudyFile::parse(&text, &shown)
        .and_then(|f| f.plan(&text, &shown))
        .ok()?;
    Some(plan.file.scene.speed.nominal_speed()).filter(|w| w.is_finite() && *w > 0.0)
}

/// The total indices on the capped settling time in `dir`'s
/// sensitivity.parquet; none when the folder has no such file.
fn total_indices(dir: &Path) -> Result<Vec<TotalIndex>, PlotError> {
    let path = dir.join(crate::study::sensitivity::FILE);
    if !path.is_file() {
        return Ok(Vec::new());
    }
    let df = crate::study::results::io::read_parquet(&path)
        .map_err(|e| PlotError::unreadable(&path, e))?;
    let settling = crate::study::sensitivity::Measure::RestrictedSettling.name();
    let (design, measure, input) = (
        df.column("design_id")?.u32()?.clone(),
        df.column("measure")?.str()?.clone(),
        df.column("input")?.str()?.clone(),
    );
    let (t, lo, hi) = (
        df.column("total_order")?.f64()?.clone(),
        df.column("total_order_lo")?.f64()?.clone(),
        df.column("total_order_hi")?.f64()?.clone(),
    );
    Ok((0..df.height())
        .filter(|&i| measure.get(i) == Some(settling))
        .filter_map(|i| {
            Some(TotalIndex {
                design_id: design.get(i)?,
                input: input.get(i)?.to_string(),
                total: (t.get(i)?, lo.get(i)?, hi.get(i)?),
            })
        })
        .collect())
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
    /// The speed law's operating speed (rad/s) from the folder's
    /// `study.toml`; `None` when it cannot be read.
    pub operating_speed: Option<f64>,
    /// The total indices on the capped settling time from the folder's
    /// sensitivity.parquet (`study sensitivity`); empty without one.
    pub sensitivity: Vec<TotalIndex>,
}

impl StudyData {
    /// Read `runs.parquet` and `summary.parquet` from a study's output folder.
    pub fn read(dir: &Path) -> Result<Self, PlotError> {
        let open = |file: &str, kind: TableKind| {
            let path = dir.join(file);
            if !path.is_file() {
                return Err(PlotError::invalid(
                    path.display().to_string(),
                    "not found: give the output folder of `study run`",
                ));
            }
            read_table(&path, kind).map_err(|e| PlotError::unreadable(&path, e))
        };
        let runs = from_dataframe(&open("runs.parquet", TableKind::Runs)?)?;
        let designs = design_stats(&open("summary.parquet", TableKind::Summary)?)?;
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
            operating_speed: operating_speed(dir),
            sensitivity: total_indices(dir)?,
        })
    }

    /// Refuse a study without designs or runs.
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
            .filter_map(|r| self.settled_revs(r))
            .filter(|v| v.is_finite())
            .collect()
    }

    /// Revolutions of run `r` before the rotor reached its operating speed:
    /// the figures count settling from there, as the ranking does on a
    /// run-up (0 at a constant speed, or without the operating speed).
    fn run_up_revs(&self, r: &RunRecord) -> f64 {
        match (self.operating_speed, r.metrics.operating_time) {
            (Some(omega), Some(t)) if omega > 0.0 => t * omega / std::f64::consts::TAU,
            _ => 0.0,
        }
    }

    /// Run `r`'s settling time on the ranking's clock (revolutions after
    /// the operating speed was reached); `None` when it did not settle.
    fn settled_revs(&self, r: &RunRecord) -> Option<f64> {
        let t = r.metrics.settling_revs.filter(|_| r.metrics.settled)?;
        Some((t - self.run_up_revs(r)).max(0.0))
    }

    /// What a settling-time axis counts: revolutions, and on a run-up from
    /// when (every figure counts from the operating speed, as the ranking).
    fn settling_axis(&self) -> &'static str {
        let run_up = self.runs.iter().any(|r| self.run_up_revs(r) > 0.0);
        if run_up {
            "revolutions after reaching the operating speed"
        } else {
            "revolutions"
        }
    }

    /// Every run of one design as a settling observation (revolutions):
    /// settled at its time, or censored unsettled.
    fn settling_observations(&self, design_id: u32) -> Vec<Observation> {
        // runs.parquet gives a censoring time only to runs simulated to their
        // end, and does not hold the horizon; the others are censored at the
        // latest time any run shows. Quantiles, all the figures draw from the
        // fit, do not depend on where beyond the last settling a run is censored.
        let latest = self
            .runs
            .iter()
            .flat_map(|r| [r.metrics.settling_revs, r.metrics.censoring_revs])
            .flatten()
            .filter(|t| t.is_finite())
            .fold(0.0, f64::max);
        self.runs
            .iter()
            .filter(|r| r.design_id == design_id)
            .map(|r| match self.settled_revs(r) {
                Some(t) if t.is_finite() => Observation {
                    time: t,
                    settled: true,
                },
                _ => Observation {
                    time: (r.metrics.censoring_revs.unwrap_or(latest) - self.run_up_revs(r))
                        .max(0.0),
                    settled: false,
                },
            })
            .collect()
    }
}

/// The three figures of a study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StudyFigure {
    /// Settling-time box plots per design (Kaplan–Meier quartiles over every run).
    SettlingTime,
    /// Settled fraction per design with Wilson intervals.
    SettledFraction,
    /// Settling time against unbalance / capacity.
    SettlingVsUnbalance,
    /// Final spin rate against the motor's stall torque (studies that sweep
    /// it; not in [`StudyFigure::ALL`]).
    Passage,
    /// Each input's total Sobol index per design (folders where `study
    /// sensitivity` wrote sensitivity.parquet; not in [`StudyFigure::ALL`]).
    Sensitivity,
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
            StudyFigure::Passage => "passage",
            StudyFigure::Sensitivity => "sensitivity",
        }
    }

    /// Draw this figure of `data` into `path` (.svg or .png).
    pub fn plot(self, data: &StudyData, path: &Path) -> Result<(), PlotError> {
        match self {
            StudyFigure::SettlingTime => plot_settling_times(data, path),
            StudyFigure::SettledFraction => plot_settled_fraction(data, path),
            StudyFigure::SettlingVsUnbalance => plot_settling_vs_unbalance(data, path),
            StudyFigure::Passage => plot_passage(data, path),
            StudyFigure::Sensitivity => plot_sensitivity(data, path),
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
    // Every figure's data is checked before the folder or any figure is made.
    data.check()?;
    if figures.contains(&StudyFigure::Passage) {
        passage::passage_data(data)?;
    }
    if figures.contains(&StudyFigure::Sensitivity) {
        sensitivity::sensitivity_data(data)?;
    }
    std::fs::create_dir_all(out_dir).map_err(|e| {
        PlotError::Io(std::io::Error::new(
            e.kind(),
            format!("{}: {e}", out_dir.display()),
        ))
    })?;
    figures
        .iter()
        .map(|figure| {
            let path = out_dir.join(format!("{}.{}", figure.file_stem(), format.extension()));
            figure.plot(data, &path).map(|()| path)
        })
        .collect()
}
