//! The claims report (markdown), written from the experiment's numbers only.

use super::normalisation::Normalisation;
use super::{ClaimsOutput, DesignResult};
use crate::decide::verdict::{
    BestVersusRest, Comparison, DesignRuns, Favours, Verdict, best_versus_rest, compare, favoured,
    holm_across, measure_scale,
};
use crate::design::geometry::{rho_half_race, sector_angle};
use crate::design::optimum::optimal_rho;
use crate::model::balancer::Kind;
use crate::model::rotor::RotorModel;
use crate::stats::holm::holm_adjust;
use crate::study::plan::config::StudyPlan;
use crate::study::plan::criterion::Criterion;
use crate::study::results::measured_runs::Scale;
use std::fmt::Write;

fn f(v: Option<f64>, d: usize) -> String {
    v.map_or("–".into(), |x| format!("{x:.d$}"))
}

/// An interval whose ends may be unbounded within the run (∞).
fn ci(v: (Option<f64>, Option<f64>)) -> String {
    let end = |x: Option<f64>| x.map_or("∞".into(), |x| format!("{x:.1}"));
    format!("[{}, {}]", end(v.0), end(v.1))
}

/// A p-value as printed: "p = 0.0123" or "p < 0.0001".
fn p_text(p: f64) -> String {
    if p < 1e-4 {
        "p < 0.0001".into()
    } else {
        format!("p = {p:.4}")
    }
}

fn design_table(out: &mut String, rows: &[&DesignResult]) {
    out.push_str("| kind | n | ρ | capacity (kg·m) | weights (kg) | settled | median t_s (rev) [95% CI] | restricted mean | p90 |\n|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.4} | {:.3e} | {:.3} | {:.2} | {} {} | {} | {} |",
            r.kind,
            r.n,
            r.rho,
            r.capacity,
            r.total_mass,
            r.settled_fraction,
            f(r.median, 1),
            ci(r.median_ci),
            f(r.rmst, 1),
            f(r.p90, 1)
        );
    }
}

/// "A settles sooner than B in x % [lo, hi] of N paired runs, median d rev
/// sooner [lo, hi]", from a paired comparison with A first.
fn paired_effect(c: &Comparison, a: &str, b: &str) -> String {
    let Some(p) = &c.paired else {
        return format!("{a} and {b} could not be paired");
    };
    let rev = |x: f64| {
        if x.is_finite() {
            format!("{x:.1}")
        } else {
            "∞".into()
        }
    };
    format!(
        "{a} settle sooner than {b} in {:.0} % [{:.0}, {:.0}] of {} paired runs ({b} sooner in {:.0} %, ties {:.0} %), median {} rev sooner [{}, {}]",
        100.0 * p.a_sooner_share,
        100.0 * p.a_sooner_share_interval.0,
        100.0 * p.a_sooner_share_interval.1,
        p.n,
        100.0 * p.b_sooner as f64 / p.n as f64,
        100.0 * p.ties as f64 / p.n as f64,
        rev(p.median_difference),
        rev(p.median_difference_interval.0),
        rev(p.median_difference_interval.1),
    )
}

/// The results of one normalisation.
fn of_normalisation(results: &[DesignResult], norm: Normalisation) -> Vec<&DesignResult> {
    results.iter().filter(|r| r.normalisation == norm).collect()
}

/// Holm-adjusted p-values per measure over the comparisons of one family
/// (one claim): `result[i][k]` for comparison i and measure k.
fn holm_per_measure(comparisons: &[&Comparison]) -> Vec<Vec<f64>> {
    let measures = comparisons.first().map_or(0, |c| c.measures.len());
    let mut out = vec![vec![1.0; measures]; comparisons.len()];
    for k in 0..measures {
        let raw: Vec<f64> = comparisons
            .iter()
            .map(|c| c.measures[k].difference.map_or(1.0, |d| d.p_value))
            .collect();
        for (i, p) in holm_adjust(&raw).into_iter().enumerate() {
            out[i][k] = p;
        }
    }
    out
}

/// Every measure of a comparison, A then B, with A − B, its test and the
/// Holm-adjusted p-value in `holm` (same order as the measures).
fn measure_list(c: &Comparison, holm: &[f64], family: &str) -> String {
    let parts: Vec<String> = c
        .measures
        .iter()
        .zip(holm)
        .map(|(m, p)| match m.difference {
            Some(d) => {
                let (scale, digits) = match m.criterion.unit() {
                    "%" => (100.0, 1),
                    "rev" => (1.0, 1),
                    _ => (1.0, 4),
                };
                let x = |v: f64| {
                    if v.is_finite() {
                        format!("{:.digits$}", scale * v)
                    } else {
                        "∞".into()
                    }
                };
                let unit = match m.criterion.unit() {
                    "" => String::new(),
                    u => format!(" {u}"),
                };
                format!(
                    "{} {} vs {}{unit} ({}, {})",
                    m.criterion.label(),
                    x(d.a),
                    x(d.b),
                    d.test,
                    p_text(*p)
                )
            }
            None => format!("{}: no comparison", m.criterion.label()),
        })
        .collect();
    format!("{} [{family}]", parts.join("; "))
}

/// " But B is significantly better on …": the measures on which the
/// comparison goes the other way from the ranking criterion's point
/// estimate (empty when none does).
fn disagreement(c: &Comparison, holm: &[f64], alpha: f64, a: &str, b: &str) -> String {
    let Some(first) = c.measures.first().and_then(|m| m.difference) else {
        return String::new();
    };
    let a_ahead = c.measures[0].criterion.a_better(first.difference);
    let against: Vec<String> = c
        .measures
        .iter()
        .zip(holm)
        .skip(1)
        .filter(|(m, p)| {
            let behind = if a_ahead { Favours::B } else { Favours::A };
            m.difference
                .is_some_and(|d| favoured(m.criterion, &d, **p, alpha) == Some(behind))
        })
        .map(|(m, p)| format!("the {} (Holm-adjusted {})", m.criterion.label(), p_text(*p)))
        .collect();
    if against.is_empty() {
        return String::new();
    }
    let (ahead, behind) = if a_ahead { (b, a) } else { (a, b) };
    format!(
        " The measures disagree: {ahead} are significantly better than {behind} on {}.",
        against.join(" and ")
    )
}

/// One line describing the rotor of the study.
fn rotor_description(rotor: &RotorModel) -> String {
    match rotor.as_rotor().isotropic_plane() {
        Ok(r) => format!(
            "{}, M = {} kg, k = {:.3e} N/m, b = {} N·s/m",
            rotor.name(),
            r.mass,
            r.stiffness,
            r.damping
        ),
        Err(_) => rotor.name().to_string(),
    }
}

/// The markdown report of a claims run.
pub fn render(plan: &StudyPlan, out: &ClaimsOutput, command: &str) -> String {
    let mut s = String::new();
    let scale = measure_scale(plan);
    write_preamble(&mut s, plan, command);
    write_claim_capacity(&mut s, out);
    write_claim_shift(&mut s, plan, out, &scale);
    write_claim_fastest(&mut s, plan, out, &scale);
    s.push_str(NOTES);
    s
}

/// The title and the setup every claim shares, so a reader can rerun it.
fn write_preamble(s: &mut String, plan: &StudyPlan, command: &str) {
    let g = &plan.file.designs;
    let _ = writeln!(
        s,
        "# Seed 000's design claims, put to a virtual experiment\n"
    );
    let _ = writeln!(
        s,
        "Generated by `{command}` (study `{}`, seed {}, {} samples per design, autobal {}). \
         Rotor: {}; race R = {} m, density {} kg/m³, roller height {} m, drag β = {} N·s/m per weight; \
         weights of finite size (the contact effect) unless stated. Settling: r ≤ {} A_ref held {} revolutions (docs/metrics.md).\n",
        plan.name,
        plan.file.seed,
        plan.file.sampling.samples,
        env!("CARGO_PKG_VERSION"),
        rotor_description(&plan.file.scene.rotor),
        g.race_radius,
        g.density,
        g.roller_height,
        g.drag.values()[0],
        plan.file.metrics.delta,
        plan.file.metrics.hold_revs,
    );
}

/// Claim 1: the capacity table, then its verdict and the sectors the
/// optimum fills.
fn write_claim_capacity(s: &mut String, out: &ClaimsOutput) {
    let _ = writeln!(s, "## Claim 1: capacity is maximal near half-race fill\n");
    s.push_str("Each point: one run with an unbalance of 1.5 n m l, which the weights cannot cancel; they press together opposite it and their total unbalance at the end is the capacity they can deliver.\n\n");
    s.push_str("| kind | n | Table-1 ρ | sector at Table-1 ρ | ρ of largest simulated capacity | largest |simulated − eq 5| over ρ, % of peak | capacity at half-race / at optimum |\n|---|---|---|---|---|---|---|\n");
    let (all_match, sectors) = capacity_rows(s, out);
    let span = |k: Kind| {
        let v: Vec<f64> = sectors
            .iter()
            .filter(|(kk, _)| *kk == k)
            .map(|(_, a)| *a)
            .collect();
        let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        format!("{lo:.0}–{hi:.0}°")
    };
    let _ = writeln!(
        s,
        "\n**Verdict.** {} The optimum does not fill exactly half the race: at the Table-1 radius balls fill {}, rollers {}; the last column gives the capacity lost by filling exactly half.\n",
        if all_match {
            "Confirmed: for every n the simulated capacity (finite-size weights pressed by the rotor's own dynamics) peaks at the Table-1 radius among the radii scanned, and it equals eq 5 to the accuracy shown."
        } else {
            "Not everywhere: for some n the simulated capacity peaks at another scanned radius than Table 1 (see the table)."
        },
        span(Kind::Ball),
        span(Kind::Roller)
    );
}

/// Claim 1's table rows, one per kind and n; returns whether every n peaks
/// at the Table-1 radius and the sector each optimum fills, for the verdict.
fn capacity_rows(s: &mut String, out: &ClaimsOutput) -> (bool, Vec<(Kind, f64)>) {
    let mut all_match = true;
    let mut sectors: Vec<(Kind, f64)> = Vec::new();
    for kind in [Kind::Ball, Kind::Roller] {
        let mut ns: Vec<u32> = out
            .capacity
            .iter()
            .filter(|p| p.kind == kind)
            .map(|p| p.n)
            .collect();
        ns.dedup();
        for n in ns {
            let pts: Vec<_> = out
                .capacity
                .iter()
                .filter(|p| p.kind == kind && p.n == n)
                .collect();
            let best = pts
                .iter()
                .max_by(|a, b| a.simulated.total_cmp(&b.simulated))
                .expect("points");
            let peak = pts.iter().map(|p| p.analytic).fold(0.0, f64::max);
            let worst = pts
                .iter()
                .map(|p| (p.simulated - p.analytic).abs() / peak)
                .fold(0.0, f64::max);
            let shape = kind.model().shape();
            let opt = optimal_rho(shape, n).map(|o| o.rho).unwrap_or(f64::NAN);
            let half = rho_half_race(n).unwrap_or(f64::NAN);
            let at = |rho: f64| {
                pts.iter()
                    .find(|p| (p.rho - rho).abs() < 1e-12)
                    .map(|p| p.analytic)
            };
            let ratio = at(half).zip(at(opt)).map(|(h, o)| h / o);
            // The scan's grid can hold a point within a hair of the optimum;
            // count a match when the optimum's simulated capacity is within
            // 0.5 % of the largest one.
            let at_opt = pts
                .iter()
                .find(|p| (p.rho - opt).abs() < 1e-12)
                .map_or(0.0, |p| p.simulated);
            all_match &= at_opt >= 0.995 * best.simulated;
            let sector = sector_angle(n, opt)
                .map(f64::to_degrees)
                .unwrap_or(f64::NAN);
            sectors.push((kind, sector));
            let _ = writeln!(
                s,
                "| {kind} | {n} | {opt:.4} | {:.0}° | {:.4} | {:.3} % | {} |",
                sector,
                best.rho,
                100.0 * worst,
                f(ratio, 4)
            );
        }
    }
    (all_match, sectors)
}

/// Claim 2: three weights against two after a 90° shift, one section per
/// normalisation, Holm-adjusted over the normalisations.
fn write_claim_shift(s: &mut String, plan: &StudyPlan, out: &ClaimsOutput, scale: &Scale) {
    let alpha = plan.file.statistics.alpha;
    let _ = writeln!(
        s,
        "## Claim 2: three or more weights re-balance much faster than two after a 90° shift\n"
    );
    s.push_str("Start: the weights at the position that balanced an unbalance of the same magnitude turned by 90°, the rotor in the locked steady state of the new unbalance (so that settling measures the weights, not the support's start-up transient). Verdicts compare three with two weights on runs that met the same unbalance, on the study's ranking criterion (`[summary] rank_by`, `--rank-by`) with its paired test at α, Holm-adjusted over the normalisations (they answer one claim); \"confirmed\" also needs three weights to settle sooner in at least 75 % of the pairs. Each verdict lists every measure, and says where the median and the tail disagree.\n\n");
    let criterion = plan.file.summary.rank_by;
    let mut measures = vec![criterion];
    measures.extend(Criterion::REPORTED.iter().filter(|&&c| c != criterion));
    // Every normalisation answers the same claim: one Holm family over them.
    let mut shift_cases = Vec::new();
    for norm in Normalisation::ALL {
        let rows = of_normalisation(&out.shift, norm);
        let two = rows.iter().find(|r| r.n == 2);
        let three = rows.iter().find(|r| r.n == 3);
        let c = two.zip(three).map(|(two, three)| {
            compare(
                &three.runs_by_sample,
                &two.runs_by_sample,
                true,
                &measures,
                scale,
                three.seed,
            )
        });
        shift_cases.push((norm, rows, c));
    }
    let shift_holm = holm_per_measure(
        &shift_cases
            .iter()
            .filter_map(|(_, _, c)| c.as_ref())
            .collect::<Vec<_>>(),
    );
    let mut shift_holm = shift_holm.into_iter();
    let tested = shift_cases.iter().filter(|(_, _, c)| c.is_some()).count();
    for (norm, rows, c) in &shift_cases {
        if rows.is_empty() {
            continue;
        }
        let _ = writeln!(s, "### {} — {}\n", norm.name(), norm.describe());
        design_table(s, rows);
        if let Some(c) = c {
            let holm = shift_holm.next().unwrap_or_default();
            let verdict = shift_verdict(c, &holm, criterion, alpha);
            let _ = writeln!(
                s,
                "\n{}. {}. {verdict}{}\n",
                paired_effect(c, "three weights", "two"),
                measure_list(
                    c,
                    &holm,
                    &format!("Holm over the {tested} normalisations answering claim 2")
                ),
                disagreement(c, &holm, alpha, "three weights", "two")
            );
        }
    }
}

/// Claim 2's verdict under one normalisation: the criterion's Holm p-value
/// decides, and "confirmed" also needs the 75 % share of pairs.
fn shift_verdict(c: &Comparison, holm: &[f64], criterion: Criterion, alpha: f64) -> String {
    let p = holm.first().copied().unwrap_or(1.0);
    let on = c.measures.first().and_then(|m| m.difference);
    let better = on.is_some_and(|d| criterion.a_better(d.difference));
    let clear = p <= alpha && on.is_some_and(|d| d.difference != 0.0);
    let share = c.paired.as_ref().map_or(0.5, |x| x.a_sooner_share);
    match (clear, better) {
        (true, true) if share >= 0.75 => format!(
            "Confirmed on the {} under this normalisation, and three weights settle sooner in at least 75 % of the pairs.",
            criterion.label()
        ),
        (true, true) => format!(
            "Three are faster on the {}, but settle sooner in fewer than 75 % of the pairs: not by the wide margin the paper suggests.",
            criterion.label()
        ),
        (true, false) => format!(
            "Contradicted on the {}: two weights are faster here.",
            criterion.label()
        ),
        (false, _) => format!(
            "Not distinguishable on the {} at this sample size.",
            criterion.label()
        ),
    }
}

/// One kind under one normalisation in claim 3: the normalisation, the kind,
/// the paper's fastest count, that kind's designs, and the fastest design
/// against the rest.
type FastestCase<'a> = (
    Normalisation,
    Kind,
    u32,
    Vec<&'a DesignResult>,
    BestVersusRest,
);

/// Claim 3: the fastest count of each kind, one section per normalisation,
/// Holm-adjusted over every kind and normalisation together.
fn write_claim_fastest(s: &mut String, plan: &StudyPlan, out: &ClaimsOutput, scale: &Scale) {
    let alpha = plan.file.statistics.alpha;
    let criterion = plan.file.summary.rank_by;
    let _ = writeln!(
        s,
        "## Claim 3: the shortest transients come with 3 balls or 5 rollers\n"
    );
    s.push_str("Start: the locked steady state with the weights pressed together at a random angle; unbalances as in [sampling].\n\n");
    // Every normalisation and kind answers claim 3: one Holm family over all.
    let mut cases: Vec<FastestCase> = Vec::new();
    for norm in Normalisation::ALL {
        let rows = of_normalisation(&out.fastest, norm);
        for (kind, paper_n) in [(Kind::Ball, 3), (Kind::Roller, 5)] {
            let of_kind: Vec<&DesignResult> =
                rows.iter().copied().filter(|r| r.kind == kind).collect();
            let runs: Vec<DesignRuns> = of_kind.iter().map(|r| r.runs_by_sample.clone()).collect();
            let seed = of_kind.first().map_or(0, |r| r.seed);
            if let Some(v) = best_versus_rest(&runs, criterion, scale, alpha, true, seed) {
                cases.push((norm, kind, paper_n, of_kind, v));
            }
        }
    }
    let mut families: Vec<_> = cases.iter().map(|c| c.4.clone()).collect();
    holm_across(&mut families);
    let comparisons: usize = families.iter().map(|f| f.others.len()).sum();
    let family = format!(
        "α = {alpha}, Holm-adjusted over all {comparisons} comparisons of the fastest design with the others, every kind and normalisation together (they answer one claim)"
    );
    for norm in Normalisation::ALL {
        let rows = of_normalisation(&out.fastest, norm);
        if rows.is_empty() {
            continue;
        }
        let _ = writeln!(s, "### {} — {}\n", norm.name(), norm.describe());
        design_table(s, &rows);
        s.push('\n');
        for ((_, kind, paper_n, of_kind, _), v) in cases
            .iter()
            .zip(&families)
            .filter(|((n, ..), _)| *n == norm)
        {
            let per_design = of_kind
                .iter()
                .map(|r| r.runs_by_sample.settling.len())
                .max()
                .unwrap_or(0);
            let verdict = FastestKind {
                kind: *kind,
                paper_n: *paper_n,
                of_kind,
                v,
                family: format!("{family}; n = {per_design} runs per design"),
                criterion,
                alpha,
            }
            .verdict();
            let _ = writeln!(s, "- {verdict}");
        }
        s.push('\n');
    }
}

/// A comparison's own Holm-adjusted p-values, measure by measure.
fn own_holm(c: &Comparison) -> Vec<f64> {
    c.measures.iter().map(|m| m.p_holm).collect()
}

/// One kind under one normalisation in claim 3, holding what its verdict
/// sentence needs so the two ways it can go share one borrowed state.
struct FastestKind<'a> {
    kind: Kind,
    /// The count the paper calls fastest.
    paper_n: u32,
    /// That kind's designs under this normalisation.
    of_kind: &'a [&'a DesignResult],
    /// The fastest design against the rest, Holm-adjusted over the claim.
    v: &'a BestVersusRest,
    /// The claim's Holm family, with this kind's runs per design.
    family: String,
    criterion: Criterion,
    alpha: f64,
}

impl FastestKind<'_> {
    /// The number of weights of design `id` among this kind's designs (0
    /// when it is not among them).
    fn n_of(&self, id: u32) -> u32 {
        self.of_kind
            .iter()
            .find(|r| r.runs_by_sample.design_id == id)
            .map_or(0, |r| r.n)
    }

    /// Claim 3's verdict: whether the paper's count ranks first, and how
    /// firmly.
    fn verdict(&self) -> String {
        let best_n = self.n_of(self.v.best);
        if best_n == self.paper_n {
            self.paper_count_first()
        } else {
            self.other_count_first(best_n)
        }
    }

    /// The paper's count ranks first: confirmed if it beats every other
    /// count, partly if some cannot be told apart, with every disagreement.
    fn paper_count_first(&self) -> String {
        let (kind, paper_n, family) = (self.kind, self.paper_n, &self.family);
        let label = self.criterion.label();
        let beaten = self
            .v
            .others
            .iter()
            .filter(|(_, _, x)| *x == Verdict::BestBetter)
            .count();
        let unclear: Vec<String> = self
            .v
            .others
            .iter()
            .filter(|(_, _, x)| *x != Verdict::BestBetter)
            .map(|(c, p, _)| {
                format!(
                    "{} {kind}s ({}; Holm-adjusted {})",
                    self.n_of(c.b),
                    measure_list(c, &own_holm(c), "Holm over the claim"),
                    p_text(*p)
                )
            })
            .collect();
        let tails: Vec<String> = self
            .v
            .others
            .iter()
            .map(|(c, _, _)| {
                disagreement(
                    c,
                    &own_holm(c),
                    self.alpha,
                    &format!("{paper_n} {kind}s"),
                    &format!("{} {kind}s", self.n_of(c.b)),
                )
            })
            .filter(|t| !t.is_empty())
            .collect();
        if unclear.is_empty() {
            format!(
                "Confirmed on the {label}: {paper_n} {kind}s rank first and are better than each of the other {beaten} counts ({family}).{}",
                tails.concat()
            )
        } else {
            format!(
                "Partly confirmed on the {label}: {paper_n} {kind}s rank first, but cannot be told apart from {} ({family}).{}",
                unclear.join("; "),
                tails.concat()
            )
        }
    }

    /// Another count ranks first: how it stands against the paper's count
    /// (contradicted, not distinguishable, or mixed), or that the paper's
    /// count was not simulated.
    fn other_count_first(&self, best_n: u32) -> String {
        let (kind, paper_n, family) = (self.kind, self.paper_n, &self.family);
        let label = self.criterion.label();
        match self
            .v
            .others
            .iter()
            .find(|(c, _, _)| self.n_of(c.b) == paper_n)
        {
            Some((c, p, x)) => {
                let effect = measure_list(c, &own_holm(c), "Holm over the claim");
                let tail = disagreement(
                    c,
                    &own_holm(c),
                    self.alpha,
                    &format!("{best_n} {kind}s"),
                    &format!("{paper_n} {kind}s"),
                );
                match x {
                    Verdict::BestBetter => format!(
                        "Contradicted on the {label}: {best_n} {kind}s rank first and are better than {paper_n} ({effect}; Holm-adjusted {}; {family}).{tail}",
                        p_text(*p)
                    ),
                    Verdict::NotDistinguishable => format!(
                        "Not distinguishable on the {label}: {best_n} {kind}s rank first, but not significantly ahead of {paper_n} ({effect}; Holm-adjusted {}; {family}).{tail}",
                        p_text(*p)
                    ),
                    Verdict::OtherBetter => format!(
                        "Mixed on the {label}: {best_n} {kind}s have the better point estimate, yet {paper_n} {kind}s are significantly better on its paired test ({effect}; Holm-adjusted {}; {family}).{tail}",
                        p_text(*p)
                    ),
                }
            }
            None => {
                format!("{best_n} {kind}s rank first on the {label}; {paper_n} was not simulated.")
            }
        }
    }
}

/// The closing notes: how the simulation's ranking differs from the
/// paper's measure, and where the numbers come from.
const NOTES: &str = "## Notes\n\n- The paper's measure ã (eqs 15/16) ranks designs at p = p_max, the slowest balanced configuration; the simulation ranks by the study's criterion (`[summary] rank_by`; by default the restricted mean settling time, which counts the slow tail) over the sampled unbalances (every run counts, unsettled ones as censored) and compares designs on paired runs, so a design can rank differently. Each verdict names the measure it rests on and lists the others (median, restricted mean, p90, residual p95), and says so where they disagree.\n- Every number above comes from the runs under `results/` of the command at the top; rerunning it rewrites this file.\n";
