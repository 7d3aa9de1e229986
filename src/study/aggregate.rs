//! Per-design statistics of a study (`summary.parquet`), computed with polars.
//!
//! Settling statistics use the settled runs and are in revolutions; residual
//! vibration uses every run that was simulated to the end (settled or not),
//! i.e. the distribution over the sampled unbalances; diverged and failed runs
//! are counted, not averaged.

use super::config::StudyPlan;
use super::record::{RunRecord, to_dataframe};
use super::sample::{Purpose, stream};
use crate::model::gap::GapGauge;
use crate::stats::bootstrap;
use crate::stats::interval::wilson_interval;
use crate::stats::quantile::{Interpolation, quantile_sorted};
use polars::prelude::*;

/// Non-null values of a column, sorted for [`quantile_sorted`].
///
/// The quantiles were polars's `QuantileMethod::Linear` (and its `median`),
/// which [`Interpolation::Linear`] reproduces bit for bit: same position,
/// same formula. Polars orders −0.0 with +0.0 and every NaN last, where
/// `f64::total_cmp` does not; neither value occurs here, as settling times
/// are (t − t₀)/T with t ≥ t₀ and residuals are RMS/A_ref of finite runs.
fn sorted_values(ca: &Float64Chunked) -> Vec<f64> {
    let mut v: Vec<f64> = ca.iter().flatten().collect();
    v.sort_by(f64::total_cmp);
    v
}

/// The median settling time over every run of a design, a run that did not
/// settle counting as "later than any settled one": censored runs are only
/// known to settle after t_end − W, which no settled run's t_s exceeds (its
/// hold had to complete by t_end), and diverged or failed runs never settle.
/// With such censoring this is exactly the Kaplan–Meier median. `None` when
/// half the runs or more did not settle: the median is then beyond the run.
fn median_counting_unsettled(settled_sorted: &[f64], runs: u64) -> Option<f64> {
    let runs = runs as usize;
    if runs == 0 {
        return None;
    }
    // Lower and upper middle order statistics of all runs (unsettled = +∞).
    let (lo, hi) = ((runs - 1) / 2, runs / 2);
    let at = |i: usize| settled_sorted.get(i).copied();
    Some(0.5 * (at(lo)? + at(hi)?))
}

/// The q-quantile (linear interpolation) over every run of a design, runs
/// that did not settle counting as later than every settled one; `None`
/// when it falls among them (beyond the run).
fn quantile_counting_unsettled(settled_sorted: &[f64], runs: u64, q: f64) -> Option<f64> {
    if runs == 0 {
        return None;
    }
    let h = q * (runs - 1) as f64;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    let (a, b) = (*settled_sorted.get(lo)?, *settled_sorted.get(hi)?);
    Some(a + (h - lo as f64) * (b - a))
}

/// One row per design, in design order.
pub fn summarize(plan: &StudyPlan, runs: &[RunRecord]) -> PolarsResult<DataFrame> {
    summarize_table(plan, &to_dataframe(runs)?)
}

/// One row per design from a runs table holding at least the columns in
/// [`super::runs_file::SUMMARY_COLUMNS`].
pub fn summarize_table(plan: &StudyPlan, df: &DataFrame) -> PolarsResult<DataFrame> {
    let design_col = df.column("design_id")?.u32()?.clone();
    let mut rows = SummaryColumns::default();
    for design in &plan.designs {
        let mine = df.filter(&design_col.equal(design.id))?;
        let outcome = mine.column("outcome")?.str()?.clone();
        let count = |name: &str| outcome.equal(name).sum().unwrap_or(0) as u64;
        let settled_mask = mine.column("settled")?.bool()?.clone();
        let settled = mine.filter(&settled_mask)?;
        let ts = settled.column("settling_revs")?.f64()?.clone();
        let simulated = mine.filter(
            &(outcome.equal("settled") | outcome.equal("censored") | outcome.equal("not_settled")),
        )?;
        let residual = simulated.column("residual_rel")?.f64()?.clone();
        let runs_n = mine.height() as u64;
        let settled_n = settled.height() as u64;
        let (lo, hi) = wilson_interval(settled_n, runs_n);
        let ts_values: Vec<f64> = ts.into_no_null_iter().collect();
        let mut rng = stream(plan.file.seed, Some(design.id), 0, Purpose::Bootstrap);
        let ci = bootstrap::mean_ci(&ts_values, &mut rng);

        rows.design_id.push(design.id);
        rows.kind.push(design.spec.kind.name().to_string());
        rows.n.push(design.spec.n);
        rows.rho.push(design.rho);
        rows.drag.push(design.spec.drag);
        rows.capacity.push(design.capacity);
        rows.runs.push(runs_n);
        rows.settled.push(settled_n);
        rows.settled_fraction.push(if runs_n == 0 {
            0.0
        } else {
            settled_n as f64 / runs_n as f64
        });
        rows.settled_lo.push(lo);
        rows.settled_hi.push(hi);
        rows.ts_mean.push(ts.mean());
        rows.ts_std.push(ts.std(1));
        let ts_sorted = sorted_values(&ts);
        let ts_q = |q| quantile_sorted(&ts_sorted, q, Interpolation::Linear);
        rows.ts_median.push(ts_q(0.5));
        rows.ts_median_all
            .push(median_counting_unsettled(&ts_sorted, runs_n));
        rows.ts_p90_all
            .push(quantile_counting_unsettled(&ts_sorted, runs_n, 0.9));
        rows.ts_p10.push(ts_q(0.10));
        rows.ts_p90.push(ts_q(0.90));
        rows.ts_p95.push(ts_q(0.95));
        rows.ts_max.push(ts.max());
        rows.ts_ci_lo.push(ci.map(|c| c.0));
        rows.ts_ci_hi.push(ci.map(|c| c.1));
        rows.res_mean.push(residual.mean());
        let res_sorted = sorted_values(&residual);
        let res_q = |q| quantile_sorted(&res_sorted, q, Interpolation::Linear);
        rows.res_median.push(res_q(0.5));
        rows.res_p95.push(res_q(0.95));
        rows.censored.push(count("censored"));
        rows.not_settled.push(count("not_settled"));
        rows.diverged.push(count("diverged"));
        rows.solver_failed.push(count("solver_failed"));
        rows.budget_exceeded.push(count("budget_exceeded"));
        // Whether the weights were solid, and how close they came in the
        // worst run (negative: they overlapped).
        let contact = mine.column("contact")?.bool()?.clone();
        rows.contact.push(contact.all());
        let min_gap = mine.column("min_gap_rad")?.f64()?.min();
        rows.min_gap.push(min_gap);
        // The deepest overlap as a share of the touching angle 2α: what the
        // penalty contact lets through (docs/model.md: below 2 % by default).
        let touching = plan
            .scene(design, 0.0, 0.0)
            .cargoes()
            .ok()
            .and_then(|c| GapGauge::new(&c))
            .map(|g| g.contact_angle());
        rows.max_overlap.push(
            min_gap
                .zip(touching)
                .map(|(gap, angle)| (-gap).max(0.0) / angle),
        );
    }
    rows.into_dataframe()
}

/// Column buffers of the summary table.
#[derive(Default)]
struct SummaryColumns {
    design_id: Vec<u32>,
    kind: Vec<String>,
    n: Vec<u32>,
    rho: Vec<f64>,
    drag: Vec<f64>,
    capacity: Vec<f64>,
    runs: Vec<u64>,
    settled: Vec<u64>,
    settled_fraction: Vec<f64>,
    settled_lo: Vec<f64>,
    settled_hi: Vec<f64>,
    ts_mean: Vec<Option<f64>>,
    ts_std: Vec<Option<f64>>,
    ts_median: Vec<Option<f64>>,
    ts_median_all: Vec<Option<f64>>,
    ts_p90_all: Vec<Option<f64>>,
    ts_p10: Vec<Option<f64>>,
    ts_p90: Vec<Option<f64>>,
    ts_p95: Vec<Option<f64>>,
    ts_max: Vec<Option<f64>>,
    ts_ci_lo: Vec<Option<f64>>,
    ts_ci_hi: Vec<Option<f64>>,
    res_mean: Vec<Option<f64>>,
    res_median: Vec<Option<f64>>,
    res_p95: Vec<Option<f64>>,
    censored: Vec<u64>,
    not_settled: Vec<u64>,
    diverged: Vec<u64>,
    solver_failed: Vec<u64>,
    budget_exceeded: Vec<u64>,
    contact: Vec<bool>,
    min_gap: Vec<Option<f64>>,
    max_overlap: Vec<Option<f64>>,
}

impl SummaryColumns {
    fn into_dataframe(self) -> PolarsResult<DataFrame> {
        let height = self.design_id.len();
        DataFrame::new(
            height,
            vec![
                Column::new("design_id".into(), self.design_id),
                Column::new("kind".into(), self.kind),
                Column::new("n".into(), self.n),
                Column::new("rho".into(), self.rho),
                Column::new("drag".into(), self.drag),
                Column::new("capacity".into(), self.capacity),
                Column::new("runs".into(), self.runs),
                Column::new("settled".into(), self.settled),
                Column::new("settled_fraction".into(), self.settled_fraction),
                Column::new("settled_fraction_lo".into(), self.settled_lo),
                Column::new("settled_fraction_hi".into(), self.settled_hi),
                Column::new("settling_revs_mean".into(), self.ts_mean),
                Column::new("settling_revs_std".into(), self.ts_std),
                Column::new("settling_revs_median".into(), self.ts_median),
                Column::new("settling_revs_median_all_runs".into(), self.ts_median_all),
                Column::new("settling_revs_p90_all_runs".into(), self.ts_p90_all),
                Column::new("settling_revs_p10".into(), self.ts_p10),
                Column::new("settling_revs_p90".into(), self.ts_p90),
                Column::new("settling_revs_p95".into(), self.ts_p95),
                Column::new("settling_revs_max".into(), self.ts_max),
                Column::new("settling_revs_mean_ci_lo".into(), self.ts_ci_lo),
                Column::new("settling_revs_mean_ci_hi".into(), self.ts_ci_hi),
                Column::new("residual_rel_mean".into(), self.res_mean),
                Column::new("residual_rel_median".into(), self.res_median),
                Column::new("residual_rel_p95".into(), self.res_p95),
                Column::new("censored".into(), self.censored),
                Column::new("not_settled".into(), self.not_settled),
                Column::new("diverged".into(), self.diverged),
                Column::new("solver_failed".into(), self.solver_failed),
                Column::new("budget_exceeded".into(), self.budget_exceeded),
                Column::new("contact".into(), self.contact),
                Column::new("min_gap_rad".into(), self.min_gap),
                Column::new("max_overlap_fraction".into(), self.max_overlap),
            ],
        )
    }
}
