//! Adaptive sampling: a study that asks for a precision instead of a sample
//! count runs in batches of samples (every design the same samples, so runs
//! stay paired) and stops after the first batch at which the precision holds,
//! or at the cap `samples`. The decision after batch k reads only the runs of
//! batches 0..=k, so the same seed gives the same batches and the same stop,
//! however often the run is interrupted and resumed.

use crate::decide::verdict::{LEVEL, SettlingClock, best_versus_rest, design_runs, measure_scale};
use crate::stats::survival::Transform;
use crate::study::plan::config::{StopWhen, StudyPlan};
use crate::study::results::measured_runs::DesignRuns;
use polars::prelude::*;
use std::ops::Range;

/// The sample ranges of the batches, in order (one batch of every sample
/// when the study asks for no precision and races no designs).
pub fn batches(plan: &StudyPlan) -> Vec<Range<u32>> {
    let s = &plan.file.sampling;
    let step = if s.stop_when.is_some() {
        s.batch
    } else if crate::study::run::racing::races(plan) {
        crate::study::run::racing::look_batch(s.samples)
    } else {
        s.samples
    };
    (0..s.samples)
        .step_by(step as usize)
        .map(|start| start..(start + step).min(s.samples))
        .collect()
}

/// Run ids of every design for the samples in `range`, ascending.
pub fn batch_ids(plan: &StudyPlan, range: &Range<u32>) -> Vec<u64> {
    let samples = u64::from(plan.file.sampling.samples);
    (0..plan.designs.len() as u64)
        .flat_map(|d| range.clone().map(move |s| d * samples + u64::from(s)))
        .collect()
}

/// How far a batch got towards the requested precision.
#[derive(Debug, Clone, PartialEq)]
pub struct Precision {
    /// Every requested half-width holds.
    pub reached: bool,
    /// The worst half-width of each requested kind, as (key, value, target);
    /// an infinite value means an interval not bounded within the run.
    pub worst: Vec<(&'static str, f64, f64)>,
}

/// The precision of the runs in `df` (the columns of
/// [`crate::study::results::runs_file::SUMMARY_COLUMNS`]) against `stop`.
pub fn precision(plan: &StudyPlan, stop: &StopWhen, df: &DataFrame) -> PolarsResult<Precision> {
    // The same horizon, clock and criterion as the summary's verdicts, so
    // the same best design.
    let scale = measure_scale(plan);
    let designs = design_runs(df, scale.tau, SettlingClock::of(plan))?;
    let mut worst = Vec::new();
    if let Some(target) = stop.median_halfwidth_rel {
        worst.push(("median_halfwidth_rel", median_halfwidth(&designs), target));
    }
    if let Some(target) = stop.win_share_halfwidth {
        let value = best_versus_rest(
            &designs,
            plan.file.summary.rank_by,
            &scale,
            plan.file.statistics.alpha,
            plan.file.sampling.common_random_numbers,
            plan.file.seed,
        )
        .map_or(f64::INFINITY, |v| {
            v.others
                .iter()
                .map(|(c, _, _)| {
                    c.paired.as_ref().map_or(f64::INFINITY, |p| {
                        0.5 * (p.a_sooner_share_interval.1 - p.a_sooner_share_interval.0)
                    })
                })
                .fold(0.0, f64::max)
        });
        worst.push(("win_share_halfwidth", value, target));
    }
    Ok(Precision {
        reached: worst.iter().all(|(_, value, target)| value <= target),
        worst,
    })
}

/// The largest relative half-width of the designs' median intervals.
fn median_halfwidth(designs: &[DesignRuns]) -> f64 {
    designs
        .iter()
        .map(|d| {
            let Some(km) = d.kaplan_meier() else {
                return f64::INFINITY;
            };
            match (km.median(), km.median_interval(LEVEL, Transform::LogLog)) {
                (Some(m), (Some(lo), Some(hi))) if m > 0.0 => 0.5 * (hi - lo) / m,
                _ => f64::INFINITY,
            }
        })
        .fold(0.0, f64::max)
}
