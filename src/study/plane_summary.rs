//! Per-plane statistics of `summary.parquet` for rotors with several
//! watched planes (balancer planes, then the load's planes): per design and
//! plane, the share of runs in which that plane settled into its own band
//! δ·A_ref of the plane, the Kaplan–Meier median of when it did, and the
//! 95th percentile of its absolute residual. Runs without per-plane values
//! (failed runs) count as not settled and have no residual, as in the
//! design-level statistics.

use super::config::StudyPlan;
use super::design_runs::SettlingClock;
use crate::stats::quantile::{Interpolation, quantile_sorted};
use crate::stats::survival::{KaplanMeier, Observation};
use polars::prelude::*;

/// Names of the per-plane summary columns of plane `p`, as written.
pub fn column_names(p: usize) -> [String; 3] {
    [
        format!("settled_fraction_plane{p}"),
        format!("settling_revs_median_km_plane{p}"),
        format!("residual_abs_p95_plane{p}"),
    ]
}

/// A list column of `runs` as one vector per row (nulls kept).
fn lists(runs: &DataFrame, name: &str) -> PolarsResult<Vec<Vec<Option<f64>>>> {
    let list = runs.column(name)?.list()?;
    (0..list.len())
        .map(|i| match list.get_as_series(i) {
            Some(s) => Ok(s.f64()?.iter().collect()),
            None => Ok(Vec::new()),
        })
        .collect()
}

/// Append the per-plane columns to `summary` (one row per design of `plan`,
/// in plan order) from `runs` (the summary's projection of the runs
/// table); nothing when the runs carry no per-plane settling times. Times
/// are counted as the design-level ones are (`clock`); a plane that did not
/// settle is censored where its run was (or at `tau`).
pub fn append_columns(
    summary: &mut DataFrame,
    runs: &DataFrame,
    plan: &StudyPlan,
    tau: f64,
    clock: SettlingClock,
) -> PolarsResult<()> {
    if runs.column("plane_settling_revs").is_err() {
        return Ok(());
    }
    let settling = lists(runs, "plane_settling_revs")?;
    let residual = lists(runs, "plane_residual_abs")?;
    let planes = settling.iter().map(Vec::len).max().unwrap_or(0);
    if planes == 0 {
        return Ok(());
    }
    let design = runs.column("design_id")?.u32()?;
    let censoring = runs.column("censoring_revs")?.f64()?;
    let operating = runs.column("operating_time_s")?.f64()?;
    let mut columns: Vec<[Vec<Option<f64>>; 3]> = vec![Default::default(); planes];
    for d in &plan.designs {
        let rows: Vec<usize> = (0..runs.height())
            .filter(|&i| design.get(i) == Some(d.id))
            .collect();
        for (p, out) in columns.iter_mut().enumerate() {
            let mut observations = Vec::with_capacity(rows.len());
            let mut residuals = Vec::new();
            for &i in &rows {
                let offset = match clock {
                    SettlingClock::FromStart => 0.0,
                    SettlingClock::FromOperatingSpeed(rev) => {
                        operating.get(i).map_or(0.0, |t| t / rev)
                    }
                };
                observations.push(match settling[i].get(p).copied().flatten() {
                    Some(t) => Observation {
                        time: (t - offset).max(0.0),
                        settled: true,
                    },
                    None => Observation {
                        time: (censoring.get(i).unwrap_or(tau) - offset).max(0.0),
                        settled: false,
                    },
                });
                if let Some(r) = residual[i]
                    .get(p)
                    .copied()
                    .flatten()
                    .filter(|r| r.is_finite())
                {
                    residuals.push(r);
                }
            }
            let settled = observations.iter().filter(|o| o.settled).count();
            out[0].push((!rows.is_empty()).then(|| settled as f64 / rows.len() as f64));
            out[1].push(KaplanMeier::fit(&observations).and_then(|km| km.median()));
            residuals.sort_by(f64::total_cmp);
            out[2].push(quantile_sorted(&residuals, 0.95, Interpolation::Linear));
        }
    }
    for (p, values) in columns.into_iter().enumerate() {
        for (name, v) in column_names(p).into_iter().zip(values) {
            summary.with_column(Column::new(name.into(), v))?;
        }
    }
    Ok(())
}
