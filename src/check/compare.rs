//! The verdict table: every design's three metrics, baseline against now,
//! tested, Holm-corrected together, and judged.
//!
//! A significant change in either direction is a regression: faster settling
//! after a change nobody meant to make is as much a sign that the physics or
//! numerics moved as slower settling is.

use super::samples::DesignSample;
use crate::stats::holm::holm_adjust;
use crate::stats::ks::ks_two_sample;
use crate::stats::mood::mood_median_test;
use crate::stats::proportion::fisher_two_proportions;
use crate::stats::quantile::median;
use serde::Serialize;

/// Family-wise false-alarm rate used when none is given.
pub const DEFAULT_ALPHA: f64 = 0.01;

/// What is compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// Settling time of the settled runs (revolutions): two-sample KS.
    SettlingTime,
    /// Fraction of runs that settled: Fisher's exact test.
    SettledFraction,
    /// Median residual vibration (relative to A_ref): Mood's median test.
    ResidualMedian,
    /// When watched plane p settled, in the runs where it did: two-sample KS.
    PlaneSettlingTime(u32),
    /// Fraction of runs in which watched plane p settled: Fisher's exact test.
    PlaneSettledFraction(u32),
}

impl Metric {
    /// Short name used in tables.
    pub fn name(self) -> String {
        match self {
            Metric::SettlingTime => "settling_revs".into(),
            Metric::SettledFraction => "settled_fraction".into(),
            Metric::ResidualMedian => "residual_rel".into(),
            Metric::PlaneSettlingTime(p) => format!("settling_revs_plane{p}"),
            Metric::PlaneSettledFraction(p) => format!("settled_fraction_plane{p}"),
        }
    }

    /// The test applied.
    pub fn test(self) -> &'static str {
        match self {
            Metric::SettlingTime | Metric::PlaneSettlingTime(_) => "KS",
            Metric::SettledFraction | Metric::PlaneSettledFraction(_) => "Fisher",
            Metric::ResidualMedian => "Mood",
        }
    }
}

/// The judgement on one hypothesis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// No significant change.
    Pass,
    /// A significant change (Holm-adjusted p ≤ α).
    Regression,
    /// Not testable: a sample is empty (e.g. no settled runs on one side).
    NotTested,
}

impl Verdict {
    /// Label used in tables.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Regression => "REGRESSION",
            Verdict::NotTested => "n/a",
        }
    }
}

/// One row of the verdict table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VerdictRow {
    /// Design index.
    pub design_id: u32,
    /// Design label.
    pub design: String,
    /// The metric.
    pub metric: Metric,
    /// Baseline value: median settling time, settled fraction or median residual.
    pub baseline: Option<f64>,
    /// The same value now.
    pub now: Option<f64>,
    /// Effect size: relative change of the median (now/baseline − 1) for
    /// settling time and residual, difference of fractions for the settled fraction.
    pub effect: Option<f64>,
    /// Test statistic where it is meaningful (KS: D, the largest CDF gap).
    pub statistic: Option<f64>,
    /// Sample sizes (baseline, now) the test used.
    pub sizes: (u64, u64),
    /// Raw p-value.
    pub p_value: Option<f64>,
    /// Holm-adjusted p-value over every tested row of the table.
    pub p_holm: Option<f64>,
    /// The judgement.
    pub verdict: Verdict,
}

/// The whole comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckReport {
    /// One row per design and metric, in design order.
    pub rows: Vec<VerdictRow>,
    /// Family-wise level.
    pub alpha: f64,
    /// Number of hypotheses tested (the Holm family).
    pub tested: usize,
    /// True when every design's samples are identical to the baseline's.
    pub identical: bool,
}

impl CheckReport {
    /// Rows judged a regression.
    pub fn regressions(&self) -> usize {
        self.rows
            .iter()
            .filter(|r| r.verdict == Verdict::Regression)
            .count()
    }

    /// True when nothing regressed.
    pub fn passed(&self) -> bool {
        self.regressions() == 0
    }
}

/// Why two sets of samples cannot be compared.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CompareError {
    /// The design lists differ.
    #[error("the baseline has designs {baseline:?} but the new run has {now:?}")]
    DifferentDesigns {
        /// Design ids in the baseline.
        baseline: Vec<u32>,
        /// Design ids now.
        now: Vec<u32>,
    },
    /// α outside (0, 1).
    #[error("alpha = {0}: must lie strictly between 0 and 1")]
    BadAlpha(f64),
}

fn relative(base: Option<f64>, now: Option<f64>) -> Option<f64> {
    match (base, now) {
        (Some(b), Some(n)) if b != 0.0 => Some(n / b - 1.0),
        _ => None,
    }
}

/// Test every design and metric, correct with Holm at family-wise level `alpha`.
pub fn compare(
    baseline: &[DesignSample],
    now: &[DesignSample],
    alpha: f64,
) -> Result<CheckReport, CompareError> {
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(CompareError::BadAlpha(alpha));
    }
    let ids = |s: &[DesignSample]| s.iter().map(|d| d.design_id).collect::<Vec<_>>();
    if ids(baseline) != ids(now) {
        return Err(CompareError::DifferentDesigns {
            baseline: ids(baseline),
            now: ids(now),
        });
    }
    let mut rows = Vec::with_capacity(3 * baseline.len());
    for (b, n) in baseline.iter().zip(now) {
        let row =
            |metric, baseline, now, effect, statistic, sizes, p_value: Option<f64>| VerdictRow {
                design_id: b.design_id,
                design: b.label.clone(),
                metric,
                baseline,
                now,
                effect,
                statistic,
                sizes,
                p_value,
                p_holm: None,
                verdict: Verdict::NotTested,
            };
        // KS on settling times, Fisher on settled counts: the design's own
        // and each watched plane's.
        let settling = |metric, before: &[f64], now: &[f64]| {
            let (mb, mn) = (median(before), median(now));
            let ks = ks_two_sample(before, now);
            row(
                metric,
                mb,
                mn,
                relative(mb, mn),
                ks.map(|k| k.statistic),
                (before.len() as u64, now.len() as u64),
                ks.map(|k| k.p_value),
            )
        };
        let share = |metric, before: u64, now: u64| {
            let fraction = fisher_two_proportions(before, b.runs, now, n.runs);
            row(
                metric,
                fraction.map(|f| f.a),
                fraction.map(|f| f.b),
                fraction.map(|f| f.difference),
                None,
                (b.runs, n.runs),
                fraction.map(|f| f.p_value),
            )
        };
        rows.push(settling(
            Metric::SettlingTime,
            &b.settling_revs,
            &n.settling_revs,
        ));
        rows.push(share(Metric::SettledFraction, b.settled, n.settled));
        let mood = mood_median_test(&b.residual_rel, &n.residual_rel);
        let (rb, rn) = (median(&b.residual_rel), median(&n.residual_rel));
        rows.push(row(
            Metric::ResidualMedian,
            rb,
            rn,
            relative(rb, rn),
            None,
            (b.residual_rel.len() as u64, n.residual_rel.len() as u64),
            mood.map(|m| m.p_value),
        ));
        // Watched planes: tested where both sides have them.
        for (p, (bp, np)) in b.planes.iter().zip(&n.planes).enumerate() {
            let p = p as u32;
            rows.push(settling(
                Metric::PlaneSettlingTime(p),
                &bp.settling_revs,
                &np.settling_revs,
            ));
            rows.push(share(
                Metric::PlaneSettledFraction(p),
                bp.settled,
                np.settled,
            ));
        }
    }
    let tested: Vec<usize> = (0..rows.len())
        .filter(|&i| rows[i].p_value.is_some())
        .collect();
    let raw: Vec<f64> = tested
        .iter()
        .map(|&i| rows[i].p_value.unwrap_or(1.0))
        .collect();
    for (&i, p) in tested.iter().zip(holm_adjust(&raw)) {
        rows[i].p_holm = Some(p);
        rows[i].verdict = if p <= alpha {
            Verdict::Regression
        } else {
            Verdict::Pass
        };
    }
    Ok(CheckReport {
        rows,
        alpha,
        tested: tested.len(),
        identical: baseline.iter().zip(now).all(|(b, n)| {
            b.runs == n.runs
                && b.settled == n.settled
                && b.settling_revs == n.settling_revs
                && b.residual_rel == n.residual_rel
                && b.planes == n.planes
        }),
    })
}
