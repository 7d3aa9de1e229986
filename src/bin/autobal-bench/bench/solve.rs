//! The cost of whole solves of the reference problem per method and
//! tolerance, with exact step and RHS counts and the error against a tight
//! reference solve.

use super::BenchConfig;
use super::median;
use super::problem::{ATOL_PER_RTOL, BenchProblem, status_name};
use autobal::integrate::{Method, NoObserver, OdeSystem, SolveReport, Stats, Status};
use serde::Serialize;
use std::cell::Cell;
use std::hint::black_box;
use std::time::Instant;

/// Every integration method, in report order: extend when `Method` grows.
pub const METHODS: &[Method] = &[Method::Dp5, Method::Dop853, Method::Radau5];

/// Relative tolerances of the solve series.
pub const RTOLS: &[f64] = &[1e-6, 1e-9];

/// Wraps a system and counts its right-hand-side calls (to check solver statistics).
pub struct Counted<'a, S: ?Sized> {
    inner: &'a S,
    calls: Cell<u64>,
}

impl<'a, S: OdeSystem + ?Sized> Counted<'a, S> {
    /// Start counting at zero.
    pub fn new(inner: &'a S) -> Self {
        Counted {
            inner,
            calls: Cell::new(0),
        }
    }

    /// Calls made so far.
    pub fn calls(&self) -> u64 {
        self.calls.get()
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for Counted<'_, S> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn second_order_split(&self) -> Option<usize> {
        self.inner.second_order_split()
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.calls.set(self.calls.get() + 1);
        self.inner.rhs(t, y, dydt);
    }
}

/// Cost and result of one solve case.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolveCost {
    /// Integration method.
    pub method: Method,
    /// Number of cargoes.
    pub cargoes: usize,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance on the problem's scales.
    pub atol: f64,
    /// Horizon in revolutions.
    pub revolutions: f64,
    /// Horizon in time units.
    pub t_end: f64,
    /// Timed solves.
    pub repeats: usize,
    /// Median wall time per solve (ms).
    pub median_ms: f64,
    /// Fastest solve (ms).
    pub min_ms: f64,
    /// Median time per simulated revolution (µs).
    pub us_per_revolution: f64,
    /// Median time per right-hand-side call, solver overhead included (ns).
    pub ns_per_rhs_call: f64,
    /// The solver's own statistics.
    pub stats: Stats,
    /// RHS calls counted by wrapping the system (must equal `stats.rhs_calls`).
    pub counted_rhs_calls: u64,
    /// Final status ("finished" or the failure).
    pub status: String,
    /// Largest final-state difference to the tight reference, in scale units.
    pub error_vs_reference: Option<f64>,
}

/// Time every (method, rtol) solve of the reference problem, interleaved.
pub fn measure_solves(config: &BenchConfig) -> Vec<SolveCost> {
    let n = config.solve_cargoes;
    let problems: Vec<BenchProblem> = config
        .rtols
        .iter()
        .map(|&rtol| BenchProblem::new(n, rtol, config.revolutions))
        .collect();
    let cases: Vec<(Method, usize)> = config
        .methods
        .iter()
        .flat_map(|&m| (0..problems.len()).map(move |p| (m, p)))
        .collect();

    // One counted, untimed solve per case: the counts are deterministic, and
    // the counting wrapper would otherwise weigh on the timings.
    let counted: Vec<(SolveReport, u64)> = cases
        .iter()
        .map(|&(method, p)| {
            let pr = &problems[p];
            let sys = Counted::new(&pr.system);
            let report = autobal::integrate::solve(
                method,
                &sys,
                0.0,
                &pr.y0,
                pr.t_end,
                &pr.options,
                &mut NoObserver,
            );
            (report, sys.calls())
        })
        .collect();
    let reference: Option<SolveReport> = config
        .reference_rtol
        .map(|rtol| BenchProblem::new(n, rtol, config.revolutions).solve(Method::Dp5))
        .filter(|r| r.status == Status::Finished);

    let repeats = config.solve_repeats.max(1);
    let mut times = vec![Vec::with_capacity(repeats); cases.len()];
    for _ in 0..repeats {
        for (i, &(method, p)) in cases.iter().enumerate() {
            let start = Instant::now();
            let report = black_box(problems[p].solve(method));
            times[i].push(start.elapsed().as_secs_f64() * 1e3);
            debug_assert_eq!(report.stats, counted[i].0.stats);
        }
    }

    cases
        .iter()
        .zip(counted)
        .zip(&times)
        .map(|((&(method, p), (report, calls)), t)| {
            let pr = &problems[p];
            let ms = median(t);
            let stats = report.stats;
            SolveCost {
                method,
                cargoes: n,
                rtol: pr.options.rtol,
                atol: pr.options.rtol * ATOL_PER_RTOL,
                revolutions: config.revolutions,
                t_end: pr.t_end,
                repeats,
                median_ms: ms,
                min_ms: t.iter().copied().fold(f64::INFINITY, f64::min),
                us_per_revolution: ms * 1e3 / config.revolutions,
                ns_per_rhs_call: ms * 1e6 / stats.rhs_calls.max(1) as f64,
                stats,
                counted_rhs_calls: calls,
                status: status_name(&report.status),
                error_vs_reference: reference.as_ref().map(|r| pr.scaled_error(&report.y, &r.y)),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_method_is_benchmarked() {
        // Exhaustive on purpose: a new Method variant stops this compiling
        // until it is added to METHODS.
        for &m in Method::ALL {
            match m {
                Method::Dp5 | Method::Dop853 | Method::Radau5 => assert!(METHODS.contains(&m)),
            }
        }
    }
}
