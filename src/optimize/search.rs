//! The continuous searches (argmin): Brent over ρ for each kind and n, with a
//! noise-aware stop, or Nelder–Mead over (ρ, ln β). The integer n is enumerated
//! by the caller.
//!
//! About 640 lines of code: the scan that brackets ρ, the Brent pass, its
//! noise-aware stop and the neighbour check, and the simplex's restarts share
//! one evaluation budget and one record of the evaluations, so they are one
//! file rather than parts passing that state around.

use super::evaluate::{Candidate, Evaluation, Evaluator};
use super::noisy_simplex::{self, SimplexStop, Vertex};
use super::spec::Variable;
use crate::design::geometry::rho_max;
use crate::model::balancer::Kind;
use argmin::core::{
    CostFunction, Error as ArgminError, Executor, IterState, KV, Problem, Solver, State,
    TerminationReason, TerminationStatus,
};
use argmin::solver::brent::BrentOpt;
use std::collections::HashMap;
use std::sync::Mutex;

/// Cost given to infeasible candidates (finite, so the solvers stay well defined).
const INFEASIBLE: f64 = 1e12;

/// The objective over the free variables of one (kind, n), as an argmin cost,
/// logging every evaluation.
struct CandidateCost<'a> {
    evaluator: &'a Evaluator<'a>,
    /// The candidate the search moves: its ρ in `slot` varies.
    base: Candidate,
    slot: Slot,
    drag: f64,
    phase: &'static str,
    log: Mutex<Vec<Evaluation>>,
}

/// Which radius ratio a search varies, with a design per plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// Plane 0's ρ (the only one without a design per plane).
    Plane0,
    /// Plane 1's ρ, plane 0's held.
    Plane1,
    /// One ρ for both planes.
    Tied,
}

impl Slot {
    /// The ρ this slot varies in candidate c.
    fn rho_of(self, c: &Candidate) -> f64 {
        match (self, c.plane1) {
            (Slot::Plane1, Some(p)) => p.rho,
            _ => c.rho,
        }
    }

    /// The weight count whose fit bounds this slot's ρ (the larger count, tied).
    fn n_of(self, c: &Candidate) -> u32 {
        match (self, c.plane1) {
            (Slot::Plane1, Some(p)) => p.n,
            (Slot::Tied, Some(p)) => p.n.max(c.n),
            _ => c.n,
        }
    }
}

impl CandidateCost<'_> {
    fn eval(&self, rho: f64, drag: f64) -> f64 {
        let mut c = Candidate { drag, ..self.base };
        match self.slot {
            Slot::Plane0 => c.rho = rho,
            Slot::Plane1 => {
                if let Some(p) = c.plane1.as_mut() {
                    p.rho = rho;
                }
            }
            Slot::Tied => {
                c.rho = rho;
                if let Some(p) = c.plane1.as_mut() {
                    p.rho = rho;
                }
            }
        }
        let e = self.evaluator.evaluate(c, self.phase);
        let cost = match e.value {
            // A p95 that reaches a run without a residual is +∞: as bad as
            // infeasible, and finite for the solvers.
            Some(v) if !v.is_finite() => INFEASIBLE,
            Some(v) if self.evaluator.spec.objective.maximise() => -v,
            Some(v) => v,
            None => INFEASIBLE,
        };
        self.log.lock().expect("log lock").push(e);
        cost
    }

    fn take_log(&self) -> Vec<Evaluation> {
        std::mem::take(&mut *self.log.lock().expect("log lock"))
    }
}

impl CostFunction for CandidateCost<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, ArgminError> {
        let drag = if p.len() > 1 { p[1].exp() } else { self.drag };
        Ok(self.eval(p[0], drag))
    }
}

/// 1-D view over ρ for Brent.
struct RhoCost<'a>(&'a CandidateCost<'a>);

impl CostFunction for RhoCost<'_> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, rho: &f64) -> Result<f64, ArgminError> {
        Ok(self.0.eval(*rho, self.0.drag))
    }
}

/// Brent's minimiser that also stops once the last three objective values
/// differ by less than their Monte Carlo standard error: refining ρ further
/// would only chase noise.
struct NoiseAwareBrent {
    inner: BrentOpt<f64>,
    converged: bool,
}

impl<'a> Solver<RhoCost<'a>, IterState<f64, (), (), (), (), f64>> for NoiseAwareBrent {
    fn name(&self) -> &str {
        "Brent (noise-aware)"
    }

    fn init(
        &mut self,
        problem: &mut Problem<RhoCost<'a>>,
        state: IterState<f64, (), (), (), (), f64>,
    ) -> Result<(IterState<f64, (), (), (), (), f64>, Option<KV>), ArgminError> {
        self.inner.init(problem, state)
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<RhoCost<'a>>,
        state: IterState<f64, (), (), (), (), f64>,
    ) -> Result<(IterState<f64, (), (), (), (), f64>, Option<KV>), ArgminError> {
        let out = self.inner.next_iter(problem, state)?;
        if let Some(cost) = problem.problem.as_ref() {
            let log = cost.0.log.lock().expect("log lock");
            let recent: Vec<&Evaluation> = log.iter().rev().take(3).collect();
            if recent.len() == 3 && recent.iter().all(|e| e.value.is_some() && e.std_err > 0.0) {
                let values: Vec<f64> = recent.iter().filter_map(|e| e.value).collect();
                let spread = values.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
                    - values.iter().cloned().fold(f64::INFINITY, f64::min);
                let se = recent.iter().map(|e| e.std_err).fold(0.0, f64::max);
                self.converged = spread < se;
            }
        }
        Ok(out)
    }

    fn terminate(&mut self, _state: &IterState<f64, (), (), (), (), f64>) -> TerminationStatus {
        if self.converged {
            TerminationStatus::Terminated(TerminationReason::SolverExit(
                "objective differences below the Monte Carlo standard error".into(),
            ))
        } else {
            TerminationStatus::NotTerminated
        }
    }
}

/// What one (kind, n) search produced.
#[derive(Debug, Clone)]
pub struct SearchResult {
    /// Every evaluation, in order.
    pub evaluations: Vec<Evaluation>,
    /// Why the search stopped, in words (printed, and stored in optimum.parquet).
    pub termination: String,
    /// Why, in one word: "converged", "budget", "bound", "unconfirmed" or "infeasible".
    pub stop: &'static str,
    /// How the search itself ended, whether or not its optimum sits on a
    /// bound (`stop` says "bound" over any of these).
    pub end: SearchEnd,
}

/// How a search ended: converged, or why not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchEnd {
    /// It met its tolerance and its optimum held against its neighbours.
    Converged,
    /// `optimize.max_evaluations` ran out before it met its tolerance.
    Budget,
    /// A point better than its optimum was found (a neighbour, or another
    /// count's optimum) with no budget left to search from there.
    Unconfirmed,
    /// No feasible candidate was found.
    Infeasible,
}

impl SearchEnd {
    /// The end of the search in one word, as `stop` spells it.
    fn from_stop(stop: &str) -> SearchEnd {
        match stop {
            "converged" => SearchEnd::Converged,
            "unconfirmed" => SearchEnd::Unconfirmed,
            "infeasible" => SearchEnd::Infeasible,
            _ => SearchEnd::Budget,
        }
    }
}

/// The ρ interval to search for n weights: the bounds, the fit limit and the housing limit.
pub fn rho_interval(evaluator: &Evaluator<'_>, n: u32) -> (f64, f64) {
    let spec = evaluator.spec;
    let [lo, hi] = spec.rho_bounds.map_or([0.02, 1.0], |p| p.0);
    let mut hi = hi.min(rho_max(n).unwrap_or(1.0) * (1.0 - 1e-9)).min(0.999);
    if let Some(h) = spec.housing_rho_max {
        hi = hi.min(h);
    }
    (lo.min(hi), hi)
}

/// Most passes of search-and-confirm before the search gives up (each pass
/// improves the optimum by more than its standard error, so this only
/// guards against a pathological objective).
const MAX_PASSES: usize = 20;

/// The best logged evaluation (lowest cost).
fn best_logged(cost: &CandidateCost<'_>) -> Option<Evaluation> {
    let log = cost.log.lock().expect("log lock");
    let key = |e: &Evaluation| solver_cost(cost.evaluator, e);
    log.iter().min_by(|a, b| key(a).total_cmp(&key(b))).cloned()
}

/// "; on the lower bound of …" when the optimum sits on a bound.
fn bound_note(
    best: &Evaluation,
    slot: Slot,
    rho: (f64, f64),
    drag: Option<(f64, f64)>,
    fit: f64,
) -> Option<String> {
    let at = |x: f64, b: f64| (x - b).abs() <= 1e-9 * b.abs().max(1e-12);
    let c = best.candidate;
    let c_rho = slot.rho_of(&c);
    let mut notes = Vec::new();
    if at(c_rho, rho.0) {
        notes.push(format!(
            "ρ on its lower bound {:.4} (optimize.rho_bounds)",
            rho.0
        ));
    }
    if at(c_rho, rho.1) {
        let which = if at(rho.1, fit) {
            "the largest ρ whose weights fit the race"
        } else {
            "optimize.rho_bounds or housing_rho_max"
        };
        notes.push(format!("ρ on its upper bound {:.4} ({which})", rho.1));
    }
    if let Some((lo, hi)) = drag {
        if at(c.drag, lo) {
            notes.push(format!(
                "β on its lower bound {lo} N·s/m (optimize.drag_bounds)"
            ));
        }
        if at(c.drag, hi) {
            notes.push(format!(
                "β on its upper bound {hi} N·s/m (optimize.drag_bounds)"
            ));
        }
    }
    (!notes.is_empty()).then(|| notes.join(" and "))
}

/// Search the free variables for one kind and n.
pub fn search(evaluator: &Evaluator<'_>, kind: Kind, n: u32, drag: f64) -> SearchResult {
    let base = Candidate {
        kind,
        n,
        rho: f64::NAN,
        drag,
        plane1: None,
    };
    search_slot(evaluator, base, Slot::Plane0)
}

/// Search one radius ratio (`slot`) of `base` (and the drag, when free).
pub fn search_slot(evaluator: &Evaluator<'_>, base: Candidate, slot: Slot) -> SearchResult {
    let spec = evaluator.spec;
    let drag = base.drag;
    let n = slot.n_of(&base);
    let (lo, hi) = rho_interval(evaluator, n);
    let budget = spec.max_evaluations.max(4);
    let cost = CandidateCost {
        evaluator,
        base,
        slot,
        drag,
        phase: "scan",
        log: Mutex::new(Vec::new()),
    };
    if spec.free.contains(&Variable::Drag) {
        return nelder_mead(&cost, lo, hi, budget, None);
    }
    // A coarse scan brackets the best ρ (Brent only finds a local minimum) …
    // five points, or four when that is the whole budget: the scan never
    // spends more than `max_evaluations`.
    let scan = (budget as usize).min(5);
    let grid: Vec<f64> = (0..scan)
        .map(|i| lo + (hi - lo) * i as f64 / (scan - 1) as f64)
        .collect();
    let costs: Vec<f64> = grid.iter().map(|&r| cost.eval(r, drag)).collect();
    let best = (0..scan)
        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
        .unwrap_or(0);
    if costs[best] >= INFEASIBLE || hi - lo < 1e-9 {
        return SearchResult {
            evaluations: cost.take_log(),
            termination: "infeasible: no feasible ρ in the scan".into(),
            stop: "infeasible",
            end: SearchEnd::Infeasible,
        };
    }
    // … then Brent refines it between the neighbouring scan points, and the
    // optimum is checked against its two neighbours at an eighth of the scan
    // step; a neighbour that beats it by more than its standard error starts
    // another pass around itself.
    let brent_cost = CandidateCost {
        phase: "brent",
        log: Mutex::new(cost.take_log()),
        ..cost
    };
    let mut bracket = (grid[best.saturating_sub(1)], grid[(best + 1).min(scan - 1)]);
    let h = (hi - lo) / (8.0 * 4.0);
    let mut stop = "budget";
    let mut how = String::new();
    for _ in 0..MAX_PASSES {
        let used = brent_cost.log.lock().expect("log lock").len() as u64;
        // Brent evaluates once to start and once per iteration: with fewer
        // than two evaluations left it cannot take a step within the budget.
        if used + 2 > budget {
            break;
        }
        let solver = NoiseAwareBrent {
            inner: BrentOpt::new(bracket.0, bracket.1).set_tolerance(1e-4, 1e-5),
            converged: false,
        };
        let result = Executor::new(RhoCost(&brent_cost), solver)
            .configure(|s| s.max_iters(budget - used - 1))
            .run();
        let reason = match result {
            Ok(r) => r
                .state()
                .get_termination_reason()
                .map_or("done".to_string(), |t| t.text().to_string()),
            Err(e) => format!("error: {e}"),
        };
        if reason.contains("Maximum number of iterations") || reason.starts_with("error") {
            stop = "budget";
            how = reason;
            break;
        }
        // Confirm against the two neighbours.
        let Some(opt) = best_logged(&brent_cost) else {
            break;
        };
        let (f0, se0) = (cost_of(&brent_cost, &opt), opt.std_err);
        let mut beaten = None;
        let opt_rho = slot.rho_of(&opt.candidate);
        for r in [opt_rho - h, opt_rho + h] {
            let r = r.clamp(lo, hi);
            if brent_cost.log.lock().expect("log lock").len() as u64 >= budget {
                break;
            }
            let f = brent_cost.eval(r, drag);
            if f < f0 - se0 {
                beaten = Some(r);
            }
        }
        match beaten {
            None => {
                stop = "converged";
                how = format!("{reason}; confirmed against ρ ± {h:.4} on the same samples");
                break;
            }
            Some(r) => {
                stop = "unconfirmed";
                how = format!(
                    "ρ = {r:.4} beats the refined optimum by more than its standard error {se0:.3}"
                );
                bracket = ((r - 2.0 * h).max(lo), (r + 2.0 * h).min(hi));
            }
        }
    }
    let fit = rho_max(n).unwrap_or(1.0) * (1.0 - 1e-9);
    finish(&brent_cost, stop, how, budget, (lo, hi), None, fit)
}

/// Rounds of the coordinate search over the two planes' ρ at most.
const PLANE_ROUNDS: usize = 4;

/// Search plane 0's and plane 1's radius ratios of `base` (a design per
/// plane): first one ρ for both planes, then, in rounds, plane 1's with plane
/// 0's held at the best so far and plane 0's with plane 1's held, until a
/// round improves the best by no more than its standard error (a weaker
/// plane bounds the design: raising one plane can make the other the
/// weaker, so one round is not enough). Each stage has its own
/// `optimize.max_evaluations`; the stop is the last round's worst.
pub fn search_planes(evaluator: &Evaluator<'_>, base: Candidate) -> SearchResult {
    let objective = evaluator.spec.objective;
    let key = |e: &Evaluation| match e.value {
        Some(v) if v.is_finite() && e.feasible && objective.maximise() => -v,
        Some(v) if v.is_finite() && e.feasible => v,
        _ => INFEASIBLE,
    };
    let mut evaluations: Vec<Evaluation> = Vec::new();
    let mut words = Vec::new();
    let mut stops = Vec::new();
    let mut ends = Vec::new();
    let mut start = base;
    let mut previous: Option<(f64, f64)> = None;
    let stages = std::iter::once((Slot::Tied, "one ρ for both planes")).chain(
        (0..PLANE_ROUNDS)
            .flat_map(|_| [(Slot::Plane1, "plane 1's ρ"), (Slot::Plane0, "plane 0's ρ")]),
    );
    for (k, (slot, name)) in stages.enumerate() {
        let r = search_slot(evaluator, start, slot);
        evaluations.extend(r.evaluations);
        words.push(format!("{name}: {}", r.termination));
        stops.push(r.stop);
        ends.push(r.end);
        let Some(best) = evaluations.iter().min_by(|a, b| key(a).total_cmp(&key(b))) else {
            break;
        };
        if key(best) >= INFEASIBLE {
            return SearchResult {
                evaluations,
                termination: words.join("; "),
                stop: "infeasible",
                end: SearchEnd::Infeasible,
            };
        }
        start = best.candidate;
        // After each round (plane 1, then plane 0): stop once it gained no
        // more than the standard error.
        if k % 2 == 0 && k > 0 {
            let now = (key(best), best.std_err);
            if let Some((before, _)) = previous
                && before - now.0 <= now.1.max(1e-12 * now.0.abs())
            {
                break;
            }
            previous = Some(now);
        }
    }
    // The worst of the two coordinate stages' stops.
    let rank = |s: &str| match s {
        "infeasible" => 0,
        "budget" => 1,
        "unconfirmed" => 2,
        "bound" => 3,
        _ => 4,
    };
    let stop = stops[stops.len().saturating_sub(2)..]
        .iter()
        .copied()
        .min_by_key(|s| rank(s))
        .unwrap_or("budget");
    // Converged only when both of the last stages did.
    let last = &ends[ends.len().saturating_sub(2)..];
    let end = last
        .iter()
        .copied()
        .find(|e| *e != SearchEnd::Converged)
        .unwrap_or(if last.is_empty() {
            SearchEnd::Budget
        } else {
            SearchEnd::Converged
        });
    SearchResult {
        evaluations,
        termination: words.join("; "),
        stop,
        end,
    }
}

/// The cost of a logged evaluation as the solvers see it.
fn cost_of(cost: &CandidateCost<'_>, e: &Evaluation) -> f64 {
    solver_cost(cost.evaluator, e)
}

/// The search's result with its stop stated honestly: a bound overrides
/// "converged", and a budget stop is never called converged.
fn finish(
    cost: &CandidateCost<'_>,
    stop: &'static str,
    how: String,
    budget: u64,
    rho: (f64, f64),
    drag: Option<(f64, f64)>,
    fit: f64,
) -> SearchResult {
    let best = best_logged(cost);
    let used = cost.log.lock().expect("log lock").len();
    let mut text = match stop {
        "converged" => format!("converged: {how}"),
        "unconfirmed" => format!(
            "unconfirmed: {how}, and optimize.max_evaluations = {budget} is used up; the optimum printed is the best point seen"
        ),
        _ => format!(
            "budget: optimize.max_evaluations = {budget} used up ({used} evaluations) before the search met its tolerance{}; the optimum printed is the best point seen, not a converged one",
            if how.is_empty() {
                String::new()
            } else {
                format!(" ({how})")
            }
        ),
    };
    let end = SearchEnd::from_stop(stop);
    let mut stop = stop;
    if let Some(note) = best
        .as_ref()
        .and_then(|b| bound_note(b, cost.slot, rho, drag, fit))
    {
        text = format!("bound: {note}: the optimum may lie beyond it; {text}");
        stop = "bound";
    }
    SearchResult {
        evaluations: cost.take_log(),
        termination: text,
        stop,
        end,
    }
}

/// Points tried on one count's own samples, outside its search: the
/// evaluations (phase `phase`) and each point's cost as the solvers see it
/// (lower is better) with its standard error.
pub(super) fn try_points(
    evaluator: &Evaluator<'_>,
    base: Candidate,
    points: &[(f64, f64)],
    phase: &'static str,
) -> (Vec<Evaluation>, Vec<(f64, f64)>) {
    let cost = CandidateCost {
        evaluator,
        base,
        slot: Slot::Plane0,
        drag: base.drag,
        phase,
        log: Mutex::new(Vec::new()),
    };
    let scored = points
        .iter()
        .map(|&(rho, drag)| {
            let f = cost.eval(rho, drag);
            let se = cost
                .log
                .lock()
                .expect("log lock")
                .last()
                .map_or(0.0, |e| e.std_err);
            (f, se)
        })
        .collect();
    (cost.take_log(), scored)
}

/// A logged evaluation's cost as the solvers see it (lower is better).
pub(super) fn solver_cost(evaluator: &Evaluator<'_>, e: &Evaluation) -> f64 {
    match e.value {
        Some(v) if v.is_finite() && evaluator.spec.objective.maximise() => -v,
        Some(v) if v.is_finite() => v,
        _ => INFEASIBLE,
    }
}

/// The Nelder–Mead search of `base`'s count over (ρ, ln β), restarted
/// from (ρ, β) = `from` with `budget` evaluations.
pub(super) fn nelder_mead_from(
    evaluator: &Evaluator<'_>,
    base: Candidate,
    from: (f64, f64),
    budget: u64,
) -> SearchResult {
    let (lo, hi) = rho_interval(evaluator, base.n);
    let cost = CandidateCost {
        evaluator,
        base,
        slot: Slot::Plane0,
        drag: base.drag,
        phase: "scan",
        log: Mutex::new(Vec::new()),
    };
    nelder_mead(&cost, lo, hi, budget, Some(from))
}

/// The simplex's view of the candidates: (ρ, ln β) clamped into the box,
/// each distinct point simulated once (same samples, same value), within
/// the evaluation budget.
struct SimplexCost<'a, 'b> {
    cost: &'b CandidateCost<'a>,
    rho: (f64, f64),
    ln_drag: (f64, f64),
    budget: u64,
    seen: HashMap<(u64, u64), (f64, f64)>,
}

impl SimplexCost<'_, '_> {
    fn clamp(&self, x: &[f64]) -> (f64, f64) {
        (
            x[0].clamp(self.rho.0, self.rho.1),
            x[1].clamp(self.ln_drag.0, self.ln_drag.1),
        )
    }
    fn used(&self) -> u64 {
        self.cost.log.lock().expect("log lock").len() as u64
    }
}

impl noisy_simplex::Objective for SimplexCost<'_, '_> {
    fn eval(&mut self, x: &[f64]) -> Option<(f64, f64)> {
        let (rho, ln_drag) = self.clamp(x);
        let key = (rho.to_bits(), ln_drag.to_bits());
        if let Some(&known) = self.seen.get(&key) {
            return Some(known);
        }
        if self.used() >= self.budget {
            return None;
        }
        let f = self.cost.eval(rho, ln_drag.exp());
        let se = self
            .cost
            .log
            .lock()
            .expect("log lock")
            .last()
            .map_or(0.0, |e| e.std_err);
        self.seen.insert(key, (f, se));
        Some((f, se))
    }
}

/// The points an optimum `x` of the simplex is checked against: the 8 of
/// a grid at half the first `steps`, then, for each other vertex of the
/// final `simplex`, x ± the edge towards it scaled to the same distance in
/// step units (a valley where ρ and β rise together runs along the
/// simplex, not along the axes).
fn neighbours(x: &[f64], simplex: &[Vertex], steps: &[f64; 2]) -> Vec<Vec<f64>> {
    let mut out = Vec::new();
    for i in [-1.0, 0.0, 1.0] {
        for j in [-1.0, 0.0, 1.0] {
            if i != 0.0 || j != 0.0 {
                out.push(vec![x[0] + 0.5 * i * steps[0], x[1] + 0.5 * j * steps[1]]);
            }
        }
    }
    for v in simplex.iter().filter(|v| v.x != x) {
        let d = [(v.x[0] - x[0]) / steps[0], (v.x[1] - x[1]) / steps[1]];
        let norm = d[0].hypot(d[1]);
        if norm == 0.0 || !norm.is_finite() {
            continue;
        }
        for sign in [1.0, -1.0] {
            let k = sign * 0.5 / norm;
            out.push(vec![x[0] + k * d[0] * steps[0], x[1] + k * d[1] * steps[1]]);
        }
    }
    out
}

/// Nelder–Mead over (ρ, ln β) from `from` (default: the middle of the box
/// in ρ, the study's drag): it stops when the
/// simplex's values differ by less than their standard errors, restarts from
/// its best point (at least once, and again while a restart improves by more
/// than a standard error), then checks the optimum against its 8 neighbours
/// at half the first steps on the same samples; a neighbour that beats it by
/// more than its standard error restarts the search there.
fn nelder_mead(
    cost: &CandidateCost<'_>,
    lo: f64,
    hi: f64,
    budget: u64,
    from: Option<(f64, f64)>,
) -> SearchResult {
    let spec = cost.evaluator.spec;
    let [dlo, dhi] = spec
        .drag_bounds
        .map_or([cost.drag / 10.0, cost.drag * 10.0], |p| p.0);
    let ln_drag = (dlo.ln(), dhi.ln());
    let steps = [0.25 * (hi - lo), 0.25 * (ln_drag.1 - ln_drag.0)];
    let mut objective = SimplexCost {
        cost,
        rho: (lo, hi),
        ln_drag,
        budget,
        seen: HashMap::new(),
    };
    let (rho0, drag0) = from.unwrap_or((0.5 * (lo + hi), cost.drag));
    let mut start = vec![rho0.clamp(lo, hi), drag0.ln().clamp(ln_drag.0, ln_drag.1)];
    let mut previous: Option<Vertex> = None;
    let mut restarts = 0;
    let mut stop = "budget";
    let mut how = String::new();
    for _ in 0..MAX_PASSES {
        let (simplex, why) = noisy_simplex::minimise(&mut objective, &start, &steps);
        if why == SimplexStop::Budget {
            break;
        }
        let best = simplex[0].clone();
        let improved = previous
            .as_ref()
            .is_none_or(|p| best.f < p.f - p.se.max(best.se));
        if improved || restarts == 0 {
            if previous.as_ref().is_none_or(|p| best.f < p.f) {
                previous = Some(best.clone());
            }
            start = previous.as_ref().map_or(best.x.clone(), |p| p.x.clone());
            restarts += 1;
            continue;
        }
        // Confirm the optimum against its neighbours: the 8 of a grid at
        // half the first steps, and 2 along each of the final simplex's own
        // edges (at the same scaled distance), which follow a valley that
        // runs across the axes.
        let optimum = previous.clone().unwrap_or(best);
        let mut beaten: Option<Vertex> = None;
        let mut out_of_budget = false;
        for x in neighbours(&optimum.x, &simplex, &steps) {
            match noisy_simplex::Objective::eval(&mut objective, &x) {
                None => {
                    out_of_budget = true;
                    break;
                }
                Some((f, se)) if f < optimum.f - optimum.se => {
                    if beaten.as_ref().is_none_or(|b| f < b.f) {
                        beaten = Some(Vertex { x, f, se });
                    }
                }
                Some(_) => {}
            }
        }
        match (beaten, out_of_budget) {
            (None, false) => {
                stop = "converged";
                how = format!(
                    "the simplex's values came within their standard errors, after {restarts} restart{} from its best point; confirmed against its 8 neighbours at ρ ± {:.4}, ln β ± {:.3} and along the simplex's own edges on the same samples",
                    if restarts == 1 { "" } else { "s" },
                    0.5 * steps[0],
                    0.5 * steps[1]
                );
                break;
            }
            (None, true) => break,
            (Some(v), _) => {
                let (rho, ln_b) = objective.clamp(&v.x);
                stop = "unconfirmed";
                how = format!(
                    "the neighbour ρ = {rho:.4}, β = {:.4} N·s/m beats the simplex's optimum by more than its standard error {:.3}",
                    ln_b.exp(),
                    optimum.se
                );
                start = v.x.clone();
                previous = Some(v);
                restarts += 1;
            }
        }
    }
    let fit = rho_max(cost.slot.n_of(&cost.base)).unwrap_or(1.0) * (1.0 - 1e-9);
    let mut result = finish(cost, stop, how, budget, (lo, hi), Some((dlo, dhi)), fit);
    for e in &mut result.evaluations {
        e.phase = "nelder_mead";
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(rho: f64, drag: f64) -> Evaluation {
        Evaluation {
            candidate: crate::optimize::evaluate::Candidate {
                kind: Kind::Ball,
                n: 3,
                rho,
                drag,
                plane1: None,
            },
            value: Some(1.0),
            std_err: 0.1,
            capacity: None,
            feasible: true,
            constraint: "ok".into(),
            phase: "test",
            peak_whirl_over_a_ref: None,
        }
    }

    /// The check follows the simplex's own edges, at half a step in step
    /// units: a valley along (2, 1) steps is probed along it, which the
    /// axis grid alone (spacing ½ step along ρ, ln β and their diagonals)
    /// does not do.
    #[test]
    fn the_optimum_is_checked_along_the_simplexs_own_edges() {
        let vertex = |x: [f64; 2]| Vertex {
            x: x.to_vec(),
            f: 0.0,
            se: 0.0,
        };
        let steps = [0.1, 2.0];
        let simplex = [vertex([0.3, 1.0]), vertex([0.5, 3.0]), vertex([0.3, 0.0])];
        let points = neighbours(&[0.3, 1.0], &simplex, &steps);
        assert_eq!(points.len(), 8 + 4);
        // Along (0.2, 2.0) = (2, 1) steps, half a step away, both ways.
        let unit = [2.0 / 5f64.sqrt(), 1.0 / 5f64.sqrt()];
        for sign in [1.0, -1.0] {
            let want = [
                0.3 + sign * 0.5 * unit[0] * 0.1,
                1.0 + sign * 0.5 * unit[1] * 2.0,
            ];
            assert!(
                points
                    .iter()
                    .any(|p| (p[0] - want[0]).abs() < 1e-12 && (p[1] - want[1]).abs() < 1e-12),
                "{want:?} not in {points:?}"
            );
        }
    }

    #[test]
    fn an_optimum_on_a_bound_names_the_bound() {
        let rho = (0.02, 0.4);
        let drag = Some((0.05, 20.0));
        assert_eq!(
            bound_note(&at(0.2, 1.0), Slot::Plane0, rho, drag, 0.5),
            None
        );
        let low = bound_note(&at(0.2, 0.05), Slot::Plane0, rho, drag, 0.5).unwrap();
        assert!(low.contains("β on its lower bound 0.05 N·s/m"), "{low}");
        let fit = bound_note(&at(0.4, 1.0), Slot::Plane0, rho, drag, 0.4).unwrap();
        assert!(
            fit.contains("the largest ρ whose weights fit the race"),
            "{fit}"
        );
    }
}
