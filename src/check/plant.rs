//! Planted changes, to measure what `study check` detects and how often it
//! cries wolf: the same runs with every settling time stretched by a few per
//! cent, or with a share of the settled runs turned into unsettled ones.
//!
//! Planting at the level of the samples, instead of changing the physics and
//! re-simulating, lets one set of simulated studies serve every planted
//! change, so that many replicates (and so a false-alarm rate with a useful
//! interval) cost statistics only.

use super::compare::{CompareError, compare};
use super::samples::DesignSample;

/// A change planted into every design's runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Planted {
    /// No change: measures the false-alarm rate.
    Nothing,
    /// Every settling time multiplied by 1 + this (0.05: 5 % slower); a run
    /// pushed beyond the horizon no longer settles.
    SettlingTime(f64),
    /// This share of all runs (0.05: five percentage points) turned from
    /// settled into unsettled, the slowest first (the runs a slower physics
    /// would push out of the run first).
    SettledFraction(f64),
}

impl Planted {
    /// A short label for tables, e.g. "t_s +5 %".
    pub fn label(self) -> String {
        match self {
            Planted::Nothing => "none".into(),
            Planted::SettlingTime(r) => format!("t_s {:+} %", 100.0 * r),
            Planted::SettledFraction(d) => format!("settled −{} pp", 100.0 * d),
        }
    }
}

/// `samples` with `change` planted; `horizon_revs` is the latest settling
/// time a run can show (t_end − hold).
pub fn plant(samples: &[DesignSample], change: Planted, horizon_revs: f64) -> Vec<DesignSample> {
    samples
        .iter()
        .map(|s| {
            let mut s = s.clone();
            match change {
                Planted::Nothing => {}
                Planted::SettlingTime(r) => {
                    s.settling_revs = s
                        .settling_revs
                        .iter()
                        .map(|t| t * (1.0 + r))
                        .filter(|&t| t <= horizon_revs)
                        .collect();
                    s.settled = s.settling_revs.len() as u64;
                }
                Planted::SettledFraction(d) => {
                    let drop = ((d * s.runs as f64).round() as usize).min(s.settling_revs.len());
                    let mut order: Vec<usize> = (0..s.settling_revs.len()).collect();
                    order.sort_by(|&a, &b| s.settling_revs[b].total_cmp(&s.settling_revs[a]));
                    let mut keep = vec![true; s.settling_revs.len()];
                    for &i in &order[..drop] {
                        keep[i] = false;
                    }
                    s.settling_revs = s
                        .settling_revs
                        .iter()
                        .zip(&keep)
                        .filter(|(_, k)| **k)
                        .map(|(t, _)| *t)
                        .collect();
                    s.settled = s.settling_revs.len() as u64;
                }
            }
            s
        })
        .collect()
}

/// How often a check raised an alarm over a set of replicates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlarmCount {
    /// Checks that flagged at least one row.
    pub alarms: usize,
    /// Checks run.
    pub checks: usize,
}

impl AlarmCount {
    /// alarms / checks.
    pub fn rate(&self) -> f64 {
        self.alarms as f64 / self.checks as f64
    }
}

/// The check at `alpha` of every run against every other (independent
/// inputs: studies run with different seeds) with `change` planted into the
/// second: each unordered pair once for [`Planted::Nothing`] (the tests are
/// symmetric), each ordered pair otherwise.
///
/// The pairs share studies, so they are not independent replicates; the
/// estimate of the rate is unbiased, but a binomial interval for it should
/// count about `runs.len() / 2` replicates, not the number of pairs.
pub fn alarms_independent(
    runs: &[Vec<DesignSample>],
    change: Planted,
    horizon_revs: f64,
    alpha: f64,
) -> Result<AlarmCount, CompareError> {
    let pairs = (0..runs.len())
        .flat_map(|i| (0..runs.len()).map(move |j| (i, j)))
        .filter(|&(i, j)| i != j && (change != Planted::Nothing || j > i));
    count_alarms(runs, pairs, change, horizon_revs, alpha)
}

/// The check at `alpha` of every run against itself with `change` planted
/// (the default mode of `study check`: the baseline's own inputs).
pub fn alarms_paired(
    runs: &[Vec<DesignSample>],
    change: Planted,
    horizon_revs: f64,
    alpha: f64,
) -> Result<AlarmCount, CompareError> {
    count_alarms(
        runs,
        (0..runs.len()).map(|i| (i, i)),
        change,
        horizon_revs,
        alpha,
    )
}

/// Check run `b` with `change` planted against run `a` for every (a, b).
fn count_alarms(
    runs: &[Vec<DesignSample>],
    pairs: impl Iterator<Item = (usize, usize)>,
    change: Planted,
    horizon_revs: f64,
    alpha: f64,
) -> Result<AlarmCount, CompareError> {
    let mut count = AlarmCount {
        alarms: 0,
        checks: 0,
    };
    for (a, b) in pairs {
        let report = compare(&runs[a], &plant(&runs[b], change, horizon_revs), alpha)?;
        count.alarms += usize::from(!report.passed());
        count.checks += 1;
    }
    Ok(count)
}
