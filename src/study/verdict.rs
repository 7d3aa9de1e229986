//! Which design settles sooner, and how sure is it: comparisons of designs
//! that count every run (unsettled ones as censored), paired when the
//! designs met the same sampled unbalances (common random numbers), and the
//! best design against every other with Holm's correction.

use super::config::StudyPlan;
use super::sample::{Purpose, stream};
use crate::stats::holm::holm_adjust;
use crate::stats::paired::{
    Settling, SettlingComparison, WilcoxonResult, compare_settling, median_ratio,
    wilcoxon_signed_rank,
};
use crate::stats::survival::{KaplanMeier, LogRank, Observation, log_rank};
use polars::prelude::*;
use rayon::prelude::*;

/// Level of every interval the comparisons report.
pub const LEVEL: f64 = 0.95;

/// The runs of one design, in sample order: its settling observations and
/// residual vibrations.
#[derive(Debug, Clone)]
pub struct DesignRuns {
    /// The design.
    pub design_id: u32,
    /// Sample index of each run (what pairs runs of two designs).
    pub sample_ids: Vec<u32>,
    /// Settled at t (revolutions), or censored: at `censoring_revs` for a
    /// run simulated to its end, at the horizon for one that diverged,
    /// failed or ran out of budget (it never settled within the run).
    pub settling: Vec<Observation>,
    /// Residual vibration / A_ref of runs simulated to their end.
    pub residual: Vec<Option<f64>>,
}

impl DesignRuns {
    /// The Kaplan–Meier estimate of its settling.
    pub fn kaplan_meier(&self) -> Option<KaplanMeier> {
        KaplanMeier::fit(&self.settling)
    }
}

/// The latest settling time a run of the plan can show (revolutions): the
/// end of the run less the hold window. Runs that never settled are
/// censored here.
pub fn settling_horizon(plan: &StudyPlan) -> f64 {
    plan.file.metrics.t_end_revs - plan.file.metrics.hold_revs
}

/// The time the restricted mean is taken up to, and the best design chosen
/// by: the latest time any run of `designs` could show (the plan's horizon,
/// or a later settling time).
pub fn restricted_horizon(plan: &StudyPlan, designs: &[DesignRuns]) -> f64 {
    designs
        .iter()
        .flat_map(|d| d.settling.iter().map(|o| o.time))
        .fold(settling_horizon(plan), f64::max)
}

/// Every design's runs from a runs table holding the columns of
/// [`super::runs_file::SUMMARY_COLUMNS`], in design order (designs without
/// runs are left out).
pub fn design_runs(df: &DataFrame, horizon: f64) -> PolarsResult<Vec<DesignRuns>> {
    let design = df.column("design_id")?.u32()?;
    let sample = df.column("sample_id")?.u32()?;
    let outcome = df.column("outcome")?.str()?;
    let settled = df.column("settled")?.bool()?;
    let revs = df.column("settling_revs")?.f64()?;
    let censoring = df.column("censoring_revs")?.f64()?;
    let residual = df.column("residual_rel")?.f64()?;
    let mut out: Vec<DesignRuns> = Vec::new();
    let mut rows: Vec<usize> = (0..df.height()).collect();
    rows.sort_by_key(|&i| (design.get(i), sample.get(i)));
    for i in rows {
        let id = design.get(i).unwrap_or_default();
        if out.last().is_none_or(|d| d.design_id != id) {
            out.push(DesignRuns {
                design_id: id,
                sample_ids: Vec::new(),
                settling: Vec::new(),
                residual: Vec::new(),
            });
        }
        let d = out.last_mut().expect("pushed above");
        let observation = match (settled.get(i), revs.get(i)) {
            (Some(true), Some(t)) => Observation {
                time: t,
                settled: true,
            },
            _ => Observation {
                time: censoring.get(i).unwrap_or(horizon),
                settled: false,
            },
        };
        let simulated = matches!(outcome.get(i), Some("settled" | "censored" | "not_settled"));
        d.sample_ids.push(sample.get(i).unwrap_or_default());
        d.settling.push(observation);
        d.residual
            .push(residual.get(i).filter(|r| simulated && r.is_finite()));
    }
    Ok(out)
}

/// Why two designs' runs cannot be paired.
pub fn pairing_refusal(a: &DesignRuns, b: &DesignRuns) -> Option<String> {
    (a.sample_ids != b.sample_ids).then(|| {
        format!(
            "design {} has {} runs and design {} has {}, not of the same samples",
            a.design_id,
            a.sample_ids.len(),
            b.design_id,
            b.sample_ids.len()
        )
    })
}

/// Design A against design B.
#[derive(Debug, Clone)]
pub struct Comparison {
    /// Design A.
    pub a: u32,
    /// Design B.
    pub b: u32,
    /// Runs of A and of B.
    pub runs: (usize, usize),
    /// Kaplan–Meier median settling time of A and of B (`None`: beyond the run).
    pub medians: (Option<f64>, Option<f64>),
    /// Paired settling comparison (when the runs share samples).
    pub paired: Option<SettlingComparison>,
    /// Log-rank test (when they do not).
    pub unpaired: Option<LogRank>,
    /// Paired Wilcoxon signed-rank test of the residual vibrations.
    pub residual_test: Option<WilcoxonResult>,
    /// Median of the paired residual ratios A/B with its interval.
    pub residual_ratio: Option<(f64, (f64, f64))>,
}

impl Comparison {
    /// The p-value of "A and B settle alike": the sign test when paired,
    /// the log-rank test otherwise; 1 when nothing could be compared.
    pub fn p_value(&self) -> f64 {
        self.paired
            .as_ref()
            .map(|p| p.sign_test_p)
            .or(self.unpaired.map(|u| u.p_value))
            .unwrap_or(1.0)
    }

    /// True when A settles sooner than B more often than the reverse.
    pub fn a_is_sooner(&self) -> bool {
        match (&self.paired, &self.unpaired) {
            (Some(p), _) => p.a_sooner > p.b_sooner,
            (None, Some(u)) => u.observed_a > u.expected_a,
            (None, None) => false,
        }
    }
}

/// Compare A with B, paired when `paired` (the caller checked
/// [`pairing_refusal`]); `seed` seeds the bootstrap intervals.
pub fn compare(a: &DesignRuns, b: &DesignRuns, paired: bool, seed: u64) -> Comparison {
    let median = |d: &DesignRuns| d.kaplan_meier().and_then(|km| km.median());
    let mut rng = stream(
        seed,
        Some(a.design_id),
        u64::from(b.design_id),
        Purpose::Comparison,
    );
    let (settling, unpaired, residual_test, residual_ratio) = if paired {
        let to = |d: &DesignRuns| {
            d.settling
                .iter()
                .map(|o| Settling::new(o.time, o.settled))
                .collect::<Vec<_>>()
        };
        let both: (Vec<f64>, Vec<f64>) = a
            .residual
            .iter()
            .zip(&b.residual)
            .filter_map(|(x, y)| x.zip(*y))
            .unzip();
        (
            compare_settling(&to(a), &to(b), LEVEL, &mut rng),
            None,
            wilcoxon_signed_rank(&both.0, &both.1),
            median_ratio(&both.0, &both.1, LEVEL, &mut rng),
        )
    } else {
        (None, log_rank(&a.settling, &b.settling), None, None)
    };
    Comparison {
        a: a.design_id,
        b: b.design_id,
        runs: (a.settling.len(), b.settling.len()),
        medians: (median(a), median(b)),
        paired: settling,
        unpaired,
        residual_test,
        residual_ratio,
    }
}

/// The verdict on the best design against one other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The best design settles sooner (Holm-adjusted p ≤ α).
    BestSooner,
    /// The data cannot tell the two apart at α.
    NotDistinguishable,
    /// The other design settles sooner in significantly more paired runs,
    /// although the best has the lower median: the two rankings disagree.
    OtherSooner,
}

impl Verdict {
    /// The verdict as stored in `summary.parquet`.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::BestSooner => "best_sooner",
            Verdict::NotDistinguishable => "not_distinguishable",
            Verdict::OtherSooner => "other_sooner",
        }
    }
}

/// The best design against every other one.
#[derive(Debug, Clone)]
pub struct BestVersusRest {
    /// The design with the lowest Kaplan–Meier median settling time (ties:
    /// the lower restricted mean up to the horizon).
    pub best: u32,
    /// Family-wise error rate of the verdicts.
    pub alpha: f64,
    /// Whether runs were paired by sample.
    pub paired: bool,
    /// One entry per other design: the comparison (A = best), its
    /// Holm-adjusted p-value and the verdict.
    pub others: Vec<(Comparison, f64, Verdict)>,
}

/// Rank designs by Kaplan–Meier median (restricted mean up to `horizon` to
/// break ties and to order designs whose median lies beyond the run) and
/// compare the first with every other. `None` with fewer than two designs.
pub fn best_versus_rest(
    designs: &[DesignRuns],
    horizon: f64,
    alpha: f64,
    common_random_numbers: bool,
    seed: u64,
) -> Option<BestVersusRest> {
    if designs.len() < 2 {
        return None;
    }
    let key = |d: &DesignRuns| {
        let km = d.kaplan_meier();
        let median = km
            .as_ref()
            .and_then(|k| k.median())
            .unwrap_or(f64::INFINITY);
        let rmst = km.map_or(f64::INFINITY, |k| k.restricted_mean(horizon).estimate);
        (median, rmst)
    };
    let best = designs.iter().min_by(|x, y| {
        let (kx, ky) = (key(x), key(y));
        kx.0.total_cmp(&ky.0).then(kx.1.total_cmp(&ky.1))
    })?;
    let paired =
        common_random_numbers && designs.iter().all(|d| pairing_refusal(best, d).is_none());
    // In parallel: each comparison draws from its own stream, and collect
    // keeps the order, so the result does not depend on the thread count.
    let comparisons: Vec<Comparison> = designs
        .par_iter()
        .with_max_len(1) // one comparison per job, as runs (study::run)
        .filter(|d| d.design_id != best.design_id)
        .map(|d| compare(best, d, paired, seed))
        .collect();
    let p: Vec<f64> = comparisons.iter().map(Comparison::p_value).collect();
    let adjusted = holm_adjust(&p);
    let others = comparisons
        .into_iter()
        .zip(adjusted)
        .map(|(c, p_holm)| {
            let verdict = match (p_holm <= alpha, c.a_is_sooner()) {
                (true, true) => Verdict::BestSooner,
                (true, false) => Verdict::OtherSooner,
                (false, _) => Verdict::NotDistinguishable,
            };
            (c, p_holm, verdict)
        })
        .collect();
    Some(BestVersusRest {
        best: best.design_id,
        alpha,
        paired,
        others,
    })
}
