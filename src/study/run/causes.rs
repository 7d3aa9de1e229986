//! The cause experiment: when the leading design settles too rarely (it
//! does not balance, or it falls short of settling in
//! [`crate::decide::verdict::WORKS_SETTLED_SHARE`] of its runs), its samples that did not settle
//! are re-run with each effect removed in turn, and the effect whose
//! removal restores settling is named ([`crate::decide::causes`]).
//!
//! At most `summary.counterfactual_runs` samples are re-run: the first by
//! sample id of those that did not settle, so the choice, like every draw,
//! is the seed's and not the schedule's. Each re-run is the run's own
//! simulation ([`super::sample_simulation`]) with one effect out; the rows
//! come back in (sample, counterfactual) order for any thread count, and a
//! re-run that fails is a row with its reason.

use super::assemble::guarded_metrics;
use crate::decide::causes::CauseFinding;
use crate::decide::decision::{Crown, Recommendation, StudyDecision};
use crate::decide::verdict::Shortfall;
use crate::metrics::Outcome;
use crate::simulation::Simulation;
use crate::simulation::counterfactual::Counterfactual;
use crate::study::plan::config::StudyPlan;
use crate::study::results::causes_file::CauseRun;
use polars::prelude::*;
use rayon::prelude::*;

/// The experiment's finding and its re-runs (the rows of `causes.parquet`).
#[derive(Debug, Clone, PartialEq)]
pub struct CauseExperiment {
    /// The named cause, with the counts.
    pub finding: CauseFinding,
    /// Every re-run.
    pub rows: Vec<CauseRun>,
}

/// The leading design, when the summary says it settles too rarely: it
/// does not balance, or it is recommended with that caution.
fn design_to_explain(summary: &DataFrame) -> PolarsResult<Option<u32>> {
    let decision = StudyDecision::from_summary(summary)?;
    Ok(match (&decision.crown, &decision.recommendation) {
        (Crown::NoneBalances { best, .. }, _) => Some(*best),
        (
            _,
            Recommendation::Build {
                design, shortfalls, ..
            },
        ) if shortfalls
            .iter()
            .any(|s| matches!(s, Shortfall::SettlesTooRarely(_))) =>
        {
            Some(*design)
        }
        _ => None,
    })
}

/// Run the experiment on the study's runs (`runs`: at least `design_id`,
/// `sample_id` and `outcome`) and its `summary`; `None` when it is off
/// (`counterfactual_runs = 0`), the solver only estimates, or the leading
/// design settles often enough. Call it on the study's thread pool.
pub fn experiment(
    plan: &StudyPlan,
    runs: &DataFrame,
    summary: &DataFrame,
) -> PolarsResult<Option<CauseExperiment>> {
    let limit = plan.file.summary.counterfactual_runs as usize;
    if limit == 0 || plan.file.solver.fidelity.is_estimate() {
        return Ok(None);
    }
    let Some(id) = design_to_explain(summary)? else {
        return Ok(None);
    };
    let Some(design) = plan.designs.iter().find(|d| d.id == id) else {
        return Ok(None);
    };
    let (all, unsettled) = unsettled_samples(runs, id)?;
    if unsettled.is_empty() {
        return Ok(None);
    }
    // The re-runs: every sample with every counterfactual that applies to it.
    let jobs: Vec<(u32, Counterfactual, Simulation)> = unsettled
        .iter()
        .take(limit)
        .flat_map(|&sample_id| {
            let (sample, simulation) = super::sample_simulation(plan, design, u64::from(sample_id));
            // A draw the scene refused failed its run: it did not settle
            // for no effect's sake.
            let drawn = sample.uncertain_refused.is_none().then_some(simulation);
            Counterfactual::ALL.into_iter().filter_map(move |c| {
                let mut run = drawn.clone().filter(|s| c.applies(s))?;
                c.remove(&mut run);
                Some((sample_id, c, run))
            })
        })
        .collect();
    // Collected in the jobs' order whatever the schedule.
    let rows: Vec<CauseRun> = jobs
        .par_iter()
        .map(|(sample_id, counterfactual, run)| {
            let m = guarded_metrics(run, None);
            CauseRun {
                design_id: id,
                sample_id: *sample_id,
                counterfactual: *counterfactual,
                outcome: m.outcome,
                settled: m.settled,
                settling_revs: m.settling_revs,
                residual_rel: m.outcome.has_residual().then_some(m.residual_rel),
                reason: m.reason,
            }
        })
        .collect();
    let finding = CauseFinding::from_rows(id, all, unsettled.len(), &rows);
    Ok(Some(CauseExperiment { finding, rows }))
}

/// Design `id`'s runs, and the sample ids of those that did not settle
/// (censored or not settled; failures aside), ascending.
fn unsettled_samples(runs: &DataFrame, id: u32) -> PolarsResult<(usize, Vec<u32>)> {
    let design = runs.column("design_id")?.u32()?;
    let sample = runs.column("sample_id")?.u32()?;
    let outcome = runs.column("outcome")?.str()?;
    let mut all = 0;
    let mut unsettled = Vec::new();
    for i in 0..runs.height() {
        if design.get(i) != Some(id) {
            continue;
        }
        all += 1;
        let ended = outcome.get(i).and_then(Outcome::parse);
        if matches!(ended, Some(Outcome::Censored | Outcome::NotSettled))
            && let Some(s) = sample.get(i)
        {
            unsettled.push(s);
        }
    }
    unsettled.sort_unstable();
    Ok((all, unsettled))
}

/// Run the experiment and append its columns to `summary` (what `study
/// run` and `study merge` both do after the summary).
pub fn test_and_append(
    plan: &StudyPlan,
    runs: &DataFrame,
    summary: &mut DataFrame,
) -> PolarsResult<Option<CauseExperiment>> {
    let found = experiment(plan, runs, summary)?;
    append_columns(summary, found.as_ref().map(|c| &c.finding))?;
    Ok(found)
}

/// Write `causes.parquet` at `path` from the experiment, or remove an
/// earlier one (a resumed or re-merged study's) that no longer matches
/// the summary.
pub fn write_or_remove(
    path: &std::path::Path,
    found: Option<&CauseExperiment>,
    provenance: &crate::study::results::io::Provenance,
) -> Result<(), super::RunError> {
    match found {
        Some(c) => {
            let mut table = crate::study::results::causes_file::to_dataframe(&c.rows)?;
            crate::study::results::io::write_parquet(path, &mut table, provenance)?;
        }
        None if path.exists() => std::fs::remove_file(path)?,
        None => {}
    }
    Ok(())
}

/// The summary's `cause_tested` (the finding in words) and
/// `cause_tested_key` (its causes' keys) columns: on the experiment's
/// design's row, null elsewhere and when no experiment ran.
pub fn append_columns(summary: &mut DataFrame, found: Option<&CauseFinding>) -> PolarsResult<()> {
    let ids = summary.column("design_id")?.u32()?.clone();
    let on = |f: &dyn Fn(&CauseFinding) -> String| -> Vec<Option<String>> {
        ids.iter()
            .map(|id| found.filter(|c| Some(c.design_id) == id).map(f))
            .collect()
    };
    let text = on(&|c| c.to_string());
    let key = on(&|c| c.key());
    summary.with_column(Column::new("cause_tested".into(), text))?;
    summary.with_column(Column::new("cause_tested_key".into(), key))?;
    Ok(())
}
