//! The sentences under the ranking, rendered from the library's typed
//! decision: the verdict on #1, where other measures disagree, and the
//! recommendation with its cautions, edges and Pareto set.

use super::*;
use crate::decide::decision::TestedCause;

/// "#r (design id)".
pub(super) fn who_id(decision: &StudyDecision, id: u32) -> String {
    format!("#{} (design {id})", decision.rank_of(id).unwrap_or(0))
}

/// The sentence under the ranking: whether #1 balances at all, and against
/// how many designs it is better on the criterion at α.
pub(super) fn verdict_line(decision: &StudyDecision) -> String {
    let criterion = decision.criterion;
    match &decision.crown {
        Crown::NoneBalances {
            best,
            settled_fraction,
            residual_median,
            cause,
            worse_than_none,
            dead_band_over_a_ref,
            dead_band_over_band,
            ..
        } => {
            let mut line = format!(
                "verdict: no design balances this rotor, so none is called best: even {} settles into the band in only {:.1} % of its runs (a working balancer settles in at least half) and leaves a median residual/A_ref of {} (above 1 is worse than no balancer){}; cause: {}",
                who_id(decision, *best),
                100.0 * settled_fraction,
                residual_median.map_or("– (no run was simulated to its end)".into(), |r| format!(
                    "{r:.2}"
                )),
                worse_than_none.map_or(String::new(), |w| format!(
                    "; {:.1} % of its runs end worse than with no balancer",
                    100.0 * w
                )),
                cause_text(decision, *best, cause.as_deref())
            );
            // A dead band beyond A_ref: no band a user would accept helps,
            // only less friction does, and by how much is a number.
            if let (Some(over_a_ref), Some(over_band)) = (dead_band_over_a_ref, dead_band_over_band)
            {
                line += &format!(
                    "; at this friction the weights never break away: the dead band of rolling resistance is {over_a_ref:.1}× the whirl with no balancer (A_ref), so no settling band narrower than no balancer at all can be met; a rolling resistance at least {over_band:.0}× lower would bring the dead band inside the band δ·A_ref"
                );
            }
            line + "\n"
        }
        Crown::Alone => String::new(),
        Crown::Best {
            best,
            better_than,
            not_distinguishable,
            other_better,
        } => {
            let names = |ids: &[u32]| -> Vec<String> {
                ids.iter().map(|&id| who_id(decision, id)).collect()
            };
            let mut line = format!(
                "verdict on the {}: {} is better than {} of the other {} designs ({}{}, Holm-adjusted at α = {}, {} runs per design{})",
                criterion.label(),
                who_id(decision, *best),
                better_than.len(),
                decision.ranked.len() - 1,
                criterion.test_name(decision.paired),
                if decision.paired {
                    " on runs paired by their shared samples"
                } else {
                    ": the designs did not share samples"
                },
                decision.alpha,
                decision.runs_per_design,
                if decision.ranked.iter().any(|d| d.left_race) {
                    "; fewer for the designs that left the race, each compared on the samples it ran"
                } else {
                    ""
                },
            );
            if !not_distinguishable.is_empty() {
                line += &format!(
                    "; not distinguishable from {}",
                    names(not_distinguishable).join(", ")
                );
            }
            if !other_better.is_empty() {
                line += &format!(
                    "; {} significantly better on its test although #1 has the better point estimate",
                    names(other_better).join(", ")
                );
            }
            line + "\n"
        }
    }
}

/// The tested cause when the experiment ran on design `id`.
fn tested_on(decision: &StudyDecision, id: u32) -> Option<&TestedCause> {
    decision.tested_cause.as_ref().filter(|t| t.design == id)
}

/// What introduces the floor checks beside a tested cause: they bound
/// what could stop a run, the re-runs say what does.
const FLOORS_SAY: &str = "the floor checks, which only bound what could stop a run, say: ";

/// The cause after "cause: ": the tested one (#1's runs re-run without
/// each effect) with the floor checks' diagnosis as context, else the
/// diagnosis alone.
fn cause_text(decision: &StudyDecision, best: u32, diagnosis: Option<&str>) -> String {
    match (tested_on(decision, best), diagnosis) {
        (Some(tested), Some(d)) => format!("{}; {FLOORS_SAY}{d}", tested.text),
        (Some(tested), None) => tested.text.clone(),
        (None, d) => d.unwrap_or("no cause found").to_string(),
    }
}

/// One sentence naming every design significantly better than #1 on a
/// reported measure other than the ranking criterion, with the numbers.
pub(super) fn disagreement_line(decision: &StudyDecision) -> String {
    if decision.ranked.len() < 2 {
        return String::new();
    }
    let mut claims: Vec<(u32, Vec<String>)> = Vec::new();
    for d in &decision.disagreements {
        // The median's Δ is the median of the paired differences, not the
        // difference of the two medians: say so.
        let delta = if d.measure == Criterion::Median {
            "median paired Δ"
        } else {
            "Δ"
        };
        let text = format!(
            "{} {} vs {} ({delta} {} [{}, {}], Holm p {})",
            short(d.measure),
            measure_text(d.measure, d.values.0),
            measure_text(d.measure, d.values.1),
            diff_text(d.measure, Some(d.difference)),
            diff_text(d.measure, d.interval.0),
            diff_text(d.measure, d.interval.1),
            p_text(Some(d.p_holm))
        );
        match claims.last_mut() {
            Some((id, texts)) if *id == d.design => texts.push(text),
            _ => claims.push((d.design, vec![text])),
        }
    }
    if claims.is_empty() {
        format!(
            "other measures: no design is significantly better than #1 on any of median, restricted mean, p90 and residual p95/A_ref (the residual relative to each run's A_ref, not in µm) (α = {})\n",
            decision.alpha
        )
    } else {
        format!(
            "other measures disagree: better than #1 are {}\n",
            claims
                .iter()
                .map(|(id, texts)| format!(
                    "{} on the {}",
                    who_id(decision, *id),
                    texts.join(" and the ")
                ))
                .collect::<Vec<_>>()
                .join("; ")
        )
    }
}

/// The one-line recommendation: #1 as a part to build, its cautions and
/// edges, and the Pareto set when it has more than one member; none when
/// no design balances.
pub(super) fn recommendation_line(decision: &StudyDecision) -> String {
    let Recommendation::Build {
        design,
        first,
        indistinguishable,
        tie_break,
        unsettled_risk,
        part,
        shortfalls,
        unsettled_floor,
        edges,
        pareto,
    } = &decision.recommendation
    else {
        return match decision.recommendation {
            Recommendation::NoneBalances => {
                "recommendation: none of these designs; remove the cause above first\n".into()
            }
            _ => String::new(),
        };
    };
    let mut line = if indistinguishable.len() > 1 {
        // The point estimates' order among designs that tie is noise: the
        // part is chosen from the set by the declared rule.
        format!(
            "recommendation: indistinguishable from #1 by the {} at α = {}: designs {}; part by {}: design {design}{}",
            decision.criterion.label(),
            decision.alpha,
            indistinguishable
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            tie_break.label(),
            if design == first {
                " (also #1)".to_string()
            } else {
                format!(" ({})", who_id(decision, *design))
            },
        )
    } else {
        format!(
            "recommendation: design {design} (#1 by the {})",
            decision.criterion.label()
        )
    };
    if let Some(part) = part {
        line += &format!(": {part}");
    }
    // A crown that falls short of a design that works says so, with the rule.
    let short: Vec<String> = shortfalls
        .iter()
        .map(|s| match s {
            Shortfall::SettlesTooRarely(f) => format!(
                "it settles in only {:.1} % of its runs (a design that works settles in at least {:.0} %)",
                100.0 * f,
                100.0 * WORKS_SETTLED_SHARE
            ),
            Shortfall::OftenWorseThanNone(f) => format!(
                "{:.1} % of its runs end vibrating more than with no balancer (at most {:.0} % for a design that works)",
                100.0 * f,
                100.0 * WORKS_WORSE_SHARE
            ),
        })
        .collect();
    if !short.is_empty() {
        line += &format!(", with a caution: {}", short.join("; "));
        // The cause of the shortfall: the tested one, with a floor that
        // could explain it as context.
        match (tested_on(decision, *design), unsettled_floor) {
            (Some(tested), floor) => {
                line += &format!(" ({}", tested.text);
                if let Some(floor) = floor {
                    line += &format!("; {FLOORS_SAY}{floor}");
                }
                line += ")";
            }
            (None, Some(floor)) => line += &format!(" ({floor})"),
            (None, None) => {}
        }
    }
    // A winner at the end of a swept axis: the best may lie beyond it.
    // The part's risk of not settling, with the bound a buyer can quote.
    if let Some((unsettled, runs, upper)) = unsettled_risk {
        line += &format!(
            "; it did not settle in {unsettled} of {runs} runs: risk of not settling at most {:.1} % (95 % Wilson upper bound)",
            100.0 * upper
        );
    }
    let sits = if design == first { "it" } else { "#1" };
    for e in edges {
        line += &format!(
            "; {sits} sits at the {} {} swept ({}): the best may lie beyond, so extend {} {} it",
            if e.high { "largest" } else { "smallest" },
            e.axis.key(),
            crate::number_text::significant(e.value, 4),
            e.axis.key(),
            if e.high { "above" } else { "below" },
        );
    }
    if pareto.len() > 1 {
        line += &format!(
            "; {} designs are not dominated on the study's Pareto measures: {}: if your requirement names another measure, choose among them by it",
            pareto.len(),
            pareto
                .iter()
                .map(|&id| who_id(decision, id))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    line + "\n"
}
