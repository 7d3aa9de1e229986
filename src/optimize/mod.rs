//! `study optimize`: choose weight counts, radii (and drag) for an objective,
//! analytic (milliseconds) or simulated (Monte Carlo with common random
//! numbers and standard errors).
//!
//! Problem / solver / executor as in argmin: [`evaluate`] says what a
//! candidate is worth, [`search`] runs argmin's solvers over the continuous
//! variables, and [`optimize`] enumerates the integer n and kinds and writes
//! the results.

pub mod confirm;
pub mod cross_check;
pub mod evaluate;
pub mod noisy_simplex;
pub mod pick;
pub mod search;
/// The `[optimize]` table is part of the study file, so it lives with the
/// study schema; named here as well, where it is used.
pub use crate::study::plan::optimize_spec as spec;

use crate::design::complete::{best_per_n_optimum, complete_optimization};
use crate::study::plan::config::StudyPlan;
use crate::study::results::io::{Provenance, write_parquet};
use evaluate::{Evaluation, Evaluator};
use polars::prelude::*;
use rayon::prelude::*;
use spec::{Objective, OptimizeSpec};
use std::path::PathBuf;

/// The best evaluation of one scope (a kind and n, a kind, or overall).
#[derive(Debug, Clone)]
pub struct Best {
    /// "kind_n", "overall" or "complete" (the paper's complete optimisation).
    pub scope: String,
    /// The evaluation.
    pub evaluation: Evaluation,
}

/// Everything an optimisation produced.
#[derive(Debug)]
pub struct OptimizeOutput {
    /// Every evaluated candidate, in (kind, n, evaluation) order.
    pub evaluations: Vec<Evaluation>,
    /// Per (kind, n) (and plane 1's, with a design per plane): its label
    /// ("ball n = 3"), its scope ("ball_3") and why its search stopped.
    pub terminations: Vec<(String, String, String)>,
    /// Best per (kind, n), then overall, then (capacity objective) the complete optimisation per kind.
    pub best: Vec<Best>,
    /// Folder of the files.
    pub dir: PathBuf,
    /// The optima confirmed on fresh samples (simulated objectives).
    pub confirmation: Option<confirm::Confirmation>,
    /// Whether the overall pick is final: its own search converged.
    pub pick: pick::PickStatus,
}

/// Why an optimisation cannot run.
#[derive(Debug, thiserror::Error)]
pub enum OptimizeError {
    /// The study file has no `[optimize]` table.
    #[error("{0}: no [optimize] table (see docs/optimize.md)")]
    NoSpec(String),
    /// A setting is out of its domain.
    #[error("optimize.{key} = {value}: {reason}")]
    Invalid {
        /// Key.
        key: String,
        /// Value.
        value: String,
        /// Reason.
        reason: String,
    },
    /// Writing the results failed.
    #[error("{0}")]
    Output(String),
}

/// The plan's `[optimize]` table, checked: refused (naming the key) before
/// anything runs or is written.
pub fn checked_spec(plan: &StudyPlan) -> Result<OptimizeSpec, OptimizeError> {
    let spec = plan
        .file
        .optimize
        .clone()
        .ok_or_else(|| OptimizeError::NoSpec(plan.name.clone()))?;
    validate(&spec, plan)?;
    Ok(spec)
}

/// The `[optimize]` table's values, each against its own rule and the
/// study's; the first problem found, naming its key.
fn validate(spec: &OptimizeSpec, plan: &StudyPlan) -> Result<(), OptimizeError> {
    validate_bounds(spec)?;
    validate_objective(spec)?;
    validate_budget(spec, plan)
}

/// An `[optimize]` key's refusal.
fn bad(key: &str, value: String, reason: &str) -> OptimizeError {
    OptimizeError::Invalid {
        key: key.into(),
        value,
        reason: reason.into(),
    }
}

/// What is free, within which bounds, and the capacity constraint.
fn validate_bounds(spec: &OptimizeSpec) -> Result<(), OptimizeError> {
    if spec.free.is_empty() || !spec.free.contains(&spec::Variable::Rho) {
        return Err(bad(
            "free",
            format!("{:?}", spec.free),
            "must contain \"rho\" (and optionally \"drag\")",
        ));
    }
    if let Some(crate::pair::Pair([lo, hi])) = spec.rho_bounds
        && !(lo > 0.0 && hi > lo && hi < 1.0)
    {
        return Err(bad(
            "rho_bounds",
            format!("[{lo}, {hi}]"),
            "need 0 < lo < hi < 1",
        ));
    }
    if let Some(crate::pair::Pair([lo, hi])) = spec.drag_bounds
        && !(lo > 0.0 && hi > lo && hi.is_finite())
    {
        return Err(bad(
            "drag_bounds",
            format!("[{lo}, {hi}]"),
            "need 0 < lo < hi",
        ));
    }
    if let Some(h) = spec.housing_rho_max
        && !(h > 0.0 && h < 1.0)
    {
        return Err(bad("housing_rho_max", h.to_string(), "must lie in (0, 1)"));
    }
    for (key, v) in [
        ("safety_factor", spec.safety_factor),
        ("max_unbalance", spec.max_unbalance),
        ("max_peak_over_a_ref", spec.max_peak_over_a_ref),
    ] {
        if let Some(v) = v
            && !(v.is_finite() && v > 0.0)
        {
            return Err(bad(key, v.to_string(), "must be positive and finite"));
        }
    }
    if spec.safety_factor.is_some() != spec.max_unbalance.is_some() {
        return Err(bad(
            "safety_factor",
            "…".into(),
            "give safety_factor and max_unbalance together",
        ));
    }
    Ok(())
}

/// The residual a `p_residual_below` objective counts against, and only there.
fn validate_objective(spec: &OptimizeSpec) -> Result<(), OptimizeError> {
    match (spec.objective, spec.residual_spec) {
        (Objective::PResidualBelow, None) => {
            return Err(bad(
                "residual_spec",
                "missing".into(),
                "p_residual_below needs the residual a machine may show (m), e.g. residual_spec = 2e-5",
            ));
        }
        (Objective::PResidualBelow, Some(v)) if !(v.is_finite() && v > 0.0) => {
            return Err(bad(
                "residual_spec",
                v.to_string(),
                "must be positive and finite (m)",
            ));
        }
        (Objective::PResidualBelow, Some(_)) | (_, None) => {}
        (other, Some(v)) => {
            return Err(bad(
                "residual_spec",
                v.to_string(),
                &format!(
                    "only used by objective = \"p_residual_below\", not \"{}\"",
                    other.name()
                ),
            ));
        }
    }
    Ok(())
}

/// Samples, evaluations and counts: within what a search can run.
fn validate_budget(spec: &OptimizeSpec, plan: &StudyPlan) -> Result<(), OptimizeError> {
    /// Most Monte Carlo samples per candidate (each a whole run, and the
    /// runs' metrics are held together).
    const MAX_SAMPLES: u32 = 1_000_000;
    /// Most objective evaluations per (kind, n).
    const MAX_EVALUATIONS: u64 = 100_000;
    if let Some(n) = spec.samples
        && !(1..=MAX_SAMPLES).contains(&n)
    {
        return Err(bad(
            "samples",
            n.to_string(),
            &format!("samples per candidate: 1 to {MAX_SAMPLES}"),
        ));
    }
    // As `study run` refuses it: a Sobol sequence is even only over 2^m points.
    if let Some(n) = spec.samples
        && plan.file.sampling.sequence == crate::study::plan::stream::Sequence::Sobol
        && !n.is_power_of_two()
    {
        return Err(bad(
            "samples",
            n.to_string(),
            &format!(
                "with sampling.sequence = \"sobol\" a power of two (e.g. {}): a Sobol sequence is even only over 2^m points",
                n.checked_next_power_of_two().unwrap_or(1 << 16)
            ),
        ));
    }
    if let Some(n) = spec.confirm_samples
        && n > MAX_SAMPLES
    {
        return Err(bad(
            "confirm_samples",
            n.to_string(),
            &format!("fresh samples per (kind, n) optimum: 0 to {MAX_SAMPLES}"),
        ));
    }
    if !(4..=MAX_EVALUATIONS).contains(&spec.max_evaluations) {
        return Err(bad(
            "max_evaluations",
            spec.max_evaluations.to_string(),
            &format!(
                "objective evaluations per (kind, n): 4 (the scan that brackets ρ takes 5, 4 at the least) to {MAX_EVALUATIONS}"
            ),
        ));
    }
    let ns = plan.file.designs.n.values();
    if let Some(min) = spec.min_n
        && !ns.iter().any(|&n| n >= min)
    {
        return Err(bad(
            "min_n",
            min.to_string(),
            "excludes every n of [designs]",
        ));
    }
    Ok(())
}

/// Run the optimisation of `plan`'s `[optimize]` table and write
/// `optimize.parquet` and `optimum.parquet` under the study's output folder.
pub fn optimize(plan: &StudyPlan) -> Result<OptimizeOutput, OptimizeError> {
    let spec = checked_spec(plan)?;
    // Common random numbers: every candidate meets the same sampled unbalances.
    let mut plan = plan.clone();
    plan.file.sampling.common_random_numbers = true;
    let evaluator = Evaluator {
        plan: &plan,
        spec: &spec,
        samples: spec.samples.unwrap_or(plan.file.sampling.samples),
    };
    let g = &plan.file.designs;
    let drag = g.drag.values()[0];
    // A second plane's own design (the complete optimisation below is of one balancer).
    let plane1 = g.per_plane.iter().find(|a| a.plane == 1);
    let cells = search_cells(&spec, g, drag);
    let results: Vec<_> = cells
        .par_iter()
        .with_max_len(1) // one search per job, as runs (study::run)
        .map(|&c| {
            let r = match c.plane1 {
                None => search::search(&evaluator, c.kind, c.n, drag),
                Some(_) => search::search_planes(&evaluator, c),
            };
            (c, r)
        })
        .collect();
    let results = cross_check_counts(&evaluator, results);
    let mut evaluations = Vec::new();
    let mut terminations = Vec::new();
    let mut stops = Vec::new();
    let mut best = Vec::new();
    for (c, r) in &results {
        let (scope, label) = match c.plane1 {
            None => (
                format!("{}_{}", c.kind, c.n),
                format!("{} n = {}", c.kind, c.n),
            ),
            Some(p) => (
                format!("{}_{}_plane1_{}_{}", c.kind, c.n, p.kind, p.n),
                format!("{} n = {}, plane 1: {} n = {}", c.kind, c.n, p.kind, p.n),
            ),
        };
        if let Some(b) = best_of(&r.evaluations, spec.objective) {
            best.push(Best {
                scope: scope.clone(),
                evaluation: b,
            });
        }
        stops.push(pick::SearchStop {
            label: label.clone(),
            scope: scope.clone(),
            end: r.end,
            evaluations: r.evaluations.len(),
        });
        terminations.push((label, scope, r.termination.clone()));
        evaluations.extend(r.evaluations.iter().cloned());
    }
    let per_scope: Vec<Evaluation> = best.iter().map(|b| b.evaluation.clone()).collect();
    let search_pick = best_of(&per_scope, spec.objective);
    let search_at = search_pick
        .as_ref()
        .and_then(|p| per_scope.iter().position(|e| e == p));
    // A simulated pick is the best on fresh samples, not on the search's own.
    let confirmation = search_at.and_then(|at| {
        let optima: Vec<(String, evaluate::Candidate)> = best
            .iter()
            .map(|b| (b.scope.clone(), b.evaluation.candidate))
            .collect();
        confirm::confirm(
            &evaluator,
            &optima,
            at,
            spec.confirm_samples
                .unwrap_or_else(|| confirm::default_samples(evaluator.samples)),
            1.0 - plan.file.statistics.alpha,
        )
    });
    let pick_at = confirmation.as_ref().map(|c| c.overall).or(search_at);
    let pick = pick::pick_status(
        pick_at.map(|i| best[i].scope.as_str()),
        &stops,
        spec.max_evaluations,
    );
    let overall = pick_at.map(|i| per_scope[i].clone());
    if let Some(b) = overall {
        best.push(Best {
            scope: "overall".into(),
            evaluation: b,
        });
    }
    // The paper's complete optimisation is of one balancer.
    if spec.objective == Objective::Capacity && plane1.is_none() {
        best.extend(complete_rows(&evaluator, &spec));
    }
    let dir = crate::study::run::output_dir(&plan, None);
    write_outputs(
        &plan,
        &dir,
        &evaluations,
        &best,
        &terminations,
        confirmation.as_ref(),
    )
    .map_err(|e| OptimizeError::Output(e.to_string()))?;
    Ok(OptimizeOutput {
        evaluations,
        terminations,
        best,
        dir,
        confirmation,
        pick,
    })
}

/// The searches to run: each (kind, n) of the designs allowed by `min_n`
/// (ρ to be found, `drag` fixed), and with a design per plane every
/// (kind, n) of plane 1 for each of plane 0's.
fn search_cells(
    spec: &OptimizeSpec,
    g: &crate::study::plan::config::DesignGrid,
    drag: f64,
) -> Vec<evaluate::Candidate> {
    let mut cells = Vec::new();
    for kind in g.kind.values() {
        for n in g.n.values() {
            if spec.min_n.is_none_or(|m| n >= m) {
                cells.push((kind, n));
            }
        }
    }
    // With a design per plane, every (kind, n) of plane 1 for each of plane 0's.
    let plane1 = g.per_plane.iter().find(|a| a.plane == 1);
    cells
        .into_iter()
        .flat_map(|(kind, n)| {
            let base = evaluate::Candidate {
                kind,
                n,
                rho: f64::NAN,
                drag,
                plane1: None,
            };
            match plane1 {
                None => vec![base],
                Some(a) => {
                    let kinds = a.kind.as_ref().map_or(vec![kind], |k| k.values());
                    let ns = a.n.as_ref().map_or(vec![n], |v| v.values());
                    kinds
                        .iter()
                        .flat_map(|&k1| {
                            ns.iter().map(move |&n1| evaluate::Candidate {
                                plane1: Some(evaluate::PlaneChoice {
                                    kind: k1,
                                    n: n1,
                                    rho: f64::NAN,
                                }),
                                ..base
                            })
                        })
                        .collect()
                }
            }
        })
        .collect()
}

/// Each count's search (one design per plane) checked against the other
/// counts' optima on its own samples ([`cross_check`]), one round, every
/// count in parallel from the first searches' optima.
fn cross_check_counts(
    evaluator: &Evaluator<'_>,
    results: Vec<(evaluate::Candidate, search::SearchResult)>,
) -> Vec<(evaluate::Candidate, search::SearchResult)> {
    let seeds: Vec<cross_check::Seed> = results
        .iter()
        .filter(|(c, _)| c.plane1.is_none())
        .filter_map(|(c, r)| {
            let best = best_of(&r.evaluations, evaluator.spec.objective)?;
            Some((format!("{} n = {}", c.kind, c.n), best.candidate))
        })
        .collect();
    results
        .into_par_iter()
        .with_max_len(1)
        .map(|(c, r)| match c.plane1 {
            None => (c, cross_check::cross_check(evaluator, c, r, &seeds)),
            Some(_) => (c, r),
        })
        .collect()
}

/// The paper's complete optimisation per kind (grow ρ to the housing limit,
/// dropping excess weights), next to the best per-n optimum under the same limit.
fn complete_rows(evaluator: &Evaluator<'_>, spec: &OptimizeSpec) -> Vec<Best> {
    let g = &evaluator.plan.file.designs;
    let n_max = g.n.values().into_iter().max().unwrap_or(1);
    let limit = spec.housing_rho_max.unwrap_or(0.5);
    let mut out = Vec::new();
    for kind in g.kind.values() {
        let shape = kind.model().shape();
        if let Ok(c) = complete_optimization(shape, n_max, limit) {
            let e = evaluator.evaluate(
                evaluate::Candidate {
                    kind,
                    n: c.n,
                    rho: c.rho,
                    drag: g.drag.values()[0],
                    plane1: None,
                },
                "complete",
            );
            out.push(Best {
                scope: format!("complete_{kind}"),
                evaluation: e,
            });
        }
        if let Ok((n, rho, _)) = best_per_n_optimum(shape, n_max, limit) {
            let e = evaluator.evaluate(
                evaluate::Candidate {
                    kind,
                    n,
                    rho,
                    drag: g.drag.values()[0],
                    plane1: None,
                },
                "analytic",
            );
            out.push(Best {
                scope: format!("per_n_{kind}"),
                evaluation: e,
            });
        }
    }
    out
}

/// The best feasible evaluation (ties: the first).
fn best_of(evals: &[Evaluation], objective: Objective) -> Option<Evaluation> {
    let key = |e: &Evaluation| e.value.map(|v| if objective.maximise() { -v } else { v });
    evals
        .iter()
        .filter(|e| e.feasible && e.value.is_some())
        .min_by(|a, b| {
            key(a)
                .unwrap_or(f64::INFINITY)
                .total_cmp(&key(b).unwrap_or(f64::INFINITY))
        })
        .cloned()
}

/// Evaluations as a DataFrame (one row each), with an optional scope column.
pub fn evaluations_frame(
    evals: &[Evaluation],
    scopes: Option<&[String]>,
) -> PolarsResult<DataFrame> {
    let mut cols = Vec::new();
    if let Some(s) = scopes {
        cols.push(Column::new("scope".into(), s.to_vec()));
    }
    cols.extend([
        Column::new(
            "kind".into(),
            evals
                .iter()
                .map(|e| e.candidate.kind.name().to_string())
                .collect::<Vec<_>>(),
        ),
        Column::new(
            "n".into(),
            evals.iter().map(|e| e.candidate.n).collect::<Vec<_>>(),
        ),
        Column::new(
            "rho".into(),
            evals.iter().map(|e| e.candidate.rho).collect::<Vec<_>>(),
        ),
        Column::new(
            "drag".into(),
            evals.iter().map(|e| e.candidate.drag).collect::<Vec<_>>(),
        ),
        Column::new(
            "objective".into(),
            evals.iter().map(|e| e.value).collect::<Vec<_>>(),
        ),
        Column::new(
            "std_err".into(),
            evals.iter().map(|e| e.std_err).collect::<Vec<_>>(),
        ),
        Column::new(
            "capacity".into(),
            evals.iter().map(|e| e.capacity).collect::<Vec<_>>(),
        ),
        Column::new(
            "feasible".into(),
            evals.iter().map(|e| e.feasible).collect::<Vec<_>>(),
        ),
        Column::new(
            "constraint".into(),
            evals
                .iter()
                .map(|e| e.constraint.clone())
                .collect::<Vec<_>>(),
        ),
        Column::new(
            "peak_whirl_over_a_ref_median".into(),
            evals
                .iter()
                .map(|e| e.peak_whirl_over_a_ref)
                .collect::<Vec<_>>(),
        ),
        Column::new(
            "phase".into(),
            evals
                .iter()
                .map(|e| e.phase.to_string())
                .collect::<Vec<_>>(),
        ),
    ]);
    // With a design per plane: plane 1's kind, n and ρ beside plane 0's.
    if evals.iter().any(|e| e.candidate.plane1.is_some()) {
        let p1 = |e: &Evaluation| e.candidate.plane1;
        cols.push(Column::new(
            "kind_plane1".into(),
            evals
                .iter()
                .map(|e| p1(e).map(|p| p.kind.name().to_string()))
                .collect::<Vec<_>>(),
        ));
        cols.push(Column::new(
            "n_plane1".into(),
            evals.iter().map(|e| p1(e).map(|p| p.n)).collect::<Vec<_>>(),
        ));
        cols.push(Column::new(
            "rho_plane1".into(),
            evals
                .iter()
                .map(|e| p1(e).map(|p| p.rho))
                .collect::<Vec<_>>(),
        ));
    }
    DataFrame::new(evals.len(), cols)
}

fn write_outputs(
    plan: &StudyPlan,
    dir: &std::path::Path,
    evals: &[Evaluation],
    best: &[Best],
    terminations: &[(String, String, String)],
    confirmation: Option<&confirm::Confirmation>,
) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all(dir)?;
    let provenance = Provenance::new(&plan.text, plan.file.seed, "all");
    let mut all = evaluations_frame(evals, None)?;
    write_parquet(&dir.join("optimize.parquet"), &mut all, &provenance)?;
    let scopes: Vec<String> = best.iter().map(|b| b.scope.clone()).collect();
    let chosen: Vec<Evaluation> = best.iter().map(|b| b.evaluation.clone()).collect();
    let mut optimum = evaluations_frame(&chosen, Some(&scopes))?;
    // Why each (kind, n) search stopped: converged, budget, bound or
    // unconfirmed, with the words `study optimize` prints.
    let stops: Vec<Option<String>> = scopes
        .iter()
        .map(|scope| {
            terminations
                .iter()
                .find(|(_, s, _)| s == scope)
                .map(|(_, _, why)| why.clone())
        })
        .collect();
    optimum.with_column(Column::new("stop".into(), stops))?;
    // Each scope's optimum on the fresh samples, and against the pick.
    let confirmed: Vec<Option<&confirm::Confirmed>> = scopes
        .iter()
        .map(|scope| confirmation?.row(scope))
        .collect();
    let column = |name: &str, f: &dyn Fn(&confirm::Confirmed) -> Option<f64>| {
        Column::new(
            name.into(),
            confirmed
                .iter()
                .map(|r| r.and_then(f))
                .collect::<Vec<Option<f64>>>(),
        )
    };
    let samples = confirmation.map(|c| c.samples);
    for c in [
        column("confirmed_objective", &|r| Some(r.value)),
        column("confirmed_std_err", &|r| Some(r.std_err)),
        column("vs_overall_diff", &|r| r.vs_overall.map(|d| d.difference)),
        column("vs_overall_diff_lo", &|r| {
            r.vs_overall.map(|d| d.interval.0)
        }),
        column("vs_overall_diff_hi", &|r| {
            r.vs_overall.map(|d| d.interval.1)
        }),
        Column::new(
            "confirmed_samples".into(),
            confirmed
                .iter()
                .map(|r| r.and(samples))
                .collect::<Vec<Option<u32>>>(),
        ),
        Column::new(
            "tie_with_overall".into(),
            confirmed
                .iter()
                .zip(&scopes)
                .map(|(r, scope)| r.filter(|_| scope != "overall").map(|r| r.ties()))
                .collect::<Vec<Option<bool>>>(),
        ),
    ] {
        optimum.with_column(c)?;
    }
    write_parquet(&dir.join("optimum.parquet"), &mut optimum, &provenance)?;
    Ok(())
}
