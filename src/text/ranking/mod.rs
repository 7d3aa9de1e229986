//! The ranking `study run`, `study merge` and `study report` print from
//! `summary.parquet`: the designs in the order of the declared criterion,
//! the verdict on it, where the other measures disagree, and the
//! recommendation (or why no design is recommended).

use crate::decide::decision::{Crown, Recommendation, StoredVerdict, StudyDecision};
use crate::decide::verdict::{Shortfall, WORKS_SETTLED_SHARE, WORKS_WORSE_SHARE};
use crate::study::plan::criterion::Criterion;
use crate::text::{Layout, dropped_note, fitted_table, p_value_text, text_table, wrap};
use polars::prelude::{DataFrame, PolarsResult};

mod findings;
mod notes;

use findings::{disagreement_line, recommendation_line, verdict_line};
use notes::{circulating_line, contact_line, dead_band_line, merged_line, passage_table};

/// The summary's columns by name (the library's reader).
use crate::study::results::summary_columns::SummaryColumns as Summary;

/// A parameter to four significant digits (`10`, `0.5`, not
/// `0.05000000000000001`), or "–".
fn plain(v: Option<f64>) -> String {
    v.map_or("–".to_string(), |x| crate::number_text::significant(x, 4))
}

/// A number with `digits` decimals, or "–".
fn num(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".to_string(), |x| format!("{x:.digits$}"))
}

/// A value of `criterion` as printed (shares in percent).
fn measure_text(criterion: Criterion, v: Option<f64>) -> String {
    match (criterion.unit(), v) {
        (_, None) => "beyond the run".to_string(),
        ("%", Some(x)) => format!("{:.1} %", 100.0 * x),
        ("rev", Some(x)) => format!("{x:.1} rev"),
        (_, Some(x)) => format!("{x:.4}"),
    }
}

/// A difference of `criterion` as printed.
fn diff_text(criterion: Criterion, v: Option<f64>) -> String {
    match (criterion.unit(), v) {
        (_, None) => "–".to_string(),
        ("%", Some(x)) => format!("{:+.1}", 100.0 * x),
        ("rev", Some(x)) => format!("{x:+.1}"),
        (_, Some(x)) => format!("{x:+.4}"),
    }
}

/// The kind, n, ρ and β cells of a study whose planes have designs of their
/// own (`kind_plane0`, … columns): each plane's value, joined by "/", or the
/// one value when every plane has it.
struct PlaneCells {
    /// Per plane: kinds, counts, ρ, β, one entry per summary row.
    planes: Vec<[Vec<String>; 4]>,
}

impl PlaneCells {
    /// `None` when the summary has no per-plane columns.
    fn read(summary: &DataFrame) -> PolarsResult<Option<PlaneCells>> {
        let mut planes = Vec::new();
        while summary.column(&format!("n_plane{}", planes.len())).is_ok() {
            let p = planes.len();
            let sum = Summary(summary);
            let kind = sum.s(&format!("kind_plane{p}"))?;
            let n: Vec<Option<u32>> = summary
                .column(&format!("n_plane{p}"))?
                .u32()?
                .iter()
                .collect();
            let (rho, drag) = (
                sum.f(&format!("rho_plane{p}"))?,
                sum.f(&format!("drag_plane{p}"))?,
            );
            planes.push([
                kind.into_iter().map(Option::unwrap_or_default).collect(),
                n.iter()
                    .map(|v| v.map_or("–".into(), |v| v.to_string()))
                    .collect(),
                rho.iter().map(|&v| num(v, 3)).collect(),
                drag.iter().map(|&v| plain(v)).collect(),
            ]);
        }
        Ok((!planes.is_empty()).then_some(PlaneCells { planes }))
    }

    /// The four cells of summary row i.
    fn row(&self, i: usize) -> [String; 4] {
        std::array::from_fn(|k| {
            let values: Vec<&String> = self.planes.iter().map(|p| &p[k][i]).collect();
            if values.iter().all(|v| *v == values[0]) {
                values[0].clone()
            } else {
                values
                    .iter()
                    .map(|v| v.as_str())
                    .collect::<Vec<_>>()
                    .join("/")
            }
        })
    }
}

/// The ranking, verdicts, disagreements and recommendation of a summary.
pub fn ranked_table(summary: &DataFrame, layout: Layout) -> PolarsResult<String> {
    let parts = ranking(summary, layout)?;
    let header: Vec<&str> = parts.header.iter().map(String::as_str).collect();
    let width = layout.width;
    let (table, dropped) = fitted_table(&header, &parts.rows, &parts.priority, width);
    let dropped_note = dropped_note(&dropped);
    Ok(table + &wrap(&(parts.legend + &dropped_note + &parts.findings), width) + &parts.passage)
}

/// The decision's sentences as `study run` prints them, unwrapped: the
/// verdict on #1, where the other measures disagree, and the
/// recommendation.
pub fn decision_text(decision: &StudyDecision) -> String {
    verdict_line(decision) + &disagreement_line(decision) + &recommendation_line(decision)
}

/// The ranking's pieces, for the terminal ([`ranked_table`]) and the report.
pub struct Ranking {
    /// Column headers ("\n" stacks a header on two lines).
    pub header: Vec<String>,
    /// One row per design, in rank order.
    pub rows: Vec<Vec<String>>,
    /// Which columns give way first on a narrow terminal (see `column_priority`).
    pub priority: Vec<u8>,
    /// What the columns mean, one note per line.
    pub legend: String,
    /// Verdict, disagreements, recommendation and the other findings, one per line.
    pub findings: String,
    /// The passage-through-resonance table of a stall-torque sweep (or empty).
    pub passage: String,
}

/// The ranking of a summary, in pieces.
pub fn ranking(summary: &DataFrame, layout: Layout) -> PolarsResult<Ranking> {
    let sum = Summary(summary);
    let decision = StudyDecision::from_summary(summary)?;
    let criterion = decision.criterion;
    let order: Vec<usize> = decision.ranked.iter().map(|d| d.row).collect();
    let cols = RankColumns::read(summary, criterion)?;
    let rows: Vec<Vec<String>> = order
        .iter()
        .enumerate()
        .map(|(r, &i)| cols.row(&decision, r, i))
        .collect();
    // A stall-torque sweep gets its own column after β (designs differ by
    // it alone); other studies print without it.
    let torque = sum.f_or_none("stall_torque")?;
    let swept = torque.iter().any(Option::is_some);
    let rows: Vec<Vec<String>> = if swept {
        rows.into_iter()
            .zip(&order)
            .map(|(mut row, &i)| {
                row.insert(6, num(torque[i], 3));
                row
            })
            .collect()
    } else {
        rows
    };
    let header = base_header(criterion, swept);
    // A run-up ranks on the clock from the operating speed; the median
    // from t = 0 (motor and balancer together) stands beside it.
    let run_up = sum
        .s("settling_from")?
        .iter()
        .flatten()
        .any(|f| f != "from t = 0");
    let (mut header, mut rows) = (header, rows);
    if run_up {
        let from_start = sum.f("settling_revs_median_km_from_start")?;
        let after = header.iter().position(|h| h.starts_with("median"));
        insert_column(
            &mut header,
            &mut rows,
            after.unwrap_or(0) + 1,
            "median\nfrom t = 0",
            |k| from_start[order[k]].map_or("beyond".into(), |m| format!("{m:.1}")),
        );
    }
    let raced = insert_runs_column(summary, &order, &mut header, &mut rows)?;
    let runs_note = if raced {
        "(runs: a design with fewer runs than the others left the race after that many samples, once #1 was significantly better and no other measure favoured it; its statistics, its flags (balances, the shortfalls) and its comparison with #1 rest on the runs it has, so the ranks below #1 are not those the full study would give; docs/statistics.md, \"Racing\")\n"
    } else {
        ""
    };
    let legend = legend_text(&sum, criterion, run_up, layout.wide)?;
    let seconds_note = cols.seconds_note(&order, criterion, run_up);
    let rho_note = rho_note(&sum, &cols)?;
    let plane_note = cols.planes.as_ref().map_or(String::new(), |p| {
        format!(
            "(kind, n, ρ, β: each balancer plane's, plane 0 to {} joined by “/”, one value where every plane has it; the planes' designs are columns kind_plane0 … of summary.parquet and runs.parquet)\n",
            p.planes.len() - 1
        )
    });
    let censoring_note = censoring_note(&sum, &order, &cols.ids)?;
    let any_failed = cols.failed.iter().any(|&f| f > 0);
    let priority: Vec<u8> = header
        .iter()
        .map(|h| column_priority(h, criterion, any_failed))
        .collect();
    let findings = verdict_line(&decision)
        + &disagreement_line(&decision)
        + &recommendation_line(&decision)
        + &merged_line(&sum, &order)?
        + &circulating_line(&sum, &order)?
        + &dead_band_line(&sum, &order)?
        + &contact_line(summary, layout.wide)?;
    Ok(Ranking {
        header,
        rows,
        priority,
        legend: legend
            + runs_note
            + &estimate_note(&sum)?
            + &seconds_note
            + &rho_note
            + &plane_note
            + &censoring_note,
        findings,
        passage: passage_table(summary)?,
    })
}

/// The summary columns the ranking's rows print, one entry per summary row,
/// read together (in the order they always were) before any row is built.
struct RankColumns {
    ids: Vec<u32>,
    kind: Vec<Option<String>>,
    n: Vec<Option<u32>>,
    rho: Vec<Option<f64>>,
    drag: Vec<Option<f64>>,
    frac: Vec<Option<f64>>,
    planes: Option<PlaneCells>,
    median: Vec<Option<f64>>,
    median_lo: Vec<Option<f64>>,
    median_hi: Vec<Option<f64>>,
    rmst: Vec<Option<f64>>,
    rmst_lo: Vec<Option<f64>>,
    rmst_hi: Vec<Option<f64>>,
    p90: Vec<Option<f64>>,
    res95: Vec<Option<f64>>,
    rank_value: Vec<Option<f64>>,
    /// Absent from older summaries.
    res_abs95: Vec<Option<f64>>,
    /// The operating speed's period (absent from older summaries).
    seconds_per_rev: Option<f64>,
    failed: Vec<u64>,
    p_holm: Vec<Option<f64>>,
    /// The criterion's difference from #1 with its interval (all empty when
    /// the summary does not report the criterion's difference).
    crit: [Vec<Option<f64>>; 3],
}

impl RankColumns {
    /// Reads the columns in the order the ranking always read them, so a
    /// damaged summary reports the same missing column.
    fn read(summary: &DataFrame, criterion: Criterion) -> PolarsResult<Self> {
        let sum = Summary(summary);
        Ok(Self {
            ids: summary
                .column("design_id")?
                .u32()?
                .iter()
                .map(Option::unwrap_or_default)
                .collect(),
            kind: sum.s("kind")?,
            n: summary.column("n")?.u32()?.iter().collect(),
            rho: sum.f("rho")?,
            drag: sum.f("drag")?,
            frac: sum.f("settled_fraction")?,
            planes: PlaneCells::read(summary)?,
            median: sum.f("settling_revs_median_km")?,
            median_lo: sum.f("settling_revs_median_km_lo")?,
            median_hi: sum.f("settling_revs_median_km_hi")?,
            rmst: sum.f("settling_revs_rmst")?,
            rmst_lo: sum.f("settling_revs_rmst_lo")?,
            rmst_hi: sum.f("settling_revs_rmst_hi")?,
            p90: sum.f("settling_revs_p90_all_runs")?,
            res95: sum.f("residual_rel_p95")?,
            rank_value: sum.f("rank_value")?,
            res_abs95: sum.f_or_none("residual_abs_p95")?,
            seconds_per_rev: sum
                .f_or_none("seconds_per_rev")?
                .into_iter()
                .flatten()
                .next(),
            failed: sum
                .u("solver_failed")?
                .iter()
                .zip(sum.u("budget_exceeded")?)
                .map(|(a, b)| a + b)
                .collect(),
            p_holm: sum.f("vs_best_p_holm")?,
            crit: criterion_differences(&sum, criterion, summary.height())?,
        })
    }

    /// Summary row `i` printed as rank `r` (before the optional stall-torque,
    /// run-up and runs columns are inserted).
    fn row(&self, decision: &StudyDecision, r: usize, i: usize) -> Vec<String> {
        let criterion = decision.criterion;
        let bound = |v: Option<f64>| v.map_or("∞".to_string(), |x| format!("{x:.1}"));
        let (versus, p_versus) = self.versus_cells(decision, r, i);
        let plane_cells = self.planes.as_ref().map(|p| p.row(i));
        let mut row = vec![(r + 1).to_string(), self.ids[i].to_string()];
        row.extend(plane_cells.unwrap_or_else(|| {
            [
                self.kind[i].clone().unwrap_or_default(),
                self.n[i].map_or("–".into(), |v| v.to_string()),
                num(self.rho[i], 3),
                plain(self.drag[i]),
            ]
        }));
        row.push(num(self.frac[i].map(|f| 100.0 * f), 1));
        // The ranking criterion's own column carries its interval.
        row.push(match (self.median[i], criterion) {
            (Some(m), Criterion::Median) => format!(
                "{m:.1} [{}, {}]",
                bound(self.median_lo[i]),
                bound(self.median_hi[i])
            ),
            (Some(m), _) => format!("{m:.1}"),
            (None, _) => "beyond".to_string(),
        });
        // With no run settled every run counts at the horizon τ: the
        // restricted mean is τ itself, a bound (the mean is at least
        // that), and its interval has no width to show.
        let none_settled = self.frac[i] == Some(0.0);
        row.push(match (criterion == Criterion::Mean, none_settled) {
            (_, true) => format!("≥ {}, none settled", num(self.rmst[i], 1)),
            (true, false) => format!(
                "{} [{}, {}]",
                num(self.rmst[i], 1),
                num(self.rmst_lo[i], 1),
                num(self.rmst_hi[i], 1)
            ),
            (false, false) => num(self.rmst[i], 1),
        });
        row.push(self.p90[i].map_or("beyond".into(), |x| format!("{x:.1}")));
        row.push(self.res_abs95[i].map_or("–".into(), |r| format!("{:.2}", r * 1e6)));
        row.push(num(self.res95[i], 4));
        if !Criterion::REPORTED.contains(&criterion) {
            row.push(measure_text(criterion, self.rank_value[i]));
        }
        row.push(self.failed[i].to_string());
        row.push(p_versus);
        row.push(versus);
        row
    }

    /// The "Δ vs #1" and "Holm p" cells of row `i` at rank `r`: #1 and a
    /// study's only design have nothing to be compared with.
    fn versus_cells(&self, decision: &StudyDecision, r: usize, i: usize) -> (String, String) {
        let criterion = decision.criterion;
        let [crit_diff, crit_lo, crit_hi] = &self.crit;
        match decision.ranked[r].verdict {
            Some(StoredVerdict::Best) => ("#1".to_string(), "–".to_string()),
            Some(StoredVerdict::NoDesignBalances) => ("#1 (does not balance)".into(), "–".into()),
            Some(StoredVerdict::OnlyDesign) | None => ("–".into(), "–".into()),
            Some(_) if crit_diff[i].is_some() => (
                format!(
                    "{} [{}, {}]",
                    diff_text(criterion, crit_diff[i]),
                    diff_text(criterion, crit_lo[i]),
                    diff_text(criterion, crit_hi[i]),
                ),
                p_text(self.p_holm[i]),
            ),
            Some(_) => ("–".into(), p_text(self.p_holm[i])),
        }
    }

    /// Revolutions of the operating speed are a clock: say what they are in
    /// seconds (under a run-up, seconds after the rotor reached that speed).
    fn seconds_note(&self, order: &[usize], criterion: Criterion, run_up: bool) -> String {
        match (self.seconds_per_rev, order.first()) {
            (Some(period), Some(&best)) => {
                let value = match criterion {
                    Criterion::Median => self.median[best],
                    _ => self.rmst[best],
                };
                let (speed, since) = if run_up {
                    ("at the operating speed", " after the rotor reached it")
                } else {
                    ("at the constant speed", "")
                };
                format!(
                    "({speed} one revolution takes {:.2} ms{})\n",
                    1e3 * period,
                    value.map_or(String::new(), |v| format!(
                        ": #1's {} {v:.1} rev is {:.3} s{since}",
                        if criterion == Criterion::Median {
                            "median"
                        } else {
                            "restricted mean"
                        },
                        v * period,
                    ))
                )
            }
            _ => String::new(),
        }
    }
}

/// The criterion's difference from #1 and its interval, read only when the
/// summary reports that criterion (else empty cells, one per row).
fn criterion_differences(
    sum: &Summary,
    criterion: Criterion,
    height: usize,
) -> PolarsResult<[Vec<Option<f64>>; 3]> {
    let crit_name = criterion.to_string();
    Ok(if Criterion::REPORTED.contains(&criterion) {
        [
            sum.f(&format!("vs_best_{crit_name}_diff"))?,
            sum.f(&format!("vs_best_{crit_name}_diff_lo"))?,
            sum.f(&format!("vs_best_{crit_name}_diff_hi"))?,
        ]
    } else {
        let none = vec![None; height];
        [none.clone(), none.clone(), none]
    })
}

/// The headers before the optional run-up and runs columns, which are
/// inserted later by name.
fn base_header(criterion: Criterion, swept: bool) -> Vec<String> {
    let mut header: Vec<String> = ["#", "id", "kind", "n", "ρ", "β\nN·s/m"]
        .map(String::from)
        .to_vec();
    if swept {
        header.push("M_s\nN·m".into());
    }
    header.push("settled\n%".into());
    // Settling times carry their unit in the header, not only in a footnote.
    header.push(if criterion == Criterion::Median {
        "median rev\n[95% CI]".into()
    } else {
        "median\nrev".into()
    });
    header.push(if criterion == Criterion::Mean {
        "mean rev\n[95% CI]".into()
    } else {
        "mean\nrev".into()
    });
    header.extend([
        "p90\nrev".into(),
        "residual\np95 µm".into(),
        "residual\np95/A_ref".into(),
    ]);
    if !Criterion::REPORTED.contains(&criterion) {
        header.push(criterion.to_string());
    }
    header.push("failed".into());
    header.push("Holm p\nvs #1".into());
    header.push("Δ vs #1 (paired)\n[95% CI]".into());
    header
}

/// A raced study: designs that left the race have fewer runs, and say so in
/// a runs column after "settled". True when the study was raced.
fn insert_runs_column(
    summary: &DataFrame,
    order: &[usize],
    header: &mut Vec<String>,
    rows: &mut [Vec<String>],
) -> PolarsResult<bool> {
    let runs: Vec<Option<u64>> = summary.column("runs")?.u64()?.iter().collect();
    let raced = runs.iter().flatten().min() != runs.iter().flatten().max();
    if raced {
        let after = header.iter().position(|h| h.starts_with("settled"));
        let at = after.map_or(header.len(), |p| p + 1);
        insert_column(header, rows, at, "runs", |k| {
            runs[order[k]].map_or("–".into(), |r| r.to_string())
        });
    }
    Ok(raced)
}

/// What the columns mean, with the clock the settling times were counted on
/// and the horizon the restricted mean stops at.
fn legend_text(
    sum: &Summary,
    criterion: Criterion,
    run_up: bool,
    wide: bool,
) -> PolarsResult<String> {
    let from = sum
        .s("settling_from")?
        .into_iter()
        .flatten()
        .next()
        .unwrap_or_else(|| "from t = 0".into());
    Ok(format!(
        "(ranked by the {}, designs that balance first; ρ = r/R, the weight's radius over the race's; settling times in revolutions counted {from}{}, over every run: a run that did not settle counts as censored (median: Kaplan–Meier; mean: the restricted mean, each run counted up to {}; p90: beyond the run when over 10 % did not settle); residual p95: 95th percentile of the RMS whirl over the last hold window, in µm and relative to A_ref (the whirl the same unbalance causes without a balancer); failed: runs that ended solver_failed or budget_exceeded, counted as not settled; Δ: this design minus #1, for the median the median of the paired differences)\n",
        criterion.label(),
        if run_up {
            " (but the column “median from t = 0”)"
        } else {
            ""
        },
        horizon_text(
            num(
                sum.f("settling_horizon_revs")?.first().copied().flatten(),
                0
            ),
            wide
        )
    ))
}

/// Which ρ came from a rule rather than a number: the value alone does
/// not say that 0.364 is the Table-1 optimum.
fn rho_note(sum: &Summary, cols: &RankColumns) -> PolarsResult<String> {
    let rules = sum.s_or_none("rho_rule")?;
    let mut rule_notes = Vec::new();
    for rule in ["optimal", "half_race"] {
        let mut with: Vec<(u32, Option<f64>)> = (0..sum.0.height())
            .filter(|&i| rules[i].as_deref() == Some(rule))
            .map(|i| (cols.ids[i], cols.rho[i]))
            .collect();
        if with.is_empty() {
            continue;
        }
        with.sort_by_key(|w| w.0);
        let mut values: Vec<String> = with.iter().map(|w| num(w.1, 3)).collect();
        values.dedup();
        rule_notes.push(format!(
            "ρ = \"{rule}\" is {} (ids {})",
            values.join(", "),
            with.iter()
                .map(|w| w.0.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    Ok(if rule_notes.is_empty() {
        String::new()
    } else {
        format!("({})\n", rule_notes.join("; "))
    })
}

/// The designs whose restricted mean is mostly runs that never settled,
/// each counted at the horizon τ (share (1 − settled) τ / mean over a half):
/// such a mean grows with the horizon, not with the design, and the reader
/// must know it (in rank order; empty when none).
fn censoring_note(sum: &Summary, order: &[usize], ids: &[u32]) -> PolarsResult<String> {
    let (frac, rmst) = (sum.f("settled_fraction")?, sum.f("settling_revs_rmst")?);
    let tau = sum.f("settling_horizon_revs")?;
    let mostly: Vec<String> = order
        .iter()
        .filter_map(|&i| {
            let (f, m, t) = (frac[i]?, rmst[i]?, tau[i]?);
            let share = (1.0 - f) * t / m;
            (f > 0.0 && m > 0.0 && share > 0.5).then(|| {
                format!(
                    "id {}: {:.0} % of its {m:.1} rev",
                    ids[i],
                    100.0 * share.min(1.0)
                )
            })
        })
        .collect();
    Ok(if mostly.is_empty() {
        String::new()
    } else {
        format!(
            "(restricted means that are mostly runs that never settled, each counted at the horizon τ, so that they grow with the horizon rather than with the design: {})\n",
            mostly.join(", ")
        )
    })
}

/// Insert a column `name` at `at`, row k (in rank order) holding `cell(k)`.
fn insert_column(
    header: &mut Vec<String>,
    rows: &mut [Vec<String>],
    at: usize,
    name: &str,
    cell: impl Fn(usize) -> String,
) {
    header.insert(at, name.into());
    for (k, row) in rows.iter_mut().enumerate() {
        row.insert(at, cell(k));
    }
}

/// How far the restricted mean counts a run: in words by default (the
/// verdict's test names τ), with the symbol and its formula under `--wide`.
fn horizon_text(revs: String, wide: bool) -> String {
    if wide {
        format!(
            "the horizon τ = {revs} rev, t_end − hold (less a ramp, counted from the operating speed)"
        )
    } else {
        format!("{revs} rev, the run's length less its hold window (τ)")
    }
}

/// Which columns give way first when the ranking is wider than the
/// terminal (higher goes first; 0 never): the design and the ranking
/// criterion stay, then failures (when there are any), the test against
/// #1, the residual, the other settling measures, and last the intervals
/// of the differences.
fn column_priority(header: &str, criterion: Criterion, any_failed: bool) -> u8 {
    match header {
        "#" | "id" => 0,
        "kind" | "n" | "ρ" => 1,
        h if h.starts_with("β\n") || h.starts_with("M_s\n") || h.starts_with("settled") => 1,
        "runs" => 2,
        h if h.contains("[95% CI]") && !h.starts_with('Δ') => 1,
        h if h == criterion.to_string() => 1,
        "failed" if any_failed => 2,
        "failed" => 8,
        h if h.starts_with("Holm p") => 3,
        h if h.starts_with("residual") && h.ends_with("µm") => 4,
        "p90\nrev" => 6,
        h if h.starts_with('Δ') => 7,
        _ => 5,
    }
}

/// An optional p-value as printed.
fn p_text(p: Option<f64>) -> String {
    p.map_or("–".to_string(), p_value_text)
}

/// Each summary row's design id.
fn design_ids(sum: &Summary) -> PolarsResult<Vec<u32>> {
    Ok(sum
        .0
        .column("design_id")?
        .u32()?
        .iter()
        .map(Option::unwrap_or_default)
        .collect())
}

/// Said first when the runs are estimates (the analytic or linear rung):
/// their settling times are predicted, not simulated, and they measure no
/// residual, so the ranking is a ranking of predictions.
fn estimate_note(sum: &Summary) -> PolarsResult<String> {
    // Absent from summaries written before the column existed.
    let estimated = sum
        .b("estimated")
        .map(|v| v.iter().any(|&e| e))
        .unwrap_or(false);
    Ok(if estimated {
        "(estimates, not measurements: every run is the fidelity rung's prediction (solver.fidelity = \"analytic\" or \"linear\"), so settling times are predicted, no residual is measured (shown –), and the ranking ranks predictions; `study tradeoff` measures how far they agree with simulation)\n".to_string()
    } else {
        String::new()
    })
}

/// A measure's short name in sentences.
fn short(m: Criterion) -> &'static str {
    match m {
        Criterion::Median => "median",
        Criterion::Mean => "restricted mean",
        Criterion::P90 => "p90",
        _ => "residual p95/A_ref",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polars::prelude::df;

    /// A mean that is mostly runs counted at τ is named with its share;
    /// one that is mostly settled runs, or has none settled (printed as a
    /// bound already), is not.
    #[test]
    fn a_mean_made_mostly_of_censored_runs_is_named() {
        // id 7: 10 % settled near 10 rev, 90 % counted at τ = 1450:
        // mean 0.1·10 + 0.9·1450 = 1306, of which 1305 (99.9 %) is τ.
        let summary = df!(
            "design_id" => [7u32, 8, 9],
            "settled_fraction" => [0.1, 0.99, 0.0],
            "settling_revs_rmst" => [1306.0, 80.0, 1450.0],
            "settling_horizon_revs" => [1450.0, 1450.0, 1450.0],
        )
        .unwrap();
        let note = censoring_note(&Summary(&summary), &[0, 1, 2], &[7, 8, 9]).unwrap_or_default();
        assert!(note.contains("id 7: 100 % of its 1306.0 rev"), "{note}");
        assert!(!note.contains("id 8") && !note.contains("id 9"), "{note}");
        let settled = df!(
            "design_id" => [8u32],
            "settled_fraction" => [0.99],
            "settling_revs_rmst" => [80.0],
            "settling_horizon_revs" => [1450.0],
        )
        .unwrap();
        assert_eq!(
            censoring_note(&Summary(&settled), &[0], &[8]).unwrap_or_default(),
            ""
        );
    }
}
