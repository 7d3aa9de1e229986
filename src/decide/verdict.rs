//! Which design settles sooner, and how sure is it: comparisons of designs
//! that count every run (unsettled ones as censored), paired when the
//! designs met the same sampled unbalances (common random numbers), and the
//! best design against every other with Holm's correction.
//!
//! Over 600 lines with its unit tests (the code is about 550): the rules a
//! verdict rests on (what balances, what works, a material effect, which
//! measure favours which design, a winner on the edge of a sweep) are kept
//! together so that one reading gives them all.

use crate::decide::measure::sign_difference;
use crate::stats::holm::holm_adjust;
use crate::stats::paired::{
    Settling, SettlingComparison, WilcoxonResult, compare_settling, median_ratio,
    wilcoxon_signed_rank,
};
use crate::stats::paired_measures::{Difference, honest_p};
use crate::stats::survival::{LogRank, log_rank};
use crate::study::plan::criterion::Criterion;
use crate::study::plan::stream::{Purpose, stream};
pub use crate::study::results::design_runs::{
    SettlingClock, design_runs, measure_scale, settling_horizon,
};
pub use crate::study::results::measured_runs::DesignRuns;
use crate::study::results::measured_runs::Scale;
use rayon::prelude::*;

/// Level of every interval the comparisons report.
pub const LEVEL: f64 = 0.95;

/// How many leading runs two designs share: the shorter one's, when its
/// samples are the first of the longer one's (a raced design that left
/// early, [`crate::study::run::racing`]); `None` when their samples differ otherwise.
pub fn shared_prefix(a: &DesignRuns, b: &DesignRuns) -> Option<usize> {
    let n = a.sample_ids.len().min(b.sample_ids.len());
    (a.sample_ids[..n] == b.sample_ids[..n]).then_some(n)
}

/// Why two designs' runs cannot be paired: their samples are not the same,
/// nor the first of one another's.
pub fn pairing_refusal(a: &DesignRuns, b: &DesignRuns) -> Option<String> {
    shared_prefix(a, b).is_none().then(|| {
        format!(
            "design {} has {} runs and design {} has {}, not of the same samples",
            a.design_id,
            a.sample_ids.len(),
            b.design_id,
            b.sample_ids.len()
        )
    })
}

/// Design A against design B on one measure.
#[derive(Debug, Clone)]
pub struct MeasureComparison {
    /// The measure.
    pub criterion: Criterion,
    /// A, B and A − B with its interval and unadjusted p-value (`None`:
    /// nothing to compare, e.g. no residuals).
    pub difference: Option<Difference>,
    /// Holm-adjusted p-value over the comparisons of the best design on this
    /// measure (the unadjusted one until [`best_versus_rest`] adjusts it).
    pub p_holm: f64,
}

/// A design axis of the grid, as the study file names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// `designs.n`.
    Count,
    /// `designs.rho`.
    Rho,
    /// `designs.drag`.
    Drag,
}

impl Axis {
    /// The key in the study file.
    pub fn key(self) -> &'static str {
        match self {
            Axis::Count => "designs.n",
            Axis::Rho => "designs.rho",
            Axis::Drag => "designs.drag",
        }
    }
}

/// A winner at the end of a swept axis: the axis, and whether it sits at
/// the largest value swept (else the smallest).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge {
    /// Which axis.
    pub axis: Axis,
    /// At the largest value swept.
    pub high: bool,
    /// The winner's value there.
    pub value: f64,
}

/// The swept axes (at least three values among the designs of the winner's
/// kind) on whose end the winner sits, where the best may lie beyond what
/// was swept: only where the winner is significantly better than its
/// neighbours one step inside (`beaten[j]`: #1 better than design j; a
/// winner tied with them says nothing about beyond), and only where a step
/// beyond is a part that exists (n + 1 balls or rollers that fit, a ρ
/// below ρ_max). `designs` holds (kind, n, ρ, β) per design, `best` its index.
pub fn edges(designs: &[(String, f64, f64, f64)], best: usize, beaten: &[bool]) -> Vec<Edge> {
    let Some(winner) = designs.get(best) else {
        return Vec::new();
    };
    let pick = [
        (
            Axis::Count,
            (|d: &(String, f64, f64, f64)| d.1) as fn(&(String, f64, f64, f64)) -> f64,
        ),
        (Axis::Rho, |d| d.2),
        (Axis::Drag, |d| d.3),
    ];
    pick.iter()
        .filter_map(|&(axis, value)| {
            let mut swept: Vec<f64> = designs
                .iter()
                .filter(|d| d.0 == winner.0)
                .map(value)
                .filter(|v| v.is_finite())
                .collect();
            swept.sort_by(f64::total_cmp);
            swept.dedup();
            let v = value(winner);
            if swept.len() < 3 {
                return None;
            }
            let high = v == *swept.last()?;
            if !(high || v == swept[0]) {
                return None;
            }
            let inside = if high {
                swept[swept.len() - 2]
            } else {
                swept[1]
            };
            // The neighbours one step inside: same kind, the other axes as
            // the winner's where the grid has such designs.
            let neighbours: Vec<usize> = (0..designs.len())
                .filter(|&j| designs[j].0 == winner.0 && value(&designs[j]) == inside)
                .collect();
            let same_elsewhere: Vec<usize> = neighbours
                .iter()
                .copied()
                .filter(|&j| {
                    pick.iter()
                        .filter(|(other, _)| *other != axis)
                        .all(|(_, f)| f(&designs[j]) == f(winner))
                })
                .collect();
            let neighbours = if same_elsewhere.is_empty() {
                neighbours
            } else {
                same_elsewhere
            };
            let beats = !neighbours.is_empty()
                && neighbours
                    .iter()
                    .all(|&j| beaten.get(j).copied().unwrap_or(false));
            (beats && beyond_exists(winner, axis, high, (v - inside).abs())).then_some(Edge {
                axis,
                high,
                value: v,
            })
        })
        .collect()
}

/// Whether a step beyond the winner along `axis` is a part that exists:
/// one more ball or roller that still fits at its ρ, a ρ half the last
/// `step` larger still below ρ_max(n), at least one weight; pendulums pass
/// each other and always fit.
fn beyond_exists(winner: &(String, f64, f64, f64), axis: Axis, high: bool, step: f64) -> bool {
    let (kind, n, rho) = (&winner.0, winner.1, winner.2);
    let packed = kind != "pendulum";
    let fits = |n: f64, rho: f64| {
        !packed
            || crate::design::geometry::rho_max(n as u32).is_ok_and(|max| rho < max * (1.0 - 1e-9))
    };
    match (axis, high) {
        (Axis::Count, true) => fits(n + 1.0, rho),
        (Axis::Count, false) => n > 1.0,
        (Axis::Rho, true) => fits(n, rho + 0.5 * step),
        (Axis::Rho, false) | (Axis::Drag, _) => true,
    }
}

/// The smallest difference worth reporting, relative to the larger of the
/// two values compared: 1 %. A difference below it is "not
/// distinguishable" however small its p-value (a residual p95 of 0.3640
/// against 0.3640, 3·10⁻⁶ apart, was once reported as a disagreement at
/// Holm p 0.001).
pub const MIN_RELATIVE_EFFECT: f64 = 0.01;

/// Whether a difference between values `a` and `b` is large enough to report.
pub fn material(a: f64, b: f64, difference: f64) -> bool {
    difference.abs() >= MIN_RELATIVE_EFFECT * a.abs().max(b.abs())
}

/// Whether a measured difference is large enough to report: 1 % of its
/// own scale (for a restricted mean, of the settled runs' mean time, so
/// that a longer horizon, which adds τ to every censored run of both
/// designs, cannot turn a difference into "not distinguishable").
pub fn material_difference(d: &Difference) -> bool {
    d.difference.abs() >= MIN_RELATIVE_EFFECT * d.scale
}

/// Which design of a comparison of A against B a measure favours.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Favours {
    /// Design A.
    A,
    /// Design B.
    B,
}

/// The one rule by which a measure favours a design, used by every verdict,
/// every "the measures disagree" sentence (`study run`, `study compare`,
/// `study claims`) and the decision: significant at `alpha` on its
/// Holm-adjusted p-value, non-zero, and large enough to matter
/// ([`material`]). `None` when it favours neither.
pub fn favoured(criterion: Criterion, d: &Difference, p_holm: f64, alpha: f64) -> Option<Favours> {
    let significant = p_holm <= alpha && d.difference != 0.0 && material_difference(d);
    significant.then(|| {
        if criterion.a_better(d.difference) {
            Favours::A
        } else {
            Favours::B
        }
    })
}

impl MeasureComparison {
    /// True when A is better than B on this measure at level `alpha`, by a
    /// difference worth reporting ([`favoured`]).
    pub fn a_better_at(&self, alpha: f64) -> bool {
        self.favours(alpha) == Some(Favours::A)
    }

    /// True when B is better than A on this measure at level `alpha`, by a
    /// difference worth reporting.
    pub fn b_better_at(&self, alpha: f64) -> bool {
        self.favours(alpha) == Some(Favours::B)
    }

    /// The side this measure favours at `alpha` on its own Holm p-value.
    pub fn favours(&self, alpha: f64) -> Option<Favours> {
        self.difference
            .and_then(|d| favoured(self.criterion, &d, self.p_holm, alpha))
    }
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
    /// A against B on each measure asked for, in the order asked.
    pub measures: Vec<MeasureComparison>,
}

impl Comparison {
    /// The comparison on one measure, if it was asked for.
    pub fn on(&self, criterion: Criterion) -> Option<&MeasureComparison> {
        self.measures.iter().find(|m| m.criterion == criterion)
    }

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
/// [`pairing_refusal`]), on every measure in `measures`; `seed` seeds the
/// bootstrap intervals.
pub fn compare(
    a: &DesignRuns,
    b: &DesignRuns,
    paired: bool,
    measures: &[Criterion],
    scale: &Scale,
    seed: u64,
) -> Comparison {
    // A design that left a race is compared on the samples it ran.
    let trimmed;
    let (a, b) = match shared_prefix(a, b) {
        Some(n) if paired && (n < a.sample_ids.len() || n < b.sample_ids.len()) => {
            trimmed = (a.first(n), b.first(n));
            (&trimmed.0, &trimmed.1)
        }
        _ => (a, b),
    };
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
    let medians = (median(a), median(b));
    let measures = measures
        .iter()
        .map(|&criterion| {
            // The paired median reuses the sign test above (same stream).
            let difference = match (criterion, &settling) {
                (Criterion::Median, Some(c)) => Some(sign_difference(
                    c,
                    medians.0.unwrap_or(f64::INFINITY),
                    medians.1.unwrap_or(f64::INFINITY),
                )),
                (Criterion::Median, None) if !paired => unpaired.map(|u| Difference {
                    a: medians.0.unwrap_or(f64::INFINITY),
                    b: medians.1.unwrap_or(f64::INFINITY),
                    scale: medians
                        .0
                        .unwrap_or(f64::INFINITY)
                        .max(medians.1.unwrap_or(f64::INFINITY)),
                    difference: medians.0.unwrap_or(f64::INFINITY)
                        - medians.1.unwrap_or(f64::INFINITY),
                    interval: (f64::NEG_INFINITY, f64::INFINITY),
                    p_value: honest_p(u.p_value),
                    test: "log_rank",
                }),
                _ => criterion.compare(a, b, paired, scale, LEVEL, &mut rng),
            };
            MeasureComparison {
                criterion,
                p_holm: difference.map_or(1.0, |d| d.p_value),
                difference,
            }
        })
        .collect();
    Comparison {
        a: a.design_id,
        b: b.design_id,
        runs: (a.settling.len(), b.settling.len()),
        medians,
        paired: settling,
        unpaired,
        residual_test,
        residual_ratio,
        measures,
    }
}

/// The verdict on the best design against one other, on the ranking criterion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The best design is better (Holm-adjusted p ≤ α).
    BestBetter,
    /// The data cannot tell the two apart at α.
    NotDistinguishable,
    /// The other design is significantly better by the criterion's test,
    /// although the best ranks first on the criterion's point estimate.
    OtherBetter,
}

impl Verdict {
    /// The verdict as stored in `summary.parquet`.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::BestBetter => "best_better",
            Verdict::NotDistinguishable => "not_distinguishable",
            Verdict::OtherBetter => "other_better",
        }
    }
}

/// The least share of runs the first design must settle in, and the most
/// residual/A_ref (median) it may leave, to be called a working balancer.
pub const MIN_SETTLED_SHARE: f64 = 0.5;

/// The share of runs a design that works settles in: below it a crowned
/// design is recommended with its shortfall stated.
pub const WORKS_SETTLED_SHARE: f64 = 0.9;

/// The most runs a design that works may leave vibrating more than with no
/// balancer (residual/A_ref above 1).
pub const WORKS_WORSE_SHARE: f64 = 0.05;

/// Where a design falls short of one that works, with the share measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shortfall {
    /// It settles in fewer than [`WORKS_SETTLED_SHARE`] of its runs.
    SettlesTooRarely(f64),
    /// More than [`WORKS_WORSE_SHARE`] of its runs end worse than no balancer.
    OftenWorseThanNone(f64),
}

/// The ways a design with these shares falls short of one that works
/// (empty when it works).
pub fn shortfalls(settled_share: f64, worse_than_none_share: f64) -> Vec<Shortfall> {
    let mut out = Vec::new();
    if settled_share < WORKS_SETTLED_SHARE {
        out.push(Shortfall::SettlesTooRarely(settled_share));
    }
    if worse_than_none_share > WORKS_WORSE_SHARE {
        out.push(Shortfall::OftenWorseThanNone(worse_than_none_share));
    }
    out
}

/// The best design against every other one.
#[derive(Debug, Clone)]
pub struct BestVersusRest {
    /// The design ranked first by `criterion` (ties: the lower restricted
    /// mean, the lower residual p95, then the lower design id).
    pub best: u32,
    /// What designs were ranked by.
    pub criterion: Criterion,
    /// Family-wise error rate of the verdicts (per measure).
    pub alpha: f64,
    /// Whether runs were paired by sample.
    pub paired: bool,
    /// Whether the first design balances at all: it settles in at least
    /// [`MIN_SETTLED_SHARE`] of its runs and its median residual/A_ref is at
    /// most 1. When it does not, no design is called best.
    pub works: bool,
    /// Design ids, best first, in ranking order.
    pub order: Vec<u32>,
    /// One entry per other design: the comparison (A = best), its
    /// Holm-adjusted p-value on the criterion and the verdict.
    pub others: Vec<(Comparison, f64, Verdict)>,
}

/// Design indices of `designs`, best first: the designs that balance
/// ([`balances`]) before those that do not, each group by `criterion`
/// (ties: the lower restricted mean, then the lower residual p95, then the
/// grid order). A design that settles in under half its runs is no answer
/// to "which one do I build", however fast its lucky runs are, so it never
/// ranks above one that works (before 2026-11-27 it could, and then the
/// study printed "no design balances" beside a design that did).
pub fn ranking(designs: &[DesignRuns], criterion: Criterion, scale: &Scale) -> Vec<usize> {
    // Ties (every design at τ when none settles, for instance) go to the
    // lower restricted mean, then to the lower residual p95: of designs that
    // do not settle, the one leaving the least vibration is the least bad.
    let keys: Vec<[Option<f64>; 3]> = designs
        .iter()
        .map(|d| {
            [
                criterion.value(d, scale),
                Criterion::Mean.value(d, scale),
                Criterion::ResidualP95.value(d, scale),
            ]
        })
        .collect();
    let fails: Vec<bool> = designs.iter().map(|d| !balances(d)).collect();
    let mut order: Vec<usize> = (0..designs.len()).collect();
    order.sort_by(|&x, &y| {
        fails[x]
            .cmp(&fails[y])
            .then(criterion.order(keys[x][0], keys[y][0]))
            .then(Criterion::Mean.order(keys[x][1], keys[y][1]))
            .then(Criterion::ResidualP95.order(keys[x][2], keys[y][2]))
            .then(x.cmp(&y))
    });
    order
}

/// Design ids not dominated on `measures`: no other design is at least as
/// good on every measure and better on one (a value beyond the run or
/// missing counts as the worst).
pub fn pareto_set(designs: &[DesignRuns], measures: &[Criterion], scale: &Scale) -> Vec<u32> {
    let values: Vec<Vec<Option<f64>>> = designs
        .iter()
        .map(|d| measures.iter().map(|m| m.value(d, scale)).collect())
        .collect();
    let dominates = |x: usize, y: usize| {
        let mut strictly = false;
        for (k, m) in measures.iter().enumerate() {
            match m.order(values[x][k], values[y][k]) {
                std::cmp::Ordering::Greater => return false,
                std::cmp::Ordering::Less => strictly = true,
                std::cmp::Ordering::Equal => {}
            }
        }
        strictly
    };
    (0..designs.len())
        .filter(|&y| !(0..designs.len()).any(|x| x != y && dominates(x, y)))
        .map(|y| designs[y].design_id)
        .collect()
}

/// Whether a design balances: it settled in at least [`MIN_SETTLED_SHARE`]
/// of its runs, left a median residual/A_ref of at most 1, and does not end
/// worse than no balancer in significantly more than [`WORKS_WORSE_SHARE`]
/// of its runs (the Wilson interval's lower end above it: a washer whose
/// rollers circulated in a quarter of its runs, 18–34× worse than none,
/// was called balancing before 2026-12-07).
pub fn balances(runs: &DesignRuns) -> bool {
    let n = runs.settling.len();
    let settled = runs.settling.iter().filter(|o| o.settled).count();
    let mut residual: Vec<f64> = runs.residual.iter().flatten().copied().collect();
    residual.sort_by(f64::total_cmp);
    let median = crate::stats::quantile::quantile_sorted(
        &residual,
        0.5,
        crate::stats::quantile::Interpolation::Linear,
    );
    let worse = residual.iter().filter(|&&r| r > 1.0).count();
    let (worse_lo, _) = crate::stats::interval::wilson_interval(worse as u64, n as u64);
    n > 0
        && settled as f64 >= MIN_SETTLED_SHARE * n as f64
        && median.is_none_or(|m| m <= 1.0)
        && worse_lo <= WORKS_WORSE_SHARE
}

/// Rank designs by `criterion` and compare the first with every other on
/// the criterion and on every measure of [`Criterion::REPORTED`], each
/// measure Holm-adjusted over the comparisons. `None` with fewer than two
/// designs.
pub fn best_versus_rest(
    designs: &[DesignRuns],
    criterion: Criterion,
    scale: &Scale,
    alpha: f64,
    common_random_numbers: bool,
    seed: u64,
) -> Option<BestVersusRest> {
    if designs.len() < 2 {
        return None;
    }
    let order = ranking(designs, criterion, scale);
    let best = &designs[order[0]];
    let paired =
        common_random_numbers && designs.iter().all(|d| pairing_refusal(best, d).is_none());
    let mut measures = vec![criterion];
    measures.extend(Criterion::REPORTED.iter().filter(|&&c| c != criterion));
    // In parallel: each comparison draws from its own stream, and collect
    // keeps the order, so the result does not depend on the thread count.
    let mut comparisons: Vec<Comparison> = designs
        .par_iter()
        .with_max_len(1) // one comparison per job, as runs (study::run)
        .filter(|d| d.design_id != best.design_id)
        .map(|d| compare(best, d, paired, &measures, scale, seed))
        .collect();
    for k in 0..measures.len() {
        let p: Vec<f64> = comparisons
            .iter()
            .map(|c| c.measures[k].difference.map_or(1.0, |d| d.p_value))
            .collect();
        for (c, p_holm) in comparisons.iter_mut().zip(holm_adjust(&p)) {
            c.measures[k].p_holm = honest_p(p_holm);
        }
    }
    let others = comparisons
        .into_iter()
        .map(|c| {
            let on = &c.measures[0];
            let verdict = if on.a_better_at(alpha) {
                Verdict::BestBetter
            } else if on.b_better_at(alpha) {
                Verdict::OtherBetter
            } else {
                Verdict::NotDistinguishable
            };
            let p = on.p_holm;
            (c, p, verdict)
        })
        .collect();
    Some(BestVersusRest {
        best: best.design_id,
        criterion,
        alpha,
        paired,
        works: balances(best),
        order: order.iter().map(|&i| designs[i].design_id).collect(),
        others,
    })
}

/// Holm-adjust every measure over the comparisons of several families at
/// once (the families that answer one question, e.g. one claim under every
/// normalisation), replacing each family's own adjustment, and recompute the
/// verdicts on the ranking criterion.
pub fn holm_across(families: &mut [BestVersusRest]) {
    let Some(first) = families.first() else {
        return;
    };
    let measures = first.others.first().map_or(0, |(c, _, _)| c.measures.len());
    for k in 0..measures {
        let raw: Vec<f64> = families
            .iter()
            .flat_map(|f| f.others.iter())
            .map(|(c, _, _)| {
                c.measures
                    .get(k)
                    .and_then(|m| m.difference)
                    .map_or(1.0, |d| d.p_value)
            })
            .collect();
        let mut adjusted = holm_adjust(&raw).into_iter();
        for family in families.iter_mut() {
            for (c, _, _) in family.others.iter_mut() {
                let p = adjusted.next().unwrap_or(1.0);
                if let Some(m) = c.measures.get_mut(k) {
                    m.p_holm = honest_p(p);
                }
            }
        }
    }
    for family in families.iter_mut() {
        let alpha = family.alpha;
        for (c, p, verdict) in family.others.iter_mut() {
            let Some(on) = c.measures.first() else {
                continue;
            };
            *p = on.p_holm;
            *verdict = if on.a_better_at(alpha) {
                Verdict::BestBetter
            } else if on.b_better_at(alpha) {
                Verdict::OtherBetter
            } else {
                Verdict::NotDistinguishable
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::survival::Observation;
    use crate::study::plan::criterion::Within;

    /// Runs that settle at `settled` (revolutions) or are censored at 500.
    fn design(id: u32, settled: &[Option<f64>]) -> DesignRuns {
        DesignRuns {
            design_id: id,
            sample_ids: (0..settled.len() as u32).collect(),
            settling: settled
                .iter()
                .map(|s| match s {
                    Some(t) => Observation {
                        time: *t,
                        settled: true,
                    },
                    None => Observation {
                        time: 500.0,
                        settled: false,
                    },
                })
                .collect(),
            residual: settled
                .iter()
                .map(|s| Some(if s.is_some() { 0.02 } else { 0.5 }))
                .collect(),
            residual_abs: vec![Some(1e-6); settled.len()],
        }
    }

    /// A design that settles in 18 of 24 runs with a median residual well
    /// under A_ref balanced before 2026-12-07 even when its 6 other runs
    /// ended 20× worse than no balancer (circulating weights); 6 of 24 is
    /// significantly more than 5 % (Wilson lower end 0.12), so it does not
    /// balance now. One run of 24 worse than none (lower end 0.007) still
    /// balances, with its shortfall named elsewhere.
    #[test]
    fn a_design_often_worse_than_none_does_not_balance() {
        let times: Vec<Option<f64>> = (0..24).map(|k| (k >= 6).then_some(30.0)).collect();
        let mut trapped = design(0, &times);
        for r in trapped.residual.iter_mut().take(6) {
            *r = Some(20.0);
        }
        assert!(!balances(&trapped));
        let mut once = design(1, &times);
        once.residual[0] = Some(20.0);
        assert!(balances(&once));
    }

    /// Two designs whose runs have the same outcomes at any horizon: B
    /// settles 2.4 rev after A in each of 14 paired runs, and 6 runs of
    /// each never settle (censored at the horizon τ).
    fn horizon_pair(tau: f64) -> [DesignRuns; 2] {
        let make = |id: u32, shift: f64| DesignRuns {
            design_id: id,
            sample_ids: (0..20).collect(),
            settling: (0..20)
                .map(|i| match i {
                    0..14 => Observation {
                        time: 20.0 + 0.5 * f64::from(i) + shift + 0.01 * f64::from(i % 3),
                        settled: true,
                    },
                    _ => Observation {
                        time: tau,
                        settled: false,
                    },
                })
                .collect(),
            residual: vec![Some(0.02); 20],
            residual_abs: vec![Some(1e-6); 20],
        };
        [make(0, 0.0), make(1, 2.4)]
    }

    #[test]
    fn a_verdict_on_the_restricted_mean_does_not_hang_on_the_horizon() {
        // The difference of the restricted means is 14·2.4/20 = 1.68 rev at
        // every τ, while the means grow with τ (6 of 20 runs counted at τ):
        // 1 % of the mean (1.8 rev at τ = 550, 3.5 at 1 150) would call it
        // "not distinguishable"; 1 % of the settled runs' mean (0.26 rev)
        // keeps the verdict.
        for tau in [550.0, 1150.0] {
            let designs = horizon_pair(tau);
            let scale = Scale {
                tau,
                rev_seconds: 0.01,
            };
            let v = best_versus_rest(&designs, Criterion::Mean, &scale, 0.05, true, 1).unwrap();
            assert_eq!(v.best, 0, "τ = {tau}");
            let verdicts: Vec<Verdict> = v.others.iter().map(|o| o.2).collect();
            assert_eq!(verdicts, vec![Verdict::BestBetter], "τ = {tau}");
        }
    }

    #[test]
    fn a_design_that_works_ranks_above_a_faster_one_that_mostly_fails() {
        // A: 4 of 10 runs settle by 10 rev, the rest never (40 %: no
        // balancer); B: every run settles at 40 rev. By "settled by 30 rev"
        // A leads, 0.4 against 0; the crown goes to B, which works.
        let mut a = vec![Some(10.0); 4];
        a.extend([None; 6]);
        let designs = [design(0, &a), design(1, &[Some(40.0); 10])];
        let scale = Scale {
            tau: 490.0,
            rev_seconds: 0.01,
        };
        let by = Criterion::SettledBy(Within::Revs(30.0));
        assert_eq!(by.value(&designs[0], &scale), Some(0.4));
        assert_eq!(ranking(&designs, by, &scale), vec![1, 0]);
        let v = best_versus_rest(&designs, by, &scale, 0.05, true, 1).unwrap();
        assert_eq!((v.best, v.works), (1, true));
        // With neither working, the criterion alone orders them.
        let designs = [design(0, &a), design(1, &a[1..])];
        let v = best_versus_rest(&designs, by, &scale, 0.05, true, 1).unwrap();
        assert!(!v.works);
    }

    #[test]
    fn a_difference_below_one_percent_is_not_reported_however_significant() {
        use crate::stats::paired_measures::Difference;
        let tiny = MeasureComparison {
            criterion: Criterion::ResidualP95,
            difference: Some(Difference {
                a: 0.364_003,
                b: 0.364_000,
                scale: 0.364_003,
                difference: 3e-6,
                interval: (2e-6, 4e-6),
                p_value: 1e-4,
                test: "bootstrap_paired",
            }),
            p_holm: 1e-3,
        };
        assert!(!tiny.b_better_at(0.05) && !tiny.a_better_at(0.05));
        let real = MeasureComparison {
            difference: Some(Difference {
                a: 0.40,
                b: 0.36,
                scale: 0.40,
                difference: 0.04,
                ..tiny.difference.unwrap()
            }),
            ..tiny
        };
        assert!(real.b_better_at(0.05));
        assert!(material(10.0, 9.9, 0.1) && !material(10.0, 9.95, 0.05));
    }

    #[test]
    fn a_marginal_winner_has_its_shortfalls_named() {
        // The audit's crowned design: 65 % settled, 18 % worse than none.
        assert_eq!(
            shortfalls(0.65, 0.18),
            vec![
                Shortfall::SettlesTooRarely(0.65),
                Shortfall::OftenWorseThanNone(0.18)
            ]
        );
        assert!(shortfalls(0.95, 0.01).is_empty());
        assert_eq!(
            shortfalls(0.95, 0.06),
            vec![Shortfall::OftenWorseThanNone(0.06)]
        );
    }

    #[test]
    fn a_winner_at_the_end_of_a_sweep_names_the_axis_to_extend() {
        let grid = |drags: &[f64]| -> Vec<(String, f64, f64, f64)> {
            drags
                .iter()
                .map(|&b| ("ball".to_string(), 3.0, 0.3, b))
                .collect()
        };
        // The optical drive: the largest drag swept wins, better than the
        // next inside.
        let all = [true; 3];
        let e = edges(&grid(&[3e-5, 3e-4, 3e-3]), 2, &all);
        assert_eq!(
            e,
            vec![Edge {
                axis: Axis::Drag,
                high: true,
                value: 3e-3
            }]
        );
        assert!(!edges(&grid(&[3e-5, 3e-4, 3e-3]), 0, &all)[0].high);
        // Inside the sweep, or a two-value comparison: nothing to extend.
        assert!(edges(&grid(&[3e-5, 3e-4, 3e-3]), 1, &all).is_empty());
        assert!(edges(&grid(&[3e-4, 3e-3]), 1, &all).is_empty());
    }

    #[test]
    fn edge_advice_needs_a_win_over_the_interior_and_a_part_beyond() {
        // The optical drive: 5 balls at the smallest ρ swept, tied with
        // ρ = 0.146 one step inside: nothing says the best is beyond.
        let grid: Vec<(String, f64, f64, f64)> = [0.1, 0.146, 0.2]
            .iter()
            .map(|&rho| ("ball".to_string(), 5.0, rho, 0.01))
            .collect();
        assert!(edges(&grid, 0, &[false, false, true]).is_empty());
        assert_eq!(edges(&grid, 0, &[false, true, true]).len(), 1);
        // At the largest ρ swept, better than the inside, but 5 balls half
        // a step larger would not fit (ρ_max(5) = 0.3702): no advice beyond.
        let packed: Vec<(String, f64, f64, f64)> = [0.3, 0.34, 0.37]
            .iter()
            .map(|&rho| ("ball".to_string(), 5.0, rho, 0.01))
            .collect();
        assert!(edges(&packed, 2, &[true, true, false]).is_empty());
        // Pendulums pass each other: a larger ρ always exists.
        let swung: Vec<(String, f64, f64, f64)> = packed
            .iter()
            .map(|d| ("pendulum".to_string(), d.1, d.2, d.3))
            .collect();
        assert_eq!(edges(&swung, 2, &[true, true, false]).len(), 1);
    }
}
