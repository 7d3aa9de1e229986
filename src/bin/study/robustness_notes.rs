//! The lines after the ranking of a study with uncertain keys: whether
//! another design is shown to be better than #1 within a third of some
//! key's range, and which key is shown to explain most of #1's settling
//! time. Every claim is a test's ([`autobal::decide::robustness`]); this
//! file only words it.

use crate::UserError;
use crate::sensitivity_cmd::{Total, sampled_apart, shown};
use autobal::decide::decision::StudyDecision;
use autobal::decide::robustness::{BINS, PARTS, PERMUTATIONS, Robustness, robustness};
use autobal::number_text::significant;
use autobal::study::plan::config::StudyPlan;
use autobal::study::results::io::read_parquet;
use autobal::study::sensitivity::{
    FILE as SENSITIVITY_FILE, InputKind, InputTotal, Measure, read_totals,
};
use polars::prelude::DataFrame;
use std::path::Path;

/// The robustness lines of the study in `dir`, wrapped to the terminal
/// (empty without uncertain keys).
pub fn robustness_lines(
    plan: &StudyPlan,
    dir: &Path,
    summary: &DataFrame,
) -> Result<String, UserError> {
    let text = robustness_findings(plan, dir, summary)?.join("\n");
    if text.is_empty() {
        return Ok(text);
    }
    Ok(crate::output::wrap(
        &(text + "\n"),
        crate::output::text_width(),
    ))
}

/// The robustness findings of the study in `dir`, one sentence each (the
/// report lists them with the verdicts).
pub fn robustness_findings(
    plan: &StudyPlan,
    dir: &Path,
    summary: &DataFrame,
) -> Result<Vec<String>, UserError> {
    if plan.file.uncertain.is_empty() {
        return Ok(Vec::new());
    }
    let internal = |e: polars::prelude::PolarsError| UserError::internal(e.to_string());
    let decision = StudyDecision::from_summary(summary).map_err(internal)?;
    let Some(&crown) = decision.leading(1).first() else {
        return Ok(Vec::new());
    };
    let runs = read_parquet(&dir.join("runs.parquet")).map_err(internal)?;
    let Some(r) = robustness(plan, &runs, crown).map_err(internal)? else {
        return Ok(Vec::new());
    };
    let mut findings = vec![thirds_sentence(&r, plan.file.uncertain.len())];
    let share = match read_totals(plan, dir, crown, Measure::RestrictedSettling) {
        Some(totals) => Some(totals_sentence(&totals)),
        None => share_sentence(&r),
    };
    findings.extend(share);
    debug_assert_eq!(PARTS, 3, "the lines name three parts");
    Ok(findings)
}

/// Where another design is shown to be better than #1, or that nowhere is.
fn thirds_sentence(r: &Robustness, keys: usize) -> String {
    let crown = r.crown;
    let label = r.criterion.label();
    let tests = r.third_tests();
    if tests == 0 {
        return format!(
            "uncertain physics: no third of {keys} uncertain key(s)' ranges holds runs of #1 (design {crown}) and of another design to test it against."
        );
    }
    let family = format!(
        "{tests} tests of #1 against every other design within the lowest, middle and highest third of each of {keys} uncertain key(s)' ranges, {}, Holm-adjusted at α = {}",
        if r.parts.iter().flat_map(|p| &p.tests).all(|t| t.paired) {
            "paired by sample"
        } else {
            "unpaired (the designs did not share their samples)"
        },
        r.alpha
    );
    let turns = r.turns();
    if turns.is_empty() {
        let nearest = match r.smallest_third_p() {
            Some(p) => format!(
                "smallest Holm-adjusted p of a design ahead of #1 {}",
                significant(p, 2)
            ),
            None => "#1 ahead in every one".to_string(),
        };
        return format!(
            "uncertain physics: no key's thirds differ: within no third of any uncertain key's range is another design better than #1 (design {crown}) on the {label} ({nearest}, of the {family}): the decision does not hang on them."
        );
    }
    let each: Vec<String> = turns
        .iter()
        .map(|(p, t)| {
            let (a, b) = t.difference.map_or((None, None), |d| (Some(d.a), Some(d.b)));
            format!(
                "where {} is {} ({}–{}), design {} is better than #1 (design {crown}): {} against #1's {} ({}, Holm p {}, {} runs of #1)",
                p.key,
                ["low", "middle", "high"]
                    .get(p.part)
                    .copied()
                    .unwrap_or("in another part"),
                significant(p.range.0, 3),
                significant(p.range.1, 3),
                t.design,
                value(r, b),
                value(r, a),
                r.criterion.test_name(t.paired),
                significant(t.p_holm, 2),
                p.runs
            )
        })
        .collect();
    format!(
        "uncertain physics, on the {label}: {} (of the {family}).",
        each.join("; ")
    )
}

/// The key shown to explain most of #1's settling time from the study's
/// own runs, or that none is; `None` when no key varied.
fn share_sentence(r: &Robustness) -> Option<String> {
    let smallest = r.smallest_share_p()?;
    let keys = r.explained.len();
    let how = format!(
        "permutation tests of the spread between {BINS} equal-count bins of each key, {PERMUTATIONS} reorderings each, Holm-adjusted over {keys} key(s) at α = {}",
        r.alpha
    );
    Some(match r.credited() {
        Some(top) => format!(
            "of the uncertain keys whose effect is distinguishable from noise, {} explains most of #1's settling time capped at the horizon: {:.0} % of its variance (first-order: the share between the bins less what noise alone puts there; {how}: Holm p {}); `study sensitivity` gives every input's total index.",
            top.key,
            100.0 * top.share,
            significant(top.p_holm, 2)
        ),
        None => format!(
            "no uncertain key explains a share of #1's settling time distinguishable from noise ({how}: smallest adjusted p {}); `study sensitivity` gives every input's total index.",
            significant(smallest, 2)
        ),
    })
}

/// The largest total index among the uncertain keys from
/// sensitivity.parquet, and the sampled inputs apart.
fn totals_sentence(totals: &[InputTotal]) -> String {
    let all: Vec<Total> = totals
        .iter()
        .map(|t| Total {
            input: &t.input,
            kind: t.kind,
            total: t.total,
            interval: t.interval,
        })
        .collect();
    let top = totals
        .iter()
        .filter(|t| t.kind == InputKind::MachineUnknown)
        .max_by(|a, b| a.total.total_cmp(&b.total));
    let mut out = match top {
        Some(t) => format!(
            "of the uncertain keys, {} has the largest total index on #1's settling time capped at the horizon: S_T = {} ({SENSITIVITY_FILE}; the share of its variance the key accounts for, interactions included{})",
            t.input,
            shown(t.total, t.interval),
            // As printed: an interval that shows 0.00 reaches 0.
            if t.interval.0 < 0.005 {
                "; its interval reaches 0: not distinguishable from no effect"
            } else {
                ""
            }
        ),
        None => format!("{SENSITIVITY_FILE} has no index for the uncertain keys"),
    };
    if let Some(rest) = sampled_apart(&all) {
        out += &format!("; {rest}");
    }
    out + "."
}

/// A criterion value as printed, in the criterion's unit.
fn value(r: &Robustness, v: Option<f64>) -> String {
    match (v, r.criterion.unit()) {
        (None, _) => "–".into(),
        (Some(x), "%") => format!("{} %", significant(100.0 * x, 3)),
        (Some(x), "") => significant(x, 4),
        (Some(x), unit) => format!("{} {unit}", significant(x, 4)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use autobal::decide::robustness::{Explained, PartTest, PartWinner};
    use autobal::stats::paired_measures::Difference;
    use autobal::study::plan::criterion::Criterion;

    /// #1 (design 0) against design `design` within the damping's top
    /// third: 56.7 rev against `theirs`, adjusted p `p_holm`.
    fn test(design: u32, theirs: f64, p_holm: f64, beats_crown: bool) -> PartTest {
        PartTest {
            design,
            difference: Some(Difference {
                a: 56.7,
                b: theirs,
                difference: 56.7 - theirs,
                interval: (56.7 - theirs - 3.0, 56.7 - theirs + 3.0),
                p_value: p_holm / 4.0,
                test: "paired_t",
                scale: 56.7,
            }),
            paired: true,
            p_holm,
            beats_crown,
        }
    }

    fn robust(tests: Vec<PartTest>, explained: Vec<Explained>) -> Robustness {
        Robustness {
            crown: 0,
            criterion: Criterion::Mean,
            alpha: 0.05,
            parts: vec![PartWinner {
                key: "rotor.bx".into(),
                part: 2,
                range: (210.0, 300.0),
                winner: 1,
                winner_value: Some(25.3),
                crown_value: Some(56.7),
                runs: 30,
                tests,
            }],
            explained,
        }
    }

    /// A third where a design beats #1 names it with both values, the test
    /// and its adjusted p; a design ahead without a rejecting test is not
    /// named, and the sentence then gives its p as the nearest.
    #[test]
    fn a_turn_is_named_only_where_its_test_rejects() {
        let found = thirds_sentence(
            &robust(
                vec![test(1, 25.3, 0.004, true), test(2, 60.0, 1.0, false)],
                vec![],
            ),
            1,
        );
        assert!(
            found.contains("where rotor.bx is high (210–300), design 1 is better than #1 (design 0): 25.3 rev against #1's 56.7 rev (paired t-test on min(t, τ), Holm p 0.004, 30 runs of #1)"),
            "{found}"
        );
        assert!(found.contains("of the 2 tests"), "{found}");
        let none = thirds_sentence(
            &robust(
                vec![test(1, 50.0, 0.43, false), test(2, 60.0, 0.01, false)],
                vec![],
            ),
            1,
        );
        assert!(
            none.contains("no key's thirds differ")
                && none.contains("smallest Holm-adjusted p of a design ahead of #1 0.43"),
            "{none}"
        );
        assert!(!none.contains("design 1 is better"), "{none}");
    }

    /// A key is credited only when its test rejects after Holm.
    #[test]
    fn a_share_is_credited_only_where_its_test_rejects() {
        let share = |p_holm: f64| Explained {
            key: "rotor.bx".into(),
            share: 0.4,
            p_value: p_holm / 2.0,
            p_holm,
        };
        let credited = share_sentence(&robust(vec![], vec![share(0.001)])).unwrap();
        assert!(
            credited.contains(
                "rotor.bx explains most of #1's settling time capped at the horizon: 40 %"
            ),
            "{credited}"
        );
        let none = share_sentence(&robust(vec![], vec![share(0.2)])).unwrap();
        assert!(
            none.starts_with(
                "no uncertain key explains a share of #1's settling time distinguishable from noise"
            ) && !none.contains("rotor.bx"),
            "{none}"
        );
        assert_eq!(share_sentence(&robust(vec![], vec![])), None);
    }
}
