//! Racing the designs (as F-Race and irace do): the samples run in batches
//! over the designs still in the race, every design the same samples
//! (common random numbers), and after each batch a design leaves when the
//! leader is significantly better on the declared criterion and the design
//! can no longer change what the study reports: its verdict against
//! whichever design ends first, the Pareto set, or a finding that it beats
//! #1 on another measure ([`leaves`]). A design that left keeps its runs;
//! its statistics are computed on them, and its comparisons pair on the
//! samples it ran.
//!
//! Error control across the looks: look k tests at the level the
//! Pocock-type spending function spends there ([`Spending`]), Holm across
//! the designs compared at that look. The levels sum to α, so the chance
//! that the truly best design is ever dropped stays at or below α
//! (Bonferroni over the looks; docs/statistics.md, "Racing").
//!
//! A look reads only the runs of the batches so far, and draws its
//! bootstrap streams from (seed, look, designs): the same seed gives the
//! same race for any thread count, and an interrupted race resumes exactly.
//! A look needs p-values and standard errors, not an interval's tails, so
//! it compares with [`Spread::Look`]: no resampling for the paired median
//! (the sign test and its rank interval), a tenth of the verdicts'
//! resamples for the other quantiles.

use crate::decide::measure::Spread;
use crate::decide::verdict::{
    Favours, LEVEL, balances, favoured, material_difference, pareto_set, ranking,
};
use crate::stats::holm::holm_adjust;
use crate::stats::paired_measures::Difference;
use crate::stats::spending::Spending;
use crate::study::plan::config::StudyPlan;
use crate::study::plan::criterion::Criterion;
use crate::study::plan::stream::{Purpose, stream};
use crate::study::results::design_runs::{SettlingClock, design_runs, measure_scale};
use crate::study::results::measured_runs::DesignRuns;
use polars::prelude::*;
use std::ops::Range;

/// How many looks a race aims at over the study's samples.
pub const LOOKS: u32 = 20;

/// The fewest samples per design between two looks: a paired test on fewer
/// runs leans on its large-sample approximation.
pub const MIN_LOOK_SAMPLES: u32 = 10;

/// How the race spends α over its looks: Pocock-type, about evenly, so
/// that clearly worse designs may leave at the first looks.
pub const SPENDING: Spending = Spending::Pocock;

/// How many standard errors ahead the leader must be on every other
/// reported measure before a design may leave ([`leaves`]).
pub const MARGIN_Z: f64 = 2.0;

/// The standard normal quantile of a two-sided 95 % interval.
const Z_95: f64 = 1.959_963_984_540_054;

/// Samples per design between two looks of a race of `samples` samples.
pub fn look_batch(samples: u32) -> u32 {
    samples.div_ceil(LOOKS).max(MIN_LOOK_SAMPLES)
}

/// Whether the plan races its designs: `sampling.racing` and at least two
/// designs to rank.
pub fn races(plan: &StudyPlan) -> bool {
    plan.file.sampling.racing && plan.designs.len() > 1
}

/// Why a design left the race.
#[derive(Debug, Clone, PartialEq)]
pub struct Departure {
    /// The design.
    pub design_id: u32,
    /// The look (batch, counted from 1) after which it left.
    pub after_batch: usize,
    /// Its runs: the samples run when it left.
    pub samples: u32,
    /// The leader then.
    pub leader: u32,
    /// The Holm-adjusted p-value of "the leader is better" on the criterion.
    pub p_holm: f64,
    /// The level that look spent.
    pub level: f64,
}

/// The state of a race: which designs are still in it.
#[derive(Debug, Clone)]
pub struct Race {
    levels: Vec<f64>,
    left: Vec<Option<Departure>>,
}

impl Race {
    /// A race over `plan`'s designs with a look after each of `batches`
    /// but the last (which ends the study).
    pub fn new(plan: &StudyPlan, batches: &[Range<u32>]) -> Self {
        let samples = f64::from(plan.file.sampling.samples);
        let fractions: Vec<f64> = batches.iter().map(|b| f64::from(b.end) / samples).collect();
        Race {
            levels: SPENDING.look_levels(plan.file.statistics.alpha, &fractions),
            left: vec![None; plan.designs.len()],
        }
    }

    /// True while design `index` (its place in the plan) is in the race.
    pub fn running(&self, index: usize) -> bool {
        self.left.get(index).is_none_or(Option::is_none)
    }

    /// How many designs are still in the race.
    pub fn running_count(&self) -> usize {
        self.left.iter().filter(|l| l.is_none()).count()
    }

    /// Every design that left, in design order.
    pub fn departures(&self) -> Vec<Departure> {
        self.left.iter().flatten().cloned().collect()
    }

    /// Look after batch `k` (counted from 0) at the runs in `judged` (those
    /// of batches 0..=k), and take out of the race every design that leaves
    /// ([`leaves`]). Returns those designs.
    pub fn look(
        &mut self,
        plan: &StudyPlan,
        k: usize,
        samples: u32,
        judged: &DataFrame,
    ) -> PolarsResult<Vec<Departure>> {
        let Some(&level) = self.levels.get(k) else {
            return Ok(Vec::new());
        };
        let scale = measure_scale(plan);
        let running: Vec<DesignRuns> = design_runs(judged, scale.tau, SettlingClock::of(plan))?
            .into_iter()
            .filter(|d| self.running(d.design_id as usize))
            .collect();
        let out: Vec<Departure> = leaves(plan, &running, level, k)
            .into_iter()
            .map(|(design_id, leader, p_holm)| Departure {
                design_id,
                after_batch: k + 1,
                samples,
                leader,
                p_holm,
                level,
            })
            .collect();
        for d in &out {
            if let Some(slot) = self.left.get_mut(d.design_id as usize) {
                *slot = Some(d.clone());
            }
        }
        Ok(out)
    }

    /// True once a single design is left: no later look can change the
    /// race. The one left still runs every sample: it is the part, and
    /// trimming its runs would only widen its intervals (issue 70).
    pub fn decided(&self) -> bool {
        self.running_count() < 2
    }

    /// Whether the raced study runs sample `sample` of design `index`.
    pub fn runs(&self, index: usize, sample: u32) -> bool {
        let left = self.left.get(index).and_then(Option::as_ref);
        left.is_none_or(|d| sample < d.samples)
    }

    /// The race an unsharded study makes, replayed on a table of every
    /// sample of every design (as merged shards hold): each look reads the
    /// same runs, so it makes the same departures.
    pub fn replay(
        plan: &StudyPlan,
        batches: &[Range<u32>],
        runs: &DataFrame,
    ) -> PolarsResult<Race> {
        let mut race = Race::new(plan, batches);
        let sample = runs.column("sample_id")?.u32()?.clone();
        for (k, batch) in batches
            .iter()
            .enumerate()
            .take(batches.len().saturating_sub(1))
        {
            let judged = runs.filter(&sample.lt(batch.end))?;
            race.look(plan, k, batch.end, &judged)?;
            if race.decided() {
                break;
            }
        }
        Ok(race)
    }

    /// The rows of `runs` that the raced study made ([`Race::runs`]).
    pub fn made(&self, runs: &DataFrame) -> PolarsResult<DataFrame> {
        let design = runs.column("design_id")?.u32()?;
        let sample = runs.column("sample_id")?.u32()?;
        let keep: BooleanChunked = design
            .iter()
            .zip(sample.iter())
            .map(|(d, s)| Some(d.zip(s).is_none_or(|(d, s)| self.runs(d as usize, s))))
            .collect();
        runs.filter(&keep)
    }
}

/// The designs of `running` (the race's designs, on the same samples) that
/// leave at a look spending `level`, as (design, leader, Holm p): the
/// leader (the first by the plan's criterion, and one that balances) is
/// better on the criterion at Holm-adjusted p ≤ `level` ([`favoured`]); the
/// leader and every design it does not beat yet beat it at the study's α
/// even under the end's largest Holm factor; the
/// design is outside the Pareto set of the running designs, and the leader
/// is at least as good on every reported measure, so that no "other
/// measures disagree" finding can be lost with the design.
pub fn leaves(
    plan: &StudyPlan,
    running: &[DesignRuns],
    level: f64,
    look: usize,
) -> Vec<(u32, u32, f64)> {
    if running.len() < 2 {
        return Vec::new();
    }
    let scale = measure_scale(plan);
    let criterion = plan.file.summary.rank_by;
    let leader = &running[ranking(running, criterion, &scale)[0]];
    // A race needs a winner: while no design balances, none is called worse.
    if !balances(leader) {
        return Vec::new();
    }
    let worse = significantly_worse(plan, running, leader, level, look);
    // Whichever design ends first, the verdict on a design that left is
    // made at the end on the runs it has now: it leaves only when the
    // leader and every design that may still end first beat it at the
    // study's α with the largest Holm factor the end can apply (Bonferroni
    // over every other design).
    let alpha = plan.file.statistics.alpha;
    let paired = plan.file.sampling.common_random_numbers;
    let factor = plan.designs.len().saturating_sub(1).max(1) as f64;
    let beats_at_the_end = |c: &DesignRuns, d: &DesignRuns| {
        let mut rng = stream(
            plan.file.seed,
            Some(c.design_id),
            ((look as u64) << 32) | (1 << 31) | u64::from(d.design_id),
            Purpose::Racing,
        );
        criterion
            .compare_with(c, d, paired, &scale, LEVEL, Spread::Look, &mut rng)
            .is_some_and(|x| {
                favoured(criterion, &x, (x.p_value * factor).min(1.0), alpha) == Some(Favours::A)
            })
    };
    // A design the leader beats by that test will not end first.
    let contenders: Vec<&DesignRuns> = running
        .iter()
        .filter(|c| c.design_id == leader.design_id || !beats_at_the_end(leader, c))
        .collect();
    let beaten_by_all = |d: &DesignRuns| contenders.iter().all(|c| beats_at_the_end(c, d));
    let pareto = pareto_set(running, &plan.file.summary.pareto, &scale);
    let mut measures: Vec<Criterion> = Criterion::REPORTED.to_vec();
    measures.extend(plan.file.summary.pareto.iter().copied());
    measures.retain(|&m| m != criterion);
    measures.dedup();
    // On each other measure the leader must be ahead by MARGIN_Z standard
    // errors, or the design's lead, even MARGIN_Z standard errors larger,
    // must stay under the minimum effect a finding needs
    // ([`material_difference`]): a design that might still turn out better
    // on one by a difference worth reporting keeps running, so that the
    // finding "better than #1 on m" cannot be lost with it.
    // A design ahead of the leader on some measure's point estimate by the
    // minimum effect stays whatever the spread: checked first, with no
    // resampling, so that the spreads below are paid only for designs that
    // may leave.
    let leads_on_a_point = |d: &DesignRuns| {
        measures.iter().any(|m| {
            // Point draws nothing: any stream serves.
            let mut unused = stream(plan.file.seed, None, 0, Purpose::Racing);
            m.compare_with(leader, d, paired, &scale, LEVEL, Spread::Point, &mut unused)
                .is_some_and(|x| {
                    x.difference != 0.0 && !m.a_better(x.difference) && material_difference(&x)
                })
        })
    };
    let at_least_as_good = |d: &DesignRuns| {
        !leads_on_a_point(d)
            && measures.iter().enumerate().all(|(j, m)| {
                let (a, b) = (m.value(leader, &scale), m.value(d, &scale));
                if m.order(a, b) == std::cmp::Ordering::Equal {
                    return true;
                }
                let mut rng = stream(
                    plan.file.seed,
                    Some(leader.design_id),
                    ((look as u64) << 32) | ((j as u64 + 1) << 24) | u64::from(d.design_id),
                    Purpose::Racing,
                );
                match m.compare_with(leader, d, paired, &scale, LEVEL, Spread::Look, &mut rng) {
                    Some(x) if x.interval.0.is_finite() && x.interval.1.is_finite() => {
                        let se = (x.interval.1 - x.interval.0) / (2.0 * Z_95);
                        let lead = if m.a_better(x.difference) {
                            x.difference.abs()
                        } else {
                            -x.difference.abs()
                        };
                        let ahead = lead >= MARGIN_Z * se;
                        // The design's largest plausible lead, still immaterial.
                        let immaterial = !material_difference(&Difference {
                            difference: (MARGIN_Z * se - lead).max(0.0),
                            ..x
                        });
                        ahead || immaterial
                    }
                    _ => m.order(a, b) == std::cmp::Ordering::Less,
                }
            })
    };
    worse
        .into_iter()
        .filter(|&(id, _)| {
            let d = running.iter().find(|d| d.design_id == id);
            !pareto.contains(&id) && d.is_some_and(|d| beaten_by_all(d) && at_least_as_good(d))
        })
        .map(|(id, p_holm)| (id, leader.design_id, p_holm))
        .collect()
}

/// The designs of `running` that `leader` beats on the plan's criterion at
/// a look spending `level`: its paired test, Holm-adjusted across the
/// running designs, favours the leader ([`favoured`]). As (design, Holm p).
pub fn significantly_worse(
    plan: &StudyPlan,
    running: &[DesignRuns],
    leader: &DesignRuns,
    level: f64,
    look: usize,
) -> Vec<(u32, f64)> {
    let scale = measure_scale(plan);
    let criterion = plan.file.summary.rank_by;
    let paired = plan.file.sampling.common_random_numbers;
    let others: Vec<&DesignRuns> = running
        .iter()
        .filter(|d| d.design_id != leader.design_id)
        .collect();
    let differences: Vec<_> = others
        .iter()
        .map(|d| {
            let mut rng = stream(
                plan.file.seed,
                Some(leader.design_id),
                ((look as u64) << 32) | u64::from(d.design_id),
                Purpose::Racing,
            );
            criterion.compare_with(leader, d, paired, &scale, LEVEL, Spread::Look, &mut rng)
        })
        .collect();
    let p: Vec<f64> = differences
        .iter()
        .map(|d| d.map_or(1.0, |d| d.p_value))
        .collect();
    others
        .iter()
        .zip(&differences)
        .zip(holm_adjust(&p))
        .filter(|((_, difference), p_holm)| {
            difference.is_some_and(|x| favoured(criterion, &x, *p_holm, level) == Some(Favours::A))
        })
        .map(|((d, _), p_holm)| (d.design_id, p_holm))
        .collect()
}

/// The rows of `runs` whose designs are still in `race`.
pub fn only_running(runs: &DataFrame, race: &Race) -> PolarsResult<DataFrame> {
    let keep: BooleanChunked = runs
        .column("design_id")?
        .u32()?
        .iter()
        .map(|d| Some(d.is_some_and(|d| race.running(d as usize))))
        .collect();
    runs.filter(&keep)
}
