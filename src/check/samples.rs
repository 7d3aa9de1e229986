//! The per-design samples a check compares, read from a runs table.
//!
//! Works on the full `runs.parquet` of `study run` and on the trimmed one of
//! a baseline alike: only the columns in [`COLUMNS`] are read. Settling
//! times are those of settled runs, residual vibration that of every run
//! simulated to the end (settled or not), as in `summary.parquet`.

use crate::metrics::Outcome;
use polars::prelude::*;

/// Columns a check needs from a runs table.
pub const COLUMNS: [&str; 11] = [
    "run_id",
    "design_id",
    "sample_id",
    "kind",
    "n",
    "rho",
    "drag",
    "outcome",
    "settled",
    "settling_revs",
    "residual_rel",
];

/// Per-plane column a check also reads when a runs table has it (rotors
/// with several planes; a baseline keeps it).
pub const PLANE_COLUMNS: [&str; 1] = ["plane_settling_revs"];

/// The columns a check reads from `df`: [`COLUMNS`], and [`PLANE_COLUMNS`]
/// where `df` has them.
pub fn columns_of(df: &DataFrame) -> Vec<&'static str> {
    let mut columns = COLUMNS.to_vec();
    columns.extend(PLANE_COLUMNS.iter().filter(|c| df.column(c).is_ok()));
    columns
}

/// One watched plane's runs of a design, reduced to what the tests compare.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlaneSample {
    /// Runs in which the plane settled.
    pub settled: u64,
    /// When it settled (revolutions), in run order.
    pub settling_revs: Vec<f64>,
}

/// One design's runs, reduced to what the tests compare.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSample {
    /// Design index in grid order.
    pub design_id: u32,
    /// Human label: kind, n, ρ and β.
    pub label: String,
    /// Number of runs.
    pub runs: u64,
    /// Number of settled runs.
    pub settled: u64,
    /// Settling times of the settled runs (revolutions), in run order.
    pub settling_revs: Vec<f64>,
    /// residual_rel of the runs simulated to the end, in run order.
    pub residual_rel: Vec<f64>,
    /// Each watched plane's runs (rotors with several planes; empty otherwise).
    pub planes: Vec<PlaneSample>,
}

/// Split a runs table into one sample per design, in design order.
pub fn design_samples(df: &DataFrame) -> PolarsResult<Vec<DesignSample>> {
    let design: Vec<u32> = df.column("design_id")?.u32()?.into_no_null_iter().collect();
    let kind = df.column("kind")?.str()?.clone();
    let n = df.column("n")?.u32()?.clone();
    let rho = df.column("rho")?.f64()?.clone();
    let drag = df.column("drag")?.f64()?.clone();
    let outcome = df.column("outcome")?.str()?.clone();
    let settled = df.column("settled")?.bool()?.clone();
    let revs = df.column("settling_revs")?.f64()?.clone();
    let residual = df.column("residual_rel")?.f64()?.clone();
    let plane_settling = crate::study::results::record::nullable_lists(df, PLANE_COLUMNS[0])?;
    let mut out: Vec<DesignSample> = Vec::new();
    let mut order: Vec<usize> = (0..df.height()).collect();
    order.sort_by_key(|&i| design[i]);
    for i in order {
        if out.last().is_none_or(|s| s.design_id != design[i]) {
            out.push(DesignSample {
                design_id: design[i],
                label: format!(
                    "{} n={} ρ={:.4} β={}",
                    kind.get(i).unwrap_or("?"),
                    n.get(i).unwrap_or(0),
                    rho.get(i).unwrap_or(f64::NAN),
                    drag.get(i).unwrap_or(f64::NAN)
                ),
                runs: 0,
                settled: 0,
                settling_revs: Vec::new(),
                residual_rel: Vec::new(),
                planes: Vec::new(),
            });
        }
        let s = out.last_mut().expect("pushed above");
        s.runs += 1;
        if let Some(per_run) = plane_settling.as_ref().map(|v| &v[i]) {
            if s.planes.len() < per_run.len() {
                s.planes.resize(per_run.len(), PlaneSample::default());
            }
            for (plane, t) in s.planes.iter_mut().zip(per_run) {
                if let Some(t) = t {
                    plane.settled += 1;
                    plane.settling_revs.push(*t);
                }
            }
        }
        if settled.get(i) == Some(true) {
            s.settled += 1;
            if let Some(t) = revs.get(i) {
                s.settling_revs.push(t);
            }
        }
        if outcome
            .get(i)
            .and_then(Outcome::parse)
            .is_some_and(Outcome::has_residual)
            && let Some(r) = residual.get(i)
        {
            s.residual_rel.push(r);
        }
    }
    Ok(out)
}
