//! A count's search checked against the optima the other counts found. In
//! a curved valley (ρ and β rising together) the simplex stops where its
//! values come within their standard errors, which on a plateau is not an
//! optimum: an optical drive's 5-ball search stopped "converged" at its
//! start (27.8 rev) while the 4-ball optimum's (ρ, β) gave 19.0 rev with 5
//! balls on the same samples. So every count tries the others' optima on
//! its own samples, and one that beats its own by more than their standard
//! errors restarts its search from there.

use super::evaluate::{Candidate, Evaluator};
use super::search::{
    SearchEnd, SearchResult, nelder_mead_from, rho_interval, solver_cost, try_points,
};
use super::spec::Variable;

/// Fewest evaluations left for a restart from a better seed: a simplex of
/// three points and a few moves.
const MIN_RESTART: u64 = 6;

/// One other count's optimum: its label ("ball n = 4") and its candidate.
pub type Seed = (String, Candidate);

/// `first`, the search of `base`'s count, checked against `seeds` (the
/// other counts' optima), one evaluation each on top of
/// `optimize.max_evaluations` (the check is part of calling a search
/// converged): a seed inside this count's ρ interval that beats its
/// optimum by more than both standard errors restarts the search there
/// with what is left of the budget (ρ and β free), or else makes the stop
/// "unconfirmed", the seed being the best point seen (ρ alone, where the
/// scan already covered the interval, a better seed means it missed a
/// narrow minimum).
pub fn cross_check(
    evaluator: &Evaluator<'_>,
    base: Candidate,
    first: SearchResult,
    seeds: &[Seed],
) -> SearchResult {
    let budget = evaluator.spec.max_evaluations.max(4);
    let Some(own) = first
        .evaluations
        .iter()
        .min_by(|a, b| solver_cost(evaluator, a).total_cmp(&solver_cost(evaluator, b)))
        .cloned()
    else {
        return first;
    };
    let own_cost = solver_cost(evaluator, &own);
    let (lo, hi) = rho_interval(evaluator, base.n);
    let drag_free = evaluator.spec.free.contains(&Variable::Drag);
    let tried: Vec<&Seed> = seeds
        .iter()
        .filter(|(_, c)| c.kind == base.kind && c.n != base.n)
        .filter(|(_, c)| (lo..=hi).contains(&c.rho))
        .filter(|(_, c)| drag_free || c.drag == base.drag)
        .collect();
    let left = budget.saturating_sub(first.evaluations.len() as u64);
    if tried.is_empty() {
        return first;
    }
    let points: Vec<(f64, f64)> = tried.iter().map(|(_, c)| (c.rho, c.drag)).collect();
    let (logged, scored) = try_points(evaluator, base, &points, "cross_check");
    let better = scored
        .iter()
        .enumerate()
        .filter(|(_, (f, se))| *f < own_cost - se.max(own.std_err))
        .min_by(|a, b| a.1.0.total_cmp(&b.1.0));
    let mut evaluations = first.evaluations.clone();
    evaluations.extend(logged);
    let Some((k, &(f, _))) = better else {
        return SearchResult {
            evaluations,
            termination: format!(
                "{}; no other count's optimum ({}) beats it by more than their standard errors on these samples",
                first.termination,
                tried
                    .iter()
                    .map(|(label, _)| label.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            stop: first.stop,
            end: first.end,
        };
    };
    let (label, seed) = tried[k];
    let gain = (own_cost - f).abs();
    let unit = evaluator.spec.objective.unit();
    let why = format!(
        "the optimum of {label} (ρ = {:.4}, β = {:.4} N·s/m) beat this count's first optimum by {gain:.3} {unit} on its own samples",
        seed.rho, seed.drag
    );
    // A restart needs room for a simplex and its check.
    if !drag_free || left < MIN_RESTART {
        return SearchResult {
            evaluations,
            termination: format!(
                "unconfirmed: {why}{}; the optimum printed is the best point seen (first search: {})",
                if drag_free {
                    format!(
                        ", and optimize.max_evaluations = {budget} leaves {left} evaluations, too few to search from there"
                    )
                } else {
                    String::new()
                },
                first.termination
            ),
            stop: "unconfirmed",
            end: SearchEnd::Unconfirmed,
        };
    }
    let restart = nelder_mead_from(evaluator, base, (seed.rho, seed.drag), left);
    evaluations.extend(restart.evaluations);
    SearchResult {
        evaluations,
        termination: format!("restarted: {why}; from there, {}", restart.termination),
        stop: restart.stop,
        end: restart.end,
    }
}
