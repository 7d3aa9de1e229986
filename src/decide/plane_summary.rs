//! Per-plane statistics of `summary.parquet` for rotors with several
//! watched planes (balancer planes, then the load's planes): per design and
//! plane, the share of runs in which that plane settled into its own band
//! δ·A_ref of the plane, the Kaplan–Meier median of when it did, the
//! 95th percentile of its absolute residual, that band at the plane's
//! median A_ref and, with rolling resistance, its weights' dead band. Runs without per-plane values
//! (failed runs) count as not settled and have no residual, as in the
//! design-level statistics.

use crate::stats::quantile::{Interpolation, quantile_sorted};
use crate::stats::survival::{KaplanMeier, Observation};
use crate::study::plan::config::StudyPlan;
use crate::study::results::design_runs::SettlingClock;
use polars::prelude::*;

/// Names of the per-plane summary columns of plane `p`, as written.
pub fn column_names(p: usize) -> [String; 5] {
    [
        format!("settled_fraction_plane{p}"),
        format!("settling_revs_median_km_plane{p}"),
        format!("residual_abs_p95_plane{p}"),
        format!("settling_band_m_plane{p}"),
        format!("dead_band_m_plane{p}"),
    ]
}

/// A list column of `runs` as one vector per row (nulls kept); empty rows
/// when it is absent.
fn lists(runs: &DataFrame, name: &str) -> PolarsResult<Vec<Vec<Option<f64>>>> {
    Ok(crate::study::results::record::nullable_lists(runs, name)?
        .unwrap_or_else(|| vec![Vec::new(); runs.height()]))
}

/// One plane's statistics over a set of runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneStats {
    /// Share of the runs in which the plane settled.
    pub settled_fraction: Option<f64>,
    /// Kaplan–Meier median of when it settled (revolutions, as the clock counts).
    pub settling_median_km: Option<f64>,
    /// 95th percentile of its absolute residual (m).
    pub residual_abs_p95: Option<f64>,
    /// Its own settling band δ·A_ref at its median A_ref (m).
    pub settling_band: Option<f64>,
}

/// The per-plane columns of a runs table (summary projection or whole).
pub struct PlaneRuns {
    settling: Vec<Vec<Option<f64>>>,
    residual: Vec<Vec<Option<f64>>>,
    a_ref: Vec<Vec<Option<f64>>>,
    censoring: Vec<Option<f64>>,
    operating: Vec<Option<f64>>,
    /// Watched planes.
    pub planes: usize,
}

impl PlaneRuns {
    /// The per-plane columns of `runs`; `None` when it has none.
    pub fn read(runs: &DataFrame) -> PolarsResult<Option<PlaneRuns>> {
        if runs.column("plane_settling_revs").is_err() {
            return Ok(None);
        }
        let settling = lists(runs, "plane_settling_revs")?;
        let planes = settling.iter().map(Vec::len).max().unwrap_or(0);
        if planes == 0 {
            return Ok(None);
        }
        Ok(Some(PlaneRuns {
            residual: lists(runs, "plane_residual_abs")?,
            a_ref: lists(runs, "plane_a_ref")?,
            settling,
            censoring: runs.column("censoring_revs")?.f64()?.iter().collect(),
            operating: runs.column("operating_time_s")?.f64()?.iter().collect(),
            planes,
        }))
    }

    /// Plane p's statistics over the runs at `rows`, times counted by
    /// `clock`; a plane that did not settle is censored where its run was
    /// (or at `tau`).
    pub fn stats(
        &self,
        rows: &[usize],
        p: usize,
        (tau, delta): (f64, f64),
        clock: SettlingClock,
    ) -> PlaneStats {
        let mut observations = Vec::with_capacity(rows.len());
        let mut residuals = Vec::new();
        let mut a_refs: Vec<f64> = rows
            .iter()
            .filter_map(|&i| self.a_ref.get(i)?.get(p).copied().flatten())
            .collect();
        a_refs.sort_by(f64::total_cmp);
        for &i in rows {
            let offset = match clock {
                SettlingClock::FromStart => 0.0,
                SettlingClock::FromOperatingSpeed(rev) => {
                    self.operating[i].map_or(0.0, |t| t / rev)
                }
            };
            observations.push(match self.settling[i].get(p).copied().flatten() {
                Some(t) => Observation {
                    time: (t - offset).max(0.0),
                    settled: true,
                },
                None => Observation {
                    time: (self.censoring[i].unwrap_or(tau) - offset).max(0.0),
                    settled: false,
                },
            });
            if let Some(r) = self.residual[i]
                .get(p)
                .copied()
                .flatten()
                .filter(|r| r.is_finite())
            {
                residuals.push(r);
            }
        }
        let settled = observations.iter().filter(|o| o.settled).count();
        residuals.sort_by(f64::total_cmp);
        PlaneStats {
            settled_fraction: (!rows.is_empty()).then(|| settled as f64 / rows.len() as f64),
            settling_median_km: KaplanMeier::fit(&observations).and_then(|km| km.median()),
            residual_abs_p95: quantile_sorted(&residuals, 0.95, Interpolation::Linear),
            settling_band: quantile_sorted(&a_refs, 0.5, Interpolation::Linear).map(|a| delta * a),
        }
    }
}

/// Append the per-plane columns to `summary` (one row per design of `plan`,
/// in plan order) from `runs` (the summary's projection of the runs
/// table); nothing when the runs carry no per-plane settling times. Times
/// are counted as the design-level ones are (`clock`).
pub fn append_columns(
    summary: &mut DataFrame,
    runs: &DataFrame,
    plan: &StudyPlan,
    tau: f64,
    clock: SettlingClock,
) -> PolarsResult<()> {
    let Some(planes) = PlaneRuns::read(runs)? else {
        return Ok(());
    };
    let design = runs.column("design_id")?.u32()?;
    let mut columns: Vec<[Vec<Option<f64>>; 5]> = vec![Default::default(); planes.planes];
    let balancer_planes = plan.file.scene.rotor.as_rotor().planes();
    for d in &plan.designs {
        let rows: Vec<usize> = (0..runs.height())
            .filter(|&i| design.get(i) == Some(d.id))
            .collect();
        for (p, out) in columns.iter_mut().enumerate() {
            let s = planes.stats(&rows, p, (tau, plan.file.metrics.delta), clock);
            out[0].push(s.settled_fraction);
            out[1].push(s.settling_median_km);
            out[2].push(s.residual_abs_p95);
            out[3].push(s.settling_band);
            // Only the balancer planes hold weights that can stop short.
            out[4].push(
                (p < balancer_planes)
                    .then(|| crate::decide::diagnosis::plane_dead_band(plan, d, p))
                    .flatten(),
            );
        }
    }
    for (p, values) in columns.into_iter().enumerate() {
        for (name, v) in column_names(p).into_iter().zip(values) {
            summary.with_column(Column::new(name.into(), v))?;
        }
    }
    Ok(())
}
