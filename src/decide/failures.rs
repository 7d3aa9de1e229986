//! Runs that did not finish are never absorbed: after a study has written
//! everything, this says how many runs ended `budget_exceeded` or
//! `solver_failed`, why, and which setting to change (`study run` then
//! exits 1).

use crate::metrics::{Budget, Outcome};
use crate::study::plan::config::StudyPlan;
use polars::prelude::*;
use std::path::Path;

/// The one-line advice for a runs table with failed runs; `None` when every
/// run finished (settled, censored, not settled or diverged).
pub fn failure_advice(plan: &StudyPlan, runs_path: &Path) -> PolarsResult<Option<String>> {
    let file = std::fs::File::open(runs_path)
        .map_err(|e| polars_err!(ComputeError: "cannot read {}: {e}", runs_path.display()))?;
    let df = ParquetReader::new(file)
        .with_columns(Some(vec!["outcome".into(), "reason".into()]))
        .finish()?;
    let outcome = df.column("outcome")?.str()?;
    let reason = df.column("reason")?.str()?;
    let (mut steps, mut wall, mut failed) = (0u64, 0u64, 0u64);
    for (o, r) in outcome.iter().zip(reason.iter()) {
        match o.and_then(Outcome::parse) {
            Some(Outcome::BudgetExceeded) => match Budget::of_reason(r.unwrap_or_default()) {
                Budget::WallTime => wall += 1,
                Budget::Steps => steps += 1,
            },
            Some(Outcome::SolverFailed) => failed += 1,
            _ => {}
        }
    }
    let total = steps + wall + failed;
    if total == 0 {
        return Ok(None);
    }
    let solver = &plan.file.solver;
    let mut parts = Vec::new();
    if steps > 0 {
        parts.push(format!(
            "{steps} ran out of steps: raise [solver] max_steps (now {})",
            solver.max_steps
        ));
    }
    if wall > 0 {
        parts.push(format!(
            "{wall} ran out of time: raise [solver] max_wall_seconds (now {})",
            solver.max_wall_seconds
        ));
    }
    if failed > 0 {
        parts.push(format!(
            "{failed} solver_failed (step size underflow or Newton failure): set [solver] method = \"radau5\" or loosen rtol (now {:e})",
            solver.rtol
        ));
    }
    Ok(Some(format!(
        "{total} of {} runs did not finish ({}); the statistics count them as not settled by the horizon, so the ranking may be wrong; their reasons are in runs.parquet",
        df.height(),
        parts.join("; ")
    )))
}
