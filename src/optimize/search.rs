//! The continuous searches (argmin): Brent over ρ for each kind and n, with a
//! noise-aware stop, or Nelder–Mead over (ρ, ln β). The integer n is enumerated
//! by the caller.

use super::evaluate::{Candidate, Evaluation, Evaluator};
use super::spec::Variable;
use crate::design::geometry::rho_max;
use crate::model::balancer::Kind;
use argmin::core::{
    CostFunction, Error as ArgminError, Executor, IterState, KV, Problem, Solver, State,
    TerminationReason, TerminationStatus,
};
use argmin::solver::brent::BrentOpt;
use argmin::solver::neldermead::NelderMead;
use std::sync::Mutex;

/// Cost given to infeasible candidates (finite, so the solvers stay well defined).
const INFEASIBLE: f64 = 1e12;

/// The objective over the free variables of one (kind, n), as an argmin cost,
/// logging every evaluation.
struct CandidateCost<'a> {
    evaluator: &'a Evaluator<'a>,
    kind: Kind,
    n: u32,
    drag: f64,
    phase: &'static str,
    log: Mutex<Vec<Evaluation>>,
}

impl CandidateCost<'_> {
    fn eval(&self, rho: f64, drag: f64) -> f64 {
        let c = Candidate {
            kind: self.kind,
            n: self.n,
            rho,
            drag,
        };
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
    /// Why the search stopped.
    pub termination: String,
}

/// The ρ interval to search for n weights: the bounds, the fit limit and the housing limit.
pub fn rho_interval(evaluator: &Evaluator<'_>, n: u32) -> (f64, f64) {
    let spec = evaluator.spec;
    let [lo, hi] = spec.rho_bounds.unwrap_or([0.02, 1.0]);
    let mut hi = hi.min(rho_max(n).unwrap_or(1.0) * (1.0 - 1e-9)).min(0.999);
    if let Some(h) = spec.housing_rho_max {
        hi = hi.min(h);
    }
    (lo.min(hi), hi)
}

/// Search the free variables for one kind and n.
pub fn search(evaluator: &Evaluator<'_>, kind: Kind, n: u32, drag: f64) -> SearchResult {
    let spec = evaluator.spec;
    let (lo, hi) = rho_interval(evaluator, n);
    let budget = spec.max_evaluations.max(4);
    let cost = CandidateCost {
        evaluator,
        kind,
        n,
        drag,
        phase: "scan",
        log: Mutex::new(Vec::new()),
    };
    if spec.free.contains(&Variable::Drag) {
        return nelder_mead(&cost, lo, hi, budget);
    }
    // A coarse scan brackets the best ρ (Brent only finds a local minimum) …
    const SCAN: usize = 5;
    let grid: Vec<f64> = (0..SCAN)
        .map(|i| lo + (hi - lo) * i as f64 / (SCAN - 1) as f64)
        .collect();
    let costs: Vec<f64> = grid.iter().map(|&r| cost.eval(r, drag)).collect();
    let best = (0..SCAN)
        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
        .unwrap_or(0);
    if costs[best] >= INFEASIBLE || hi - lo < 1e-9 {
        return SearchResult {
            evaluations: cost.take_log(),
            termination: "no feasible ρ in the scan".into(),
        };
    }
    // … then Brent refines it between the neighbouring scan points.
    let (a, b) = (grid[best.saturating_sub(1)], grid[(best + 1).min(SCAN - 1)]);
    let brent_cost = CandidateCost {
        phase: "brent",
        log: Mutex::new(cost.take_log()),
        ..cost
    };
    let solver = NoiseAwareBrent {
        inner: BrentOpt::new(a, b).set_tolerance(1e-4, 1e-5),
        converged: false,
    };
    let result = Executor::new(RhoCost(&brent_cost), solver)
        .configure(|s| s.max_iters(budget.saturating_sub(SCAN as u64 + 1)))
        .run();
    let termination = match result {
        Ok(r) => r
            .state()
            .get_termination_reason()
            .map_or("done".to_string(), |t| t.text().to_string()),
        Err(e) => format!("error: {e}"),
    };
    SearchResult {
        evaluations: brent_cost.take_log(),
        termination,
    }
}

/// Nelder–Mead over (ρ, ln β), starting from a simplex around the middle of
/// the ρ interval and the given drag; stops when the simplex's costs spread
/// less than the first evaluation's standard error.
fn nelder_mead(cost: &CandidateCost<'_>, lo: f64, hi: f64, budget: u64) -> SearchResult {
    let spec = cost.evaluator.spec;
    let [dlo, dhi] = spec
        .drag_bounds
        .unwrap_or([cost.drag / 10.0, cost.drag * 10.0]);
    let mid = 0.5 * (lo + hi);
    let ln_drag = cost.drag.ln();
    let step_rho = 0.25 * (hi - lo);
    let step_drag = 0.25 * (dhi.ln() - dlo.ln());
    let bounded = BoundedCost {
        inner: cost,
        rho: (lo, hi),
        ln_drag: (dlo.ln(), dhi.ln()),
    };
    let first = bounded.cost(&vec![mid, ln_drag]).unwrap_or(INFEASIBLE);
    let se = cost
        .log
        .lock()
        .expect("log lock")
        .last()
        .map_or(0.0, |e| e.std_err);
    let _ = first;
    let simplex = vec![
        vec![mid, ln_drag],
        vec![mid + step_rho, ln_drag],
        vec![mid, ln_drag + step_drag],
    ];
    let solver = match NelderMead::new(simplex).with_sd_tolerance(se.max(1e-12)) {
        Ok(s) => s,
        Err(e) => {
            return SearchResult {
                evaluations: cost.take_log(),
                termination: format!("error: {e}"),
            };
        }
    };
    let result = Executor::new(bounded, solver)
        .configure(|s| s.max_iters(budget / 2))
        .run();
    let termination = match result {
        Ok(r) => r
            .state()
            .get_termination_reason()
            .map_or("done".to_string(), |t| t.text().to_string()),
        Err(e) => format!("error: {e}"),
    };
    let mut evaluations = cost.take_log();
    for e in &mut evaluations {
        e.phase = "nelder_mead";
    }
    SearchResult {
        evaluations,
        termination,
    }
}

/// (ρ, ln β) with box bounds: points outside cost [`INFEASIBLE`] without being simulated.
struct BoundedCost<'a> {
    inner: &'a CandidateCost<'a>,
    rho: (f64, f64),
    ln_drag: (f64, f64),
}

impl CostFunction for BoundedCost<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, ArgminError> {
        if p[0] < self.rho.0 || p[0] > self.rho.1 || p[1] < self.ln_drag.0 || p[1] > self.ln_drag.1
        {
            return Ok(INFEASIBLE);
        }
        self.inner.cost(p)
    }
}
