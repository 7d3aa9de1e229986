//! The lines after the ranking of a study with uncertain keys: whether #1
//! stays #1 in each third of every key's range, and which key explains
//! most of #1's settling time.

use crate::UserError;
use crate::sensitivity_cmd::{Total, sampled_apart, shown};
use autobal::decide::decision::StudyDecision;
use autobal::decide::robustness::{PARTS, robustness};
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
    let keys = plan.file.uncertain.len();
    let mut out = format!(
        "uncertain physics: #1 (design {crown}) is also best in {} of the {} thirds of its {keys} uncertain key(s)' ranges (the runs whose drawn value lies in the lowest, middle or highest third, ranked on their own)",
        r.kept(),
        r.parts.len(),
    );
    let lost: Vec<String> = r
        .parts
        .iter()
        .filter(|p| p.winner != crown)
        .map(|p| {
            format!(
                "where {} is {} ({}–{}), design {} is best ({} against #1's {}, {} runs of #1)",
                p.key,
                ["low", "middle", "high"]
                    .get(p.part)
                    .copied()
                    .unwrap_or("in another part"),
                autobal::number_text::significant(p.range.0, 3),
                autobal::number_text::significant(p.range.1, 3),
                p.winner,
                value(p.winner_value),
                value(p.crown_value),
                p.runs
            )
        })
        .collect();
    if lost.is_empty() {
        out += ": the decision does not hang on them";
    } else {
        out += &format!("; {}", lost.join("; "));
    }
    out += ".";
    let mut findings = vec![out];
    match read_totals(plan, dir, crown, Measure::RestrictedSettling) {
        Some(totals) => findings.push(totals_sentence(&totals)),
        None => {
            if let Some(top) = r.explained.first() {
                findings.push(format!(
                    "of the uncertain keys, {} explains most of #1's settling time capped at the horizon: {:.0} % of its variance (first-order, from {} equal-count bins of the study's runs, less what noise alone puts between them); `study sensitivity` gives every input's total index.",
                    top.key,
                    100.0 * top.share,
                    autobal::decide::robustness::BINS
                ));
            }
        }
    }
    debug_assert_eq!(PARTS, 3, "the lines name three parts");
    Ok(findings)
}

/// A criterion value as printed.
fn value(v: Option<f64>) -> String {
    v.map_or("–".into(), |x| autobal::number_text::significant(x, 4))
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
