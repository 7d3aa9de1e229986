//! The optimiser's pick confirmed on fresh samples before it is called the
//! overall optimum.
//!
//! Each (kind, n) search picks the best of many candidates on the same N
//! samples, so its best value is biased low (the winner's curse), and a few
//! rare runs that never settle may not be among the N at all. An 8 kg rotor
//! searched on 48 samples picked n = 3 at 12.5 rev; on 300 fresh samples
//! that design averaged 43 rev, because two of them never settled. So every
//! scope's optimum is evaluated again on samples the search never saw (more
//! of them than the search used, with common random numbers), the overall
//! pick is the best there, and each other optimum is compared with it,
//! paired on those samples: where the interval of the difference covers 0
//! the two are a tie, and said to be.

use super::evaluate::{Candidate, Evaluator, estimate, statistic};
use crate::stats::paired_measures::{Difference, bootstrap_difference};
use crate::study::plan::stream::{Purpose, stream};

/// One scope's optimum, evaluated again on the fresh samples.
#[derive(Debug, Clone)]
pub struct Confirmed {
    /// The scope ("ball_3").
    pub scope: String,
    /// The optimum the search found for that scope.
    pub candidate: Candidate,
    /// The objective on the fresh samples.
    pub value: f64,
    /// Its Monte Carlo standard error.
    pub std_err: f64,
    /// This optimum minus the overall pick, paired on the fresh samples
    /// (percentile bootstrap of pairs); `None` for the pick itself.
    pub vs_overall: Option<Difference>,
}

impl Confirmed {
    /// Not distinguishable from the overall pick: the interval covers 0,
    /// or the difference is too small to matter
    /// ([`material_difference`](crate::decide::verdict::material_difference), 1 %).
    pub fn ties(&self) -> bool {
        self.vs_overall.is_some_and(|d| {
            (d.interval.0 <= 0.0 && d.interval.1 >= 0.0)
                || !crate::decide::verdict::material_difference(&d)
        })
    }
}

/// Every scope's optimum on the fresh samples, and the overall pick.
#[derive(Debug, Clone)]
pub struct Confirmation {
    /// The first fresh sample (the search used 0..first).
    pub first_sample: u64,
    /// How many fresh samples.
    pub samples: u32,
    /// Confidence level of the paired intervals (1 − α).
    pub level: f64,
    /// One row per scope, in the scopes' order.
    pub rows: Vec<Confirmed>,
    /// Index in `rows` of the overall pick: the best on the fresh samples.
    pub overall: usize,
    /// Index in `rows` of the scope the search's own values would have picked.
    pub search_pick: usize,
}

impl Confirmation {
    /// The row of `scope` ("overall": the pick's).
    pub fn row(&self, scope: &str) -> Option<&Confirmed> {
        if scope == "overall" {
            self.rows.get(self.overall)
        } else {
            self.rows.iter().find(|r| r.scope == scope)
        }
    }

    /// The scopes tied with the overall pick.
    pub fn ties(&self) -> impl Iterator<Item = &Confirmed> {
        self.rows.iter().filter(|r| r.ties())
    }
}

/// Evaluate each `(scope, candidate)` on samples `first..first + samples`,
/// pick the best, and compare every other with it at `level`.
/// `search_pick` is the index of the search's own overall pick. `None` for
/// an analytic objective or no scope.
pub fn confirm(
    evaluator: &Evaluator<'_>,
    optima: &[(String, Candidate)],
    search_pick: usize,
    samples: u32,
    level: f64,
) -> Option<Confirmation> {
    let objective = evaluator.spec.objective;
    if !objective.simulated() || optima.is_empty() || samples == 0 {
        return None;
    }
    let first = u64::from(evaluator.samples);
    let fresh = first..first + u64::from(samples);
    let values: Vec<Vec<f64>> = optima
        .iter()
        .map(|(_, c)| {
            evaluator.build(c).map_or_else(
                |_| Vec::new(),
                |d| evaluator.run_values(&d, fresh.clone(), objective),
            )
        })
        .collect();
    let key = |v: f64| if objective.maximise() { -v } else { v };
    let estimates: Vec<(f64, f64)> = values
        .iter()
        .map(|v| {
            if v.is_empty() {
                (f64::NAN, f64::NAN)
            } else {
                estimate(evaluator.plan, objective, v)
            }
        })
        .collect();
    // The best on the fresh samples (NaN, an unbuildable optimum, never).
    let overall = (0..optima.len())
        .filter(|&i| !estimates[i].0.is_nan())
        .min_by(|&a, &b| key(estimates[a].0).total_cmp(&key(estimates[b].0)))?;
    let rows = optima
        .iter()
        .enumerate()
        .map(|(i, (scope, candidate))| Confirmed {
            scope: scope.clone(),
            candidate: *candidate,
            value: estimates[i].0,
            std_err: estimates[i].1,
            vs_overall: (i != overall && !values[i].is_empty())
                .then(|| {
                    bootstrap_difference(
                        &values[i],
                        &values[overall],
                        |v| statistic(objective, v),
                        true,
                        level,
                        &mut stream(
                            evaluator.plan.file.seed,
                            None,
                            i as u64,
                            Purpose::Comparison,
                        ),
                    )
                })
                .flatten(),
        })
        .collect();
    Some(Confirmation {
        first_sample: first,
        samples,
        level,
        rows,
        overall,
        search_pick,
    })
}

/// The number of fresh samples by default: four times the search's, so the
/// confirmation sees runs the search could not.
pub fn default_samples(search_samples: u32) -> u32 {
    search_samples.saturating_mul(4)
}
