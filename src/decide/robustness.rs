//! Whether a study's #1 survives its uncertain physics: the ranking
//! repeated in each third of every uncertain key's range, and how much of
//! #1's capped settling time each key explains.
//!
//! Every run of a study with `[uncertain]` keys drew its own physics, and
//! (with common random numbers) sample k of every design drew the same. So
//! the runs whose key lies in its lowest third are a study of their own,
//! on a machine whose key is known to be low: if #1 is still #1 there, and
//! in the middle and top thirds, the decision does not hang on the key. A
//! third where another design wins says where the decision turns.
//!
//! The share of #1's variance each key explains is the correlation ratio
//! over equal-count bins of the key, corrected for the share that noise
//! alone puts between bins (ε², which is 0 on average for a key that does
//! nothing, where the plain ratio is (bins − 1)/(runs − 1)): a first-order
//! index from the study's own runs. The total index, interactions
//! included, needs the pick-freeze runs of `study sensitivity`.

use crate::study::plan::config::StudyPlan;
use crate::study::results::design_runs::{SettlingClock, design_runs, measure_scale};
use crate::uncertain::COLUMN_PREFIX;
use polars::prelude::*;

/// Parts a key's range is cut into, by the crown's runs' values.
pub const PARTS: usize = 3;

/// Equal-count bins of the correlation ratio.
pub const BINS: usize = 8;

/// The ranking within one third of one key's range.
#[derive(Debug, Clone, PartialEq)]
pub struct PartWinner {
    /// The uncertain key.
    pub key: String,
    /// Which third (0: lowest).
    pub part: usize,
    /// The key's range in this third (its lowest and highest drawn value).
    pub range: (f64, f64),
    /// The design best on the criterion among the runs in this third.
    pub winner: u32,
    /// The winner's criterion value there.
    pub winner_value: Option<f64>,
    /// #1's criterion value there.
    pub crown_value: Option<f64>,
    /// #1's runs in this third.
    pub runs: usize,
}

/// How much of #1's capped settling time one key explains.
#[derive(Debug, Clone, PartialEq)]
pub struct Explained {
    /// The uncertain key.
    pub key: String,
    /// The correlation ratio over [`BINS`] equal-count bins, in [0, 1].
    pub share: f64,
}

/// The decision against the study's uncertain keys.
#[derive(Debug, Clone, PartialEq)]
pub struct Robustness {
    /// #1 of the whole study.
    pub crown: u32,
    /// The winner of every third of every key, key by key.
    pub parts: Vec<PartWinner>,
    /// Each key's share of #1's capped settling time, largest first.
    pub explained: Vec<Explained>,
}

impl Robustness {
    /// The thirds in which #1 is also best.
    pub fn kept(&self) -> usize {
        self.parts.iter().filter(|p| p.winner == self.crown).count()
    }
}

/// The robustness of `crown` (#1) over the study's uncertain keys, from its
/// runs (runs.parquet's columns); `None` when the study has no uncertain keys.
pub fn robustness(
    plan: &StudyPlan,
    runs: &DataFrame,
    crown: u32,
) -> PolarsResult<Option<Robustness>> {
    if plan.file.uncertain.is_empty() {
        return Ok(None);
    }
    let mut parts = Vec::new();
    let mut explained = Vec::new();
    for key in plan.file.uncertain.keys() {
        let column = format!("{COLUMN_PREFIX}{key}");
        let values: Vec<Option<f64>> = runs.column(&column)?.f64()?.iter().collect();
        let design: Vec<Option<u32>> = runs.column("design_id")?.u32()?.iter().collect();
        let mut mine: Vec<f64> = design
            .iter()
            .zip(&values)
            .filter(|(d, _)| **d == Some(crown))
            .filter_map(|(_, v)| *v)
            .collect();
        mine.sort_by(f64::total_cmp);
        // A key that did not vary over #1's runs cuts nothing.
        if mine.len() < PARTS || mine.first() == mine.last() {
            continue;
        }
        let cuts: Vec<f64> = (1..PARTS).map(|p| mine[p * mine.len() / PARTS]).collect();
        for part in 0..PARTS {
            let lo = if part == 0 {
                f64::NEG_INFINITY
            } else {
                cuts[part - 1]
            };
            let hi = if part + 1 == PARTS {
                f64::INFINITY
            } else {
                cuts[part]
            };
            let mask: BooleanChunked = values
                .iter()
                .map(|v| v.is_some_and(|x| x >= lo && x < hi))
                .collect();
            let within = runs.filter(&mask)?;
            let winner = part_winner(plan, &within, crown, key, part)?;
            if winner.runs > 0 {
                parts.push(winner);
            }
        }
        explained.push(Explained {
            key: key.clone(),
            share: correlation_ratio(plan, runs, crown, &values)?,
        });
    }
    explained.sort_by(|a, b| b.share.total_cmp(&a.share));
    Ok(Some(Robustness {
        crown,
        parts,
        explained,
    }))
}

/// The best design on the plan's criterion among `within`'s runs.
fn part_winner(
    plan: &StudyPlan,
    within: &DataFrame,
    crown: u32,
    key: &str,
    part: usize,
) -> PolarsResult<PartWinner> {
    let scale = measure_scale(plan);
    let criterion = plan.file.summary.rank_by;
    let designs = design_runs(within, scale.tau, SettlingClock::of(plan))?;
    let value_of = |id: u32| {
        designs
            .iter()
            .find(|d| d.design_id == id)
            .and_then(|d| criterion.value(d, &scale))
    };
    let best = designs
        .iter()
        .map(|d| (d.design_id, criterion.value(d, &scale)))
        .min_by(|a, b| criterion.order(a.1, b.1).then(a.0.cmp(&b.0)))
        .map_or(crown, |(id, _)| id);
    let keyed: Vec<f64> = within
        .column(&format!("{COLUMN_PREFIX}{key}"))?
        .f64()?
        .iter()
        .flatten()
        .collect();
    let range = keyed
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    Ok(PartWinner {
        key: key.to_string(),
        part,
        range,
        winner: best,
        winner_value: value_of(best),
        crown_value: value_of(crown),
        runs: designs
            .iter()
            .find(|d| d.design_id == crown)
            .map_or(0, |d| d.settling.len()),
    })
}

/// The share of the variance of #1's capped settling time between
/// equal-count bins of one key (the correlation ratio η²).
fn correlation_ratio(
    plan: &StudyPlan,
    runs: &DataFrame,
    crown: u32,
    values: &[Option<f64>],
) -> PolarsResult<f64> {
    let scale = measure_scale(plan);
    let mask: BooleanChunked = runs
        .column("design_id")?
        .u32()?
        .iter()
        .map(|d| d == Some(crown))
        .collect();
    let mine = runs.filter(&mask)?;
    let keyed: Vec<Option<f64>> = values
        .iter()
        .zip(mask.iter())
        .filter(|(_, m)| *m == Some(true))
        .map(|(v, _)| *v)
        .collect();
    let Some(runs_of_crown) = design_runs(&mine, scale.tau, SettlingClock::of(plan))?.pop() else {
        return Ok(0.0);
    };
    // design_runs orders by sample; so does `mine` once sorted the same way.
    let samples: Vec<Option<u32>> = mine.column("sample_id")?.u32()?.iter().collect();
    let mut order: Vec<usize> = (0..samples.len()).collect();
    order.sort_by_key(|&i| samples[i]);
    let mut pairs: Vec<(f64, f64)> = order
        .iter()
        .zip(&runs_of_crown.settling)
        .filter_map(|(&i, o)| Some((keyed[i]?, o.time.min(scale.tau))))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(eta_squared(
        &pairs.iter().map(|p| p.1).collect::<Vec<_>>(),
        BINS,
    ))
}

/// The correlation ratio of `y` (sorted by the key) over `bins` equal-count
/// bins, less what noise puts between bins (ε² = (SS_between − (bins − 1)
/// MS_within) / SS_total), clipped to [0, 1]; 0 when `y` does not vary or
/// has fewer than two values a bin.
pub fn eta_squared(y: &[f64], bins: usize) -> f64 {
    let n = y.len();
    if n < 2 * bins {
        return 0.0;
    }
    let mean = y.iter().sum::<f64>() / n as f64;
    let total: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    if total == 0.0 {
        return 0.0;
    }
    let between: f64 = (0..bins)
        .map(|b| {
            let part = &y[b * n / bins..(b + 1) * n / bins];
            let m = part.iter().sum::<f64>() / part.len() as f64;
            part.len() as f64 * (m - mean).powi(2)
        })
        .sum();
    let within_mean_square = (total - between) / (n - bins) as f64;
    ((between - (bins - 1) as f64 * within_mean_square) / total).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = key exactly: all the variance is between bins (up to the spread
    /// within each bin); y independent of the key's order: little of it.
    #[test]
    fn the_correlation_ratio_sees_a_trend_and_not_noise() {
        let trend: Vec<f64> = (0..800).map(f64::from).collect();
        assert!(eta_squared(&trend, 8) > 0.98);
        let mut state = 7u64;
        let noise: Vec<f64> = (0..800)
            .map(|_| {
                state = crate::study::plan::stream::splitmix64(state);
                (state >> 11) as f64 / (1u64 << 53) as f64
            })
            .collect();
        // The plain ratio would be (bins − 1)/(n − 1) ≈ 0.009 on average
        // here, and 0.11 with 64 runs; the corrected one is 0 on average.
        assert!(eta_squared(&noise, 8) < 0.02);
        assert!(eta_squared(&noise[..64], 8) < 0.1);
        assert_eq!(eta_squared(&[1.0; 100], 8), 0.0);
    }
}
