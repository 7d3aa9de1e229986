//! The study's decision, typed: which design to build, or why none; the
//! verdict of #1 against the others; where the other measures disagree; and
//! the recommendation with its cautions.
//!
//! `summary.parquet` is its serialised form: [`StudyDecision::from_summary`]
//! reads it back, and `study run`, `merge`, `report` and `compare` render it
//! (src/bin/study); nothing there decides. The rules are those of
//! [`crate::decide::verdict`] (docs/statistics.md): designs that balance rank first,
//! a measure favours a design by [`favoured`], a crown that falls short of a
//! design that works carries its [`Shortfall`]s, a winner at the end of a
//! swept axis its [`Edge`]s.

use crate::decide::verdict::{Edge, Favours, Shortfall, edges, favoured, shortfalls};
use crate::stats::paired_measures::Difference;
use crate::study::plan::criterion::Criterion;
use crate::study::plan::tie_break::{Candidate, TieBreak, choose};
use crate::study::results::summary_columns::SummaryColumns;
use polars::prelude::{DataFrame, PolarsResult};

/// The verdict stored for a design in `summary.parquet` (`vs_best_verdict`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StoredVerdict {
    /// The first-ranked design, which balances.
    Best,
    /// #1 is better than this design at α.
    BestBetter,
    /// The data cannot tell this design from #1.
    NotDistinguishable,
    /// This design is significantly better than #1 on the criterion's test.
    OtherBetter,
    /// #1 does not balance, and so no design does.
    NoDesignBalances,
    /// The study has one design.
    OnlyDesign,
}

impl StoredVerdict {
    /// The verdict of a stored name; `None` for a name this build does not know.
    pub fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "best" => Self::Best,
            "best_better" => Self::BestBetter,
            "not_distinguishable" => Self::NotDistinguishable,
            "other_better" => Self::OtherBetter,
            "no_design_balances" => Self::NoDesignBalances,
            "only_design" => Self::OnlyDesign,
            _ => return None,
        })
    }
}

/// One design in rank order.
#[derive(Debug, Clone, PartialEq)]
pub struct RankedDesign {
    /// Design id.
    pub id: u32,
    /// Its row in `summary.parquet`.
    pub row: usize,
    /// Its verdict against #1.
    pub verdict: Option<StoredVerdict>,
    /// Whether it balances (settles in at least half its runs, median residual ≤ A_ref).
    pub balances: bool,
    /// Not dominated on the study's Pareto measures.
    pub pareto: bool,
    /// It left the race before the study's end (fewer runs than the others).
    pub left_race: bool,
}

/// What the verdict line says of #1.
#[derive(Debug, Clone, PartialEq)]
pub enum Crown {
    /// #1 balances and was compared with the others on the criterion.
    Best {
        /// #1's id.
        best: u32,
        /// Designs #1 is better than.
        better_than: Vec<u32>,
        /// Designs the data cannot tell from #1.
        not_distinguishable: Vec<u32>,
        /// Designs better than #1 on the criterion's test, behind it on the point estimate.
        other_better: Vec<u32>,
    },
    /// No design balances: #1 is named, with why.
    NoneBalances {
        /// #1's id.
        best: u32,
        /// #1's settled share.
        settled_fraction: f64,
        /// #1's median residual/A_ref (`None`: no run was simulated to its end).
        residual_median: Option<f64>,
        /// The diagnosis, in words.
        cause: Option<String>,
        /// The diagnosis' key (`diagnosis_cause`).
        cause_key: Option<String>,
        /// #1's share of runs that end worse than with no balancer.
        worse_than_none: Option<f64>,
        /// #1's dead band μ_s·l over its median A_ref, when rolling
        /// resistance is on and the dead band exceeds A_ref: the weights
        /// never break away, and no band narrower than the dead band helps.
        dead_band_over_a_ref: Option<f64>,
        /// #1's dead band over its settling band δ·A_ref (how many times
        /// lower the friction must be for the dead band to fit the band).
        dead_band_over_band: Option<f64>,
    },
    /// One design that balances, or none at all: nothing to crown against.
    Alone,
}

/// A design significantly and materially better than #1 on a reported
/// measure other than the ranking criterion.
#[derive(Debug, Clone, PartialEq)]
pub struct Disagreement {
    /// The design.
    pub design: u32,
    /// The measure.
    pub measure: Criterion,
    /// The design's value and #1's (`None`: beyond the run, or not measured).
    pub values: (Option<f64>, Option<f64>),
    /// This design minus #1, with its interval and Holm-adjusted p-value.
    pub difference: f64,
    /// Interval of the difference.
    pub interval: (Option<f64>, Option<f64>),
    /// Holm-adjusted p-value.
    pub p_holm: f64,
}

/// The recommendation.
#[derive(Debug, Clone, PartialEq)]
pub enum Recommendation {
    /// Build this design.
    Build {
        /// Its id: #1, or the tie-break's choice among the designs the
        /// data cannot tell from #1.
        design: u32,
        /// #1 by the point estimate of the criterion.
        first: u32,
        /// The designs the part was chosen from, in rank order: #1 and every
        /// design that balances and is not shown worse than #1 at α (and did
        /// not leave the race). One design: no tie to break.
        indistinguishable: Vec<u32>,
        /// The rule that chose among them.
        tie_break: TieBreak,
        /// The part's risk of not settling: runs that did not settle, its
        /// runs, and the 95 % Wilson upper bound on the share.
        unsettled_risk: Option<(u64, u64, f64)>,
        /// The part in an engineer's terms (count, diameter, mass, race, drag),
        /// where the summary carries the dimensions.
        part: Option<String>,
        /// How it falls short of a design that works (empty: it works).
        shortfalls: Vec<Shortfall>,
        /// A floor at or above the own band of most of its runs that did not
        /// settle (`unsettled_floor`): why it falls short, when one does.
        unsettled_floor: Option<String>,
        /// The swept axes on whose end it sits.
        edges: Vec<Edge>,
        /// The Pareto set, #1 included, in rank order.
        pareto: Vec<u32>,
    },
    /// No design balances: none is recommended.
    NoneBalances,
    /// The summary has no design.
    NoDesigns,
}

/// Which design to build, or why none, as `summary.parquet` records it.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyDecision {
    /// The ranking criterion.
    pub criterion: Criterion,
    /// α of the verdicts.
    pub alpha: f64,
    /// The test of the verdicts (`vs_best_test`).
    pub test: String,
    /// Whether the verdicts paired runs on their shared samples.
    pub paired: bool,
    /// Most runs of a design.
    pub runs_per_design: u64,
    /// The designs in rank order.
    pub ranked: Vec<RankedDesign>,
    /// How the part is chosen among indistinguishable designs (`tie_break`).
    pub tie_break: TieBreak,
    /// The verdict on #1.
    pub crown: Crown,
    /// Designs better than #1 on another measure.
    pub disagreements: Vec<Disagreement>,
    /// The recommendation.
    pub recommendation: Recommendation,
    /// Why the leading design's runs do not settle (#1 when none
    /// balances, else the part recommended), as its re-runs without each
    /// effect tell (`cause_tested`; `None` when the experiment did not run).
    pub tested_cause: Option<TestedCause>,
}

/// The cause experiment's finding on one design, as `summary.parquet`
/// records it ([`crate::decide::causes`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TestedCause {
    /// The design whose runs were re-run.
    pub design: u32,
    /// The finding in words, with the counts.
    pub text: String,
    /// The causes' keys joined by "+", or `no_single_effect`.
    pub key: String,
}

/// The tested cause, from the `cause_tested` columns: on the one row the
/// experiment ran on (the columns are absent in summaries written before it).
fn tested_cause(c: &SummaryColumns, ranked: &[RankedDesign]) -> PolarsResult<Option<TestedCause>> {
    let text = c.s_or_none("cause_tested")?;
    let key = c.s_or_none("cause_tested_key")?;
    Ok(ranked.iter().find_map(|d| {
        Some(TestedCause {
            design: d.id,
            text: text[d.row].clone()?,
            key: key[d.row].clone().unwrap_or_default(),
        })
    }))
}

/// The summary column holding each reported measure's value.
fn value_column(m: Criterion) -> &'static str {
    match m {
        Criterion::Median => "settling_revs_median_km",
        Criterion::Mean => "settling_revs_rmst",
        Criterion::P90 => "settling_revs_p90_all_runs",
        _ => "residual_rel_p95",
    }
}

impl StudyDecision {
    /// The decision a summary records.
    pub fn from_summary(summary: &DataFrame) -> PolarsResult<Self> {
        let c = SummaryColumns(summary);
        let criterion = c
            .s("rank_by")?
            .into_iter()
            .flatten()
            .next()
            .and_then(|t| Criterion::parse(&t).ok())
            .unwrap_or_default();
        let ids: Vec<u32> = c
            .u32s("design_id")?
            .into_iter()
            .map(Option::unwrap_or_default)
            .collect();
        let rank = c.u32s("rank")?;
        let mut order: Vec<usize> = (0..summary.height()).collect();
        order.sort_by_key(|&i| (rank[i].unwrap_or(u32::MAX), i));
        let verdicts = c.s("vs_best_verdict")?;
        let balances = c.b("balances")?;
        let pareto = c.b("pareto")?;
        // Summaries written before racing lack the column: nobody left.
        let left_race: Vec<bool> = match summary.column("left_race_after") {
            Ok(col) => col.u32()?.iter().map(|v| v.is_some()).collect(),
            Err(_) => vec![false; summary.height()],
        };
        let ranked: Vec<RankedDesign> = order
            .iter()
            .map(|&i| RankedDesign {
                id: ids[i],
                row: i,
                verdict: verdicts[i].as_deref().and_then(StoredVerdict::parse),
                balances: balances[i],
                pareto: pareto[i],
                left_race: left_race[i],
            })
            .collect();
        let alpha = c
            .f("vs_best_alpha")?
            .into_iter()
            .flatten()
            .next()
            .unwrap_or(0.05);
        let test = c
            .s("vs_best_test")?
            .into_iter()
            .flatten()
            .next()
            .unwrap_or_default();
        let paired = test != "log_rank" && test != "bootstrap" && test != "two_proportion";
        let runs_per_design = summary
            .column("runs")?
            .u64()?
            .iter()
            .flatten()
            .max()
            .unwrap_or(0);
        let crown = crown(&c, &ranked)?;
        let disagreements = disagreements(&c, &ranked, criterion, alpha)?;
        // Summaries written before the tie-break kept #1 as the part.
        let tie_break = match summary.column("tie_break") {
            Ok(_) => c
                .s("tie_break")?
                .into_iter()
                .flatten()
                .next()
                .and_then(|t| TieBreak::parse(&t))
                .unwrap_or_default(),
            Err(_) => TieBreak::First,
        };
        let recommendation = recommendation(&c, &ranked, tie_break)?;
        let tested_cause = tested_cause(&c, &ranked)?;
        Ok(StudyDecision {
            criterion,
            alpha,
            test,
            paired,
            runs_per_design,
            ranked,
            tie_break,
            crown,
            disagreements,
            recommendation,
            tested_cause,
        })
    }

    /// The rank (1-based) of design `id`.
    pub fn rank_of(&self, id: u32) -> Option<usize> {
        self.ranked.iter().position(|d| d.id == id).map(|r| r + 1)
    }

    /// The leading `count` designs' ids, in rank order.
    pub fn leading(&self, count: usize) -> Vec<u32> {
        self.ranked.iter().take(count).map(|d| d.id).collect()
    }
}

/// The verdict on #1.
fn crown(c: &SummaryColumns, ranked: &[RankedDesign]) -> PolarsResult<Crown> {
    let Some(best) = ranked.first() else {
        return Ok(Crown::Alone);
    };
    let none_balances = best.verdict == Some(StoredVerdict::NoDesignBalances)
        || (best.verdict == Some(StoredVerdict::OnlyDesign) && !best.balances);
    if none_balances {
        return Ok(Crown::NoneBalances {
            best: best.id,
            settled_fraction: c.f("settled_fraction")?[best.row].unwrap_or(0.0),
            residual_median: c.f("residual_rel_median")?[best.row],
            cause: c.s("diagnosis")?[best.row].clone(),
            cause_key: c.s_or_none("diagnosis_cause")?[best.row].clone(),
            worse_than_none: c.f_or_none("worse_than_none_fraction")?[best.row],
            dead_band_over_a_ref: ratio(c, "a_ref_median", best.row)?.filter(|r| *r > 1.0),
            dead_band_over_band: ratio(c, "settling_band_m", best.row)?,
        });
    }
    if best.verdict != Some(StoredVerdict::Best) {
        return Ok(Crown::Alone);
    }
    let of = |v: StoredVerdict| -> Vec<u32> {
        ranked
            .iter()
            .filter(|d| d.verdict == Some(v))
            .map(|d| d.id)
            .collect()
    };
    Ok(Crown::Best {
        best: best.id,
        better_than: of(StoredVerdict::BestBetter),
        not_distinguishable: of(StoredVerdict::NotDistinguishable),
        other_better: of(StoredVerdict::OtherBetter),
    })
}

/// Row `row`'s dead band (`dead_band_m`) over its `column`; `None` without
/// rolling resistance or the columns.
fn ratio(c: &SummaryColumns, column: &str, row: usize) -> PolarsResult<Option<f64>> {
    let dead = c.f_or_none("dead_band_m")?[row];
    let of = c.f_or_none(column)?[row];
    Ok(dead.zip(of).filter(|(_, x)| *x > 0.0).map(|(d, x)| d / x))
}

/// Every design better than #1 on a reported measure other than the criterion.
fn disagreements(
    c: &SummaryColumns,
    ranked: &[RankedDesign],
    criterion: Criterion,
    alpha: f64,
) -> PolarsResult<Vec<Disagreement>> {
    let Some(best) = ranked.first().filter(|_| ranked.len() > 1) else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    for design in ranked.iter().skip(1) {
        for &m in Criterion::REPORTED.iter().filter(|&&m| m != criterion) {
            let name = m.to_string();
            let column = |suffix: &str| -> PolarsResult<Option<f64>> {
                Ok(c.f_or_none(&format!("vs_best_{name}_{suffix}"))?[design.row])
            };
            let (Some(diff), Some(p)) = (column("diff")?, column("p_holm")?) else {
                continue;
            };
            let interval = (column("diff_lo")?, column("diff_hi")?);
            let values = c.f(value_column(m))?;
            let (a, b) = (values[design.row], values[best.row]);
            // A restricted mean's difference is judged against the settled
            // runs' mean time (horizon-free), as the verdicts judged it.
            let settled = c.f_or_none("settling_revs_mean_settled")?;
            let own_scale = match (settled[design.row], settled[best.row]) {
                (Some(x), Some(y)) => Some(x.max(y)),
                (x, y) => x.or(y),
            }
            .filter(|_| m == Criterion::Mean);
            // A value beyond the run has no size: only the sign and p count.
            let d = Difference {
                a: a.unwrap_or(0.0),
                b: b.unwrap_or(0.0),
                scale: own_scale.unwrap_or(a.unwrap_or(0.0).abs().max(b.unwrap_or(0.0).abs())),
                difference: diff,
                interval: (
                    interval.0.unwrap_or(f64::NEG_INFINITY),
                    interval.1.unwrap_or(f64::INFINITY),
                ),
                p_value: p,
                test: "",
            };
            if favoured(m, &d, p, alpha) == Some(Favours::A) {
                out.push(Disagreement {
                    design: design.id,
                    measure: m,
                    values: (a, b),
                    difference: diff,
                    interval,
                    p_holm: p,
                });
            }
        }
    }
    Ok(out)
}

/// Row i's part when the planes have designs of their own (`n_plane0`, …
/// columns): "…, in each of 2 planes" when every plane's part is the same,
/// else each plane's ("plane 0: …; plane 1: …"); `None` without those
/// columns (or a summary written before they held the part's size).
fn plane_parts(c: &SummaryColumns, i: usize) -> PolarsResult<Option<String>> {
    let mut parts = Vec::new();
    while c.0.column(&format!("n_plane{}", parts.len())).is_ok() {
        let p = parts.len();
        let col = |k: &str| c.f_or_none(&format!("{k}_plane{p}"));
        let kind = c.s(&format!("kind_plane{p}"))?;
        let n = c.u32s(&format!("n_plane{p}"))?;
        let (rho, drag) = (col("rho")?, col("drag")?);
        let (race, mass) = (col("race_radius")?, col("weight_mass")?);
        let length = col("roller_height")?;
        match (&kind[i], n[i], rho[i], race[i], mass[i], drag[i]) {
            (Some(k), Some(n), Some(r), Some(race), Some(m), Some(b)) => {
                parts.push(crate::study::plan::design::part_text(
                    k,
                    n,
                    (r, race),
                    m,
                    b,
                    length[i],
                ));
            }
            _ => return Ok(None),
        }
    }
    Ok(match parts.as_slice() {
        [] => None,
        [one] => Some(one.clone()),
        [first, ..] if parts.iter().all(|p| p == first) => {
            Some(format!("{first}, in each of {} planes", parts.len()))
        }
        _ => Some(
            parts
                .iter()
                .enumerate()
                .map(|(p, text)| format!("plane {p}: {text}"))
                .collect::<Vec<_>>()
                .join("; "),
        ),
    })
}

/// The part of summary row `i` in an engineer's terms (count, diameter,
/// mass, race, drag), per plane where the planes differ; `None` where the
/// summary lacks the dimensions (written before those columns).
fn part_of(c: &SummaryColumns, i: usize) -> PolarsResult<Option<String>> {
    if let Some(parts) = plane_parts(c, i)? {
        return Ok(Some(parts));
    }
    let kind = c.s("kind")?;
    let n = c.u32s("n")?;
    let (rho, drag) = (c.f("rho")?, c.f("drag")?);
    let (race, mass) = (c.f_or_none("race_radius")?, c.f_or_none("weight_mass")?);
    let (Some(k), Some(n), Some(r), Some(race), Some(m), Some(b)) =
        (&kind[i], n[i], rho[i], race[i], mass[i], drag[i])
    else {
        return Ok(None);
    };
    let length = c.f_or_none("roller_height")?[i];
    let part = crate::study::plan::design::part_text(k, n, (r, race), m, b, length);
    let planes = balancer_planes(c, i)?;
    Ok(Some(if planes > 1 {
        format!("{part}, in each of {planes} planes")
    } else {
        part
    }))
}

/// Balancer planes of row `i` holding the one design (1 without the column).
fn balancer_planes(c: &SummaryColumns, i: usize) -> PolarsResult<u32> {
    Ok(match c.0.column("balancer_planes") {
        Ok(_) => c.u32s("balancer_planes")?[i].unwrap_or(1),
        Err(_) => 1,
    })
}

/// What the tie-break compares of summary row `i`: the total balancer mass
/// and weight count over every plane (per-plane designs summed).
fn candidate(c: &SummaryColumns, d: &RankedDesign, rank: usize) -> PolarsResult<Candidate> {
    let i = d.row;
    let mut mass = Some(0.0);
    let mut weights = 0;
    let mut p = 0;
    while c.0.column(&format!("n_plane{p}")).is_ok() {
        let n = c.u32s(&format!("n_plane{p}"))?[i].unwrap_or(0);
        let m = c.f_or_none(&format!("weight_mass_plane{p}"))?[i];
        mass = mass.zip(m).map(|(sum, m)| sum + f64::from(n) * m);
        weights += n;
        p += 1;
    }
    if p == 0 {
        let n = c.u32s("n")?[i].unwrap_or(0);
        let planes = balancer_planes(c, i)?;
        weights = n * planes;
        mass = c.f_or_none("weight_mass")?[i].map(|m| f64::from(weights) * m);
    }
    Ok(Candidate {
        id: d.id,
        rank,
        mass,
        weights,
        rho: c.f("rho")?[i],
    })
}

/// The indices (into `ranked`) of the designs the part is chosen from: #1
/// and every design that balances, was not shown worse than #1 at α and ran
/// the whole race (a design that left was shown worse at a look); of those,
/// only the ones that work (no shortfall) when any does.
fn tied(c: &SummaryColumns, ranked: &[RankedDesign]) -> PolarsResult<Vec<usize>> {
    let settled = c.f("settled_fraction")?;
    let worse = c.f_or_none("worse_than_none_fraction")?;
    let works = |d: &RankedDesign| {
        shortfalls(settled[d.row].unwrap_or(0.0), worse[d.row].unwrap_or(0.0)).is_empty()
    };
    let crowned = ranked
        .first()
        .is_some_and(|d| d.verdict == Some(StoredVerdict::Best));
    let set: Vec<usize> = (0..ranked.len())
        .filter(|&r| {
            let d = &ranked[r];
            r == 0
                || (crowned
                    && d.balances
                    && !d.left_race
                    && matches!(
                        d.verdict,
                        Some(StoredVerdict::NotDistinguishable | StoredVerdict::OtherBetter)
                    ))
        })
        .collect();
    let working: Vec<usize> = set.iter().copied().filter(|&r| works(&ranked[r])).collect();
    Ok(if working.is_empty() { set } else { working })
}

/// The recommendation: the part chosen by `tie_break` among the designs
/// the data cannot tell from #1, with its cautions, #1's edges, or none.
fn recommendation(
    c: &SummaryColumns,
    ranked: &[RankedDesign],
    tie_break: TieBreak,
) -> PolarsResult<Recommendation> {
    let Some(best) = ranked.first() else {
        return Ok(Recommendation::NoDesigns);
    };
    if best.verdict == Some(StoredVerdict::NoDesignBalances) || !best.balances {
        return Ok(Recommendation::NoneBalances);
    }
    let set = tied(c, ranked)?;
    let candidates = set
        .iter()
        .map(|&r| candidate(c, &ranked[r], r))
        .collect::<PolarsResult<Vec<_>>>()?;
    let chosen = choose(tie_break, &candidates).map_or(best.id, |c| c.id);
    let pick = ranked.iter().find(|d| d.id == chosen).unwrap_or(best);
    let i = pick.row;
    let worse = c.f_or_none("worse_than_none_fraction")?[i].unwrap_or(0.0);
    let settled = c.f("settled_fraction")?[i].unwrap_or(0.0);
    let kind = c.s("kind")?;
    let n = c.u32s("n")?;
    let (rho, drag) = (c.f("rho")?, c.f("drag")?);
    let grid: Vec<(String, f64, f64, f64)> = (0..kind.len())
        .map(|j| {
            (
                kind[j].clone().unwrap_or_default(),
                n[j].map_or(f64::NAN, f64::from),
                rho[j].unwrap_or(f64::NAN),
                drag[j].unwrap_or(f64::NAN),
            )
        })
        .collect();
    Ok(Recommendation::Build {
        design: pick.id,
        first: best.id,
        indistinguishable: set.iter().map(|&r| ranked[r].id).collect(),
        tie_break,
        part: part_of(c, i)?,
        unsettled_risk: unsettled_risk(c, i)?,
        shortfalls: shortfalls(settled, worse),
        unsettled_floor: c.s_or_none("unsettled_floor")?[i].clone(),
        // Where the best may lie beyond the grid is a question about #1.
        edges: edges(&grid, best.row, &beaten(c)?),
        pareto: ranked.iter().filter(|d| d.pareto).map(|d| d.id).collect(),
    })
}

/// Row `i`'s runs that did not settle, its runs, and the Wilson upper
/// bound on that share (1 − the settled share's lower bound); `None` for a
/// summary without the columns or a design without runs.
fn unsettled_risk(c: &SummaryColumns, i: usize) -> PolarsResult<Option<(u64, u64, f64)>> {
    let column = |name: &str| -> PolarsResult<Option<u64>> {
        Ok(match c.0.column(name) {
            Ok(col) => col.cast(&polars::prelude::DataType::UInt64)?.u64()?.get(i),
            Err(_) => None,
        })
    };
    let (Some(runs), Some(settled)) = (column("runs")?, column("settled")?) else {
        return Ok(None);
    };
    let lo = c.f_or_none("settled_fraction_lo")?[i];
    Ok(lo
        .filter(|_| runs > 0)
        .map(|lo| (runs - settled.min(runs), runs, 1.0 - lo)))
}

/// Per summary row: whether #1 is significantly better than it on the
/// criterion (`vs_best_verdict` = `best_better`).
fn beaten(c: &SummaryColumns) -> PolarsResult<Vec<bool>> {
    Ok(c.s("vs_best_verdict")?
        .iter()
        .map(|v| v.as_deref().and_then(StoredVerdict::parse) == Some(StoredVerdict::BestBetter))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use polars::prelude::df;

    /// A summary row with two planes' designs: plane 1 given `n1` balls of ρ `rho1`.
    fn two_planes(n1: u32, rho1: f64) -> DataFrame {
        df!(
            "kind_plane0" => ["ball"], "n_plane0" => [4u32], "rho_plane0" => [0.25],
            "drag_plane0" => [10.0], "race_radius_plane0" => [0.035],
            "weight_mass_plane0" => [0.02203],
            "kind_plane1" => ["ball"], "n_plane1" => [n1], "rho_plane1" => [rho1],
            "drag_plane1" => [10.0], "race_radius_plane1" => [0.035],
            "weight_mass_plane1" => [if rho1 == 0.25 { 0.02203 } else { 0.0113 }],
        )
        .unwrap()
    }

    /// The recommendation names every plane's part where the planes
    /// differ, says "in each of 2 planes" where they are the same, and
    /// falls back to the one design's part without per-plane columns.
    #[test]
    fn the_part_names_each_planes_weights() {
        let differ = plane_parts(&SummaryColumns(&two_planes(4, 0.2)), 0)
            .unwrap()
            .unwrap();
        assert_eq!(
            differ,
            "plane 0: 4 balls of 17.5 mm diameter, 22.03 g each, in a race of radius 35 mm, drag 10 N·s/m per weight; \
             plane 1: 4 balls of 14 mm diameter, 11.3 g each, in a race of radius 35 mm, drag 10 N·s/m per weight"
        );
        let same = plane_parts(&SummaryColumns(&two_planes(4, 0.25)), 0)
            .unwrap()
            .unwrap();
        assert!(same.ends_with("per weight, in each of 2 planes"), "{same}");
        assert!(!same.contains("plane 0"), "{same}");
        let none = df!("n" => [4u32]).unwrap();
        assert_eq!(plane_parts(&SummaryColumns(&none), 0).unwrap(), None);
    }
}
