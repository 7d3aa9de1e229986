//! Performance benchmarks of the ODE core: the cost of one right-hand side as
//! the number of cargoes grows, and the cost of whole solves per method and
//! tolerance on the reference scene. Functions measure and return plain
//! structs; `study bench` prints them and `docs/benchmarks.md` explains them.
//!
//! Timings are only meaningful relative to each other within one run: every
//! series is measured interleaved (round after round over all cases, medians
//! over the rounds), so that load from other processes hits all cases alike.
//! Counts (steps, RHS calls) are exact and deterministic.
//!
//! No allocation is measured here: [`RotorSystem`]'s right-hand side keeps its
//! work arrays on the stack (fixed-size head block, cargo forces staged in
//! `dydt`), so its cost is pure arithmetic. `tests/alloc.rs` checks that with
//! a counting allocator, which only a test binary of its own may install.

use crate::integrate::{Method, NoObserver, OdeSystem, SolveReport, SolverOptions, Stats, Status};
use crate::metrics::reference::a_ref;
use crate::model::cargo::Cargo;
use crate::model::effect::Effects;
use crate::model::rotor::PlaneRotor;
use crate::model::scene::Scene;
use crate::model::speed::SpeedLaw;
use crate::model::start::{StartMode, initial_state};
use crate::model::system::RotorSystem;
use crate::simulation::scaled_atol;
use serde::Serialize;
use std::cell::Cell;
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Every integration method, in report order: extend when `Method` grows.
pub const METHODS: &[Method] = &[Method::Dp5, Method::Dop853, Method::Radau5];

/// Cargo counts of the right-hand-side scaling series.
pub const CARGO_COUNTS: &[usize] = &[1, 2, 4, 8, 16, 32, 64];

/// Relative tolerances of the solve series.
pub const RTOLS: &[f64] = &[1e-6, 1e-9];

/// Spin speed ω of the reference scene (four times the natural frequency).
pub const OMEGA: f64 = 4.0;

/// Absolute tolerance as a fraction of the relative one, on the problem's
/// scales (the pair 1e-6/1e-8 is the simulation default).
pub const ATOL_PER_RTOL: f64 = 1e-2;

/// What to measure and how often.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchConfig {
    /// Cargo counts n (each ≥ 1) of the right-hand-side series.
    pub cargo_counts: Vec<usize>,
    /// Timed batches per cargo count (the median is reported).
    pub rhs_samples: usize,
    /// Target wall time of one batch of RHS calls (µs); sets the calls per batch.
    pub rhs_batch_us: u64,
    /// Cargoes in the solve series.
    pub solve_cargoes: usize,
    /// Methods in the solve series.
    pub methods: Vec<Method>,
    /// Relative tolerances in the solve series.
    pub rtols: Vec<f64>,
    /// Horizon of every solve in revolutions (no early stopping).
    pub revolutions: f64,
    /// Timed solves per case (the median is reported).
    pub solve_repeats: usize,
    /// Relative tolerance of the reference solve for the accuracy column (none: skipped).
    pub reference_rtol: Option<f64>,
}

impl BenchConfig {
    /// The full benchmark behind `docs/benchmarks.md` (seconds in release builds).
    pub fn full() -> Self {
        BenchConfig {
            cargo_counts: CARGO_COUNTS.to_vec(),
            rhs_samples: 21,
            rhs_batch_us: 2_000,
            solve_cargoes: 3,
            methods: METHODS.to_vec(),
            rtols: RTOLS.to_vec(),
            revolutions: 500.0,
            solve_repeats: 11,
            reference_rtol: Some(1e-12),
        }
    }

    /// A fast smoke run with the same structure (for tests and quick looks).
    pub fn quick() -> Self {
        BenchConfig {
            rhs_samples: 3,
            rhs_batch_us: 100,
            revolutions: 20.0,
            solve_repeats: 3,
            reference_rtol: Some(1e-11),
            ..BenchConfig::full()
        }
    }
}

/// The reference scene with `n` identical point cargoes (`scenes/three_balls.toml` for n = 3).
pub fn reference_scene(n: usize) -> Scene {
    Scene {
        rotor: PlaneRotor::isotropic(1.0, 0.01, 1.0, 0.1).into(),
        balancers: Vec::new(),
        balancer: None,
        cargo: vec![Cargo::point(0.01, 1.0, 0.01, 1.4); n],
        speed: SpeedLaw::Constant { omega: OMEGA },
        effects: Effects::default(),
    }
}

/// Initial cargo angles 90°, 100°, 110°, … (rad) of the reference scene.
pub fn reference_angles(n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| (90.0 + 10.0 * j as f64).to_radians())
        .collect()
}

/// One benchmark problem: the assembled system, its start and its tolerances.
#[derive(Debug)]
pub struct BenchProblem {
    /// The equations.
    pub system: RotorSystem,
    /// Initial state (`locked_steady` at [`reference_angles`]).
    pub y0: Vec<f64>,
    /// Solver options with per-component absolute tolerances.
    pub options: SolverOptions,
    /// Horizon in time units.
    pub t_end: f64,
}

impl BenchProblem {
    /// The reference problem with `n` cargoes at `rtol`, over `revolutions`.
    pub fn new(n: usize, rtol: f64, revolutions: f64) -> Self {
        let system = reference_scene(n)
            .build()
            .expect("the reference scene is valid");
        let y0 = initial_state(&system, StartMode::LockedSteady, &reference_angles(n));
        let atol = scaled_atol(&system, rtol * ATOL_PER_RTOL, a_ref(&system, OMEGA), OMEGA);
        let options = SolverOptions {
            rtol,
            atol,
            max_steps: u64::MAX,
            ..SolverOptions::default()
        };
        BenchProblem {
            system,
            y0,
            options,
            t_end: revolutions * 2.0 * PI / OMEGA,
        }
    }

    /// Solve with `method` and no observer.
    pub fn solve(&self, method: Method) -> SolveReport {
        crate::integrate::solve(
            method,
            &self.system,
            0.0,
            &self.y0,
            self.t_end,
            &self.options,
            &mut NoObserver,
        )
    }

    /// Largest difference to `reference` in units of the problem's scales
    /// (A_ref for displacements, A_ref·ω for velocities, rad, rad·ω).
    pub fn scaled_error(&self, y: &[f64], reference: &[f64]) -> f64 {
        let scale = scaled_atol(&self.system, 1.0, a_ref(&self.system, OMEGA), OMEGA);
        y.iter()
            .zip(reference)
            .zip(&scale)
            .map(|((a, b), s)| (a - b).abs() / s)
            .fold(0.0, f64::max)
    }
}

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
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.calls.set(self.calls.get() + 1);
        self.inner.rhs(t, y, dydt);
    }
}

/// Cost of one right-hand-side call with n cargoes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RhsCost {
    /// Number of cargoes n.
    pub cargoes: usize,
    /// State dimension 2·(2 + n).
    pub dim: usize,
    /// Calls per timed batch.
    pub calls_per_batch: u64,
    /// Timed batches.
    pub batches: usize,
    /// Median over batches of the time per call (ns).
    pub ns_per_call: f64,
    /// Fastest batch's time per call (ns).
    pub min_ns_per_call: f64,
    /// Median time per call divided by n (ns).
    pub ns_per_call_per_cargo: f64,
}

/// Least-squares line ns_per_call ≈ intercept + slope·n.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinearFit {
    /// Fixed cost per call (ns).
    pub intercept_ns: f64,
    /// Cost per cargo per call (ns).
    pub slope_ns_per_cargo: f64,
    /// Coefficient of determination R².
    pub r_squared: f64,
    /// Largest |measured − fitted| / measured over the points.
    pub max_rel_residual: f64,
}

/// The right-hand-side scaling series and its linear fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RhsScaling {
    /// One entry per cargo count, in the order asked.
    pub points: Vec<RhsCost>,
    /// Line through the medians (`None` with fewer than two distinct counts).
    pub fit: Option<LinearFit>,
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

/// Everything one benchmark run measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchReport {
    /// What was asked.
    pub config: BenchConfig,
    /// True for a build with debug assertions (timings then mean little).
    pub debug_build: bool,
    /// Right-hand-side cost per cargo count.
    pub rhs: RhsScaling,
    /// One entry per (method, rtol), methods outer.
    pub solves: Vec<SolveCost>,
}

/// Run the whole benchmark.
pub fn run(config: &BenchConfig) -> BenchReport {
    BenchReport {
        config: config.clone(),
        debug_build: cfg!(debug_assertions),
        rhs: measure_rhs(
            &config.cargo_counts,
            config.rhs_samples,
            config.rhs_batch_us,
        ),
        solves: measure_solves(config),
    }
}

/// Median of a non-empty slice (sorted copy; mean of the middle pair when even).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// Time per RHS call for each cargo count, batches interleaved across counts.
pub fn measure_rhs(cargo_counts: &[usize], samples: usize, batch_us: u64) -> RhsScaling {
    let samples = samples.max(1);
    let cases: Vec<(RotorSystem, Vec<f64>)> = cargo_counts
        .iter()
        .map(|&n| {
            let p = BenchProblem::new(n, 1e-6, 1.0);
            (p.system, p.y0)
        })
        .collect();
    let mut dydt: Vec<Vec<f64>> = cases.iter().map(|(_, y)| vec![0.0; y.len()]).collect();
    let target = Duration::from_micros(batch_us.max(1));
    let calls: Vec<u64> = cases
        .iter()
        .zip(&mut dydt)
        .map(|((s, y), d)| calibrate(s, y, d, target))
        .collect();
    let mut per_call = vec![Vec::with_capacity(samples); cases.len()];
    for _ in 0..samples {
        for (i, (system, y)) in cases.iter().enumerate() {
            let elapsed = time_rhs(system, y, &mut dydt[i], calls[i]);
            per_call[i].push(elapsed.as_nanos() as f64 / calls[i] as f64);
        }
    }
    let points: Vec<RhsCost> = cargo_counts
        .iter()
        .zip(&cases)
        .zip(calls.iter().zip(&per_call))
        .map(|((&n, (_, y)), (&c, times))| {
            let ns = median(times);
            RhsCost {
                cargoes: n,
                dim: y.len(),
                calls_per_batch: c,
                batches: samples,
                ns_per_call: ns,
                min_ns_per_call: times.iter().copied().fold(f64::INFINITY, f64::min),
                ns_per_call_per_cargo: ns / n.max(1) as f64,
            }
        })
        .collect();
    let fit = linear_fit(
        &points
            .iter()
            .map(|p| (p.cargoes as f64, p.ns_per_call))
            .collect::<Vec<_>>(),
    );
    RhsScaling { points, fit }
}

/// Calls per batch so that one batch takes about `target`.
fn calibrate(system: &RotorSystem, y: &[f64], dydt: &mut [f64], target: Duration) -> u64 {
    let mut calls = 16;
    loop {
        let elapsed = time_rhs(system, y, dydt, calls);
        if elapsed >= target || calls >= 1 << 30 {
            let scale = target.as_secs_f64() / elapsed.as_secs_f64().max(1e-9);
            return ((calls as f64 * scale).ceil() as u64).max(1);
        }
        calls *= 4;
    }
}

fn time_rhs(system: &RotorSystem, y: &[f64], dydt: &mut [f64], calls: u64) -> Duration {
    let start = Instant::now();
    for i in 0..calls {
        // black_box on t and y keeps the compiler from hoisting the call out of the loop.
        system.rhs(black_box(i as f64 * 1e-3), black_box(y), dydt);
        black_box(&mut *dydt);
    }
    start.elapsed()
}

/// Ordinary least squares y ≈ a + b x; `None` without two distinct x.
pub fn linear_fit(points: &[(f64, f64)]) -> Option<LinearFit> {
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let ss_res: f64 = points
        .iter()
        .map(|p| (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    Some(LinearFit {
        intercept_ns: intercept,
        slope_ns_per_cargo: slope,
        r_squared: if syy > 0.0 { 1.0 - ss_res / syy } else { 1.0 },
        max_rel_residual: points
            .iter()
            .map(|p| ((p.1 - intercept - slope * p.0) / p.1).abs())
            .fold(0.0, f64::max),
    })
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
            let report = crate::integrate::solve(
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

fn status_name(status: &Status) -> String {
    match status {
        Status::Finished => "finished".into(),
        Status::Stopped => "stopped".into(),
        Status::Failed(f) => format!("failed: {f}"),
    }
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

    #[test]
    fn linear_fit_recovers_a_line() {
        let pts: Vec<(f64, f64)> = (1..6).map(|x| (x as f64, 3.0 + 2.0 * x as f64)).collect();
        let fit = linear_fit(&pts).unwrap();
        assert!((fit.intercept_ns - 3.0).abs() < 1e-12);
        assert!((fit.slope_ns_per_cargo - 2.0).abs() < 1e-12);
        assert!((fit.r_squared - 1.0).abs() < 1e-12);
        assert!(linear_fit(&[(1.0, 2.0)]).is_none());
    }

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
