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

/// Median of timings, of which every series has at least one.
pub fn median(values: &[f64]) -> f64 {
    crate::stats::quantile::median(values).expect("every series times at least once")
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

/// Relative tolerances of the comparison with SciPy's `solve_ivp` (`bench/scipy`).
pub const PEER_RTOLS: &[f64] = &[1e-6, 1e-8, 1e-9];

/// autobal's methods in the SciPy comparison: `dp5` matches RK45, `dop853` matches DOP853.
pub const PEER_METHODS: &[Method] = &[Method::Dp5, Method::Dop853];

/// The solves that `bench/scipy` repeats in Python, and how often to time them here.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeerConfig {
    /// Number of cargoes.
    pub cargoes: usize,
    /// autobal methods to time.
    pub methods: Vec<Method>,
    /// Relative tolerances (atol = rtol·[`ATOL_PER_RTOL`] on the problem's scales).
    pub rtols: Vec<f64>,
    /// Horizon in revolutions (no early stopping).
    pub revolutions: f64,
    /// Timed solves per case, interleaved across cases.
    pub repeats: usize,
    /// Relative tolerance of the DOP853 reference solve.
    pub reference_rtol: f64,
}

impl PeerConfig {
    /// The comparison recorded in `docs/benchmarks.md`.
    pub fn full() -> Self {
        PeerConfig {
            cargoes: 3,
            methods: PEER_METHODS.to_vec(),
            rtols: PEER_RTOLS.to_vec(),
            revolutions: 500.0,
            repeats: 11,
            reference_rtol: 1e-13,
        }
    }

    /// Same cases over a short horizon with few repeats (tests, smoke runs).
    pub fn quick() -> Self {
        PeerConfig {
            revolutions: 20.0,
            repeats: 3,
            ..PeerConfig::full()
        }
    }
}

/// One evaluation of the right-hand side, so that a peer can check its own
/// translation of the equations against autobal's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RhsSample {
    /// Time.
    pub t: f64,
    /// State.
    pub y: Vec<f64>,
    /// autobal's dy/dt at (t, y).
    pub dydt: Vec<f64>,
}

/// The tight solve that every case (and every peer) is compared with.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeerReference {
    /// Method of the reference solve.
    pub method: Method,
    /// Its relative tolerance.
    pub rtol: f64,
    /// Its final state at t_end.
    pub y: Vec<f64>,
    /// Largest scaled difference to a DP5 solve at rtol 10·`rtol` (how far the reference can be trusted).
    pub cross_check: f64,
}

/// Timings, counts and final state of one (method, rtol) case.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeerCase {
    /// Integration method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance per state component.
    pub atol: Vec<f64>,
    /// Every timed solve (ms), in the order measured.
    pub times_ms: Vec<f64>,
    /// Median wall time per solve (ms).
    pub median_ms: f64,
    /// Fastest solve (ms).
    pub min_ms: f64,
    /// The solver's statistics.
    pub stats: Stats,
    /// Final status ("finished" or the failure).
    pub status: String,
    /// State at t_end.
    pub y_final: Vec<f64>,
    /// Largest final-state difference to the reference, in scale units.
    pub error_vs_reference: f64,
}

/// What `bench/scipy` needs to repeat autobal's solves and judge its own.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeerReport {
    /// What was asked.
    pub config: PeerConfig,
    /// True for a build with debug assertions (timings then mean little).
    pub debug_build: bool,
    /// Spin speed ω.
    pub omega: f64,
    /// Horizon in time units (from t = 0).
    pub t_end: f64,
    /// Initial state (`locked_steady` at [`reference_angles`]).
    pub y0: Vec<f64>,
    /// Unit of each state component for errors: A_ref, A_ref·ω, rad, rad·ω.
    pub scale: Vec<f64>,
    /// Right-hand side at a few states (start, a moving state, the reference end).
    pub rhs_samples: Vec<RhsSample>,
    /// The tight reference solve.
    pub reference: PeerReference,
    /// One entry per (method, rtol), methods outer.
    pub cases: Vec<PeerCase>,
}

/// Time autobal's solves of the cases `bench/scipy` repeats with SciPy, and
/// export everything the peer needs to check itself (start, tolerances,
/// right-hand-side samples, reference and final states).
pub fn peer_cases(config: &PeerConfig) -> PeerReport {
    let n = config.cargoes;
    let base = BenchProblem::new(n, config.reference_rtol, config.revolutions);
    let reference = base.solve(Method::Dop853);
    let cross =
        BenchProblem::new(n, 10.0 * config.reference_rtol, config.revolutions).solve(Method::Dp5);
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
    // The untimed first solve of each case also warms caches and branch predictors.
    let results: Vec<SolveReport> = cases.iter().map(|&(m, p)| problems[p].solve(m)).collect();
    let repeats = config.repeats.max(1);
    let mut times = vec![Vec::with_capacity(repeats); cases.len()];
    for _ in 0..repeats {
        for (i, &(method, p)) in cases.iter().enumerate() {
            let start = Instant::now();
            black_box(problems[p].solve(method));
            times[i].push(start.elapsed().as_secs_f64() * 1e3);
        }
    }

    let sample = |t: f64, y: Vec<f64>| {
        let mut dydt = vec![0.0; y.len()];
        base.system.rhs(t, &y, &mut dydt);
        RhsSample { t, y, dydt }
    };
    // A state with every term awake: rotor off-centre and moving, cargoes
    // spread and sliding at different rates.
    let nq = base.system.layout().nq();
    let mut moving = base.y0.clone();
    for j in 0..n {
        moving[2 + j] += 0.3 * (j as f64 + 1.0);
        moving[nq + 2 + j] = 0.05 * (j as f64 - 1.0);
    }
    moving[nq] *= -0.7;
    moving[nq + 1] *= 1.3;
    let rhs_samples = vec![
        sample(0.0, base.y0.clone()),
        sample(1.234, moving),
        sample(base.t_end, reference.y.clone()),
    ];

    PeerReport {
        config: config.clone(),
        debug_build: cfg!(debug_assertions),
        omega: OMEGA,
        t_end: base.t_end,
        y0: base.y0.clone(),
        scale: scaled_atol(&base.system, 1.0, a_ref(&base.system, OMEGA), OMEGA),
        rhs_samples,
        reference: PeerReference {
            method: Method::Dop853,
            rtol: config.reference_rtol,
            cross_check: base.scaled_error(&cross.y, &reference.y),
            y: reference.y.clone(),
        },
        cases: cases
            .iter()
            .zip(results)
            .zip(&times)
            .map(|((&(method, p), report), t)| PeerCase {
                method,
                rtol: problems[p].options.rtol,
                atol: problems[p].options.atol.clone(),
                times_ms: t.clone(),
                median_ms: median(t),
                min_ms: t.iter().copied().fold(f64::INFINITY, f64::min),
                stats: report.stats,
                status: status_name(&report.status),
                error_vs_reference: base.scaled_error(&report.y, &reference.y),
                y_final: report.y,
            })
            .collect(),
    }
}

/// The study behind the thread-scaling measurement (`studies/three_balls.toml`,
/// with its samples cut down by [`ThreadConfig::samples`]).
pub const THREAD_STUDY: &str = include_str!("../studies/three_balls.toml");

/// How the thread-scaling measurement runs [`THREAD_STUDY`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThreadConfig {
    /// Samples per design (the file's 20 designs each get this many runs).
    pub samples: u32,
    /// Thread counts to compare; the first is the baseline of the speed-ups.
    pub thread_counts: Vec<usize>,
    /// Timed studies per thread count, interleaved (ABBA order).
    pub repeats: usize,
}

impl ThreadConfig {
    /// The measurement recorded in `docs/benchmarks.md`: 1 against 2 threads.
    pub fn full() -> Self {
        ThreadConfig {
            samples: 25,
            thread_counts: vec![1, 2],
            repeats: 7,
        }
    }

    /// One sample per design and one repeat (tests, smoke runs).
    pub fn quick() -> Self {
        ThreadConfig {
            samples: 1,
            repeats: 1,
            ..ThreadConfig::full()
        }
    }
}

/// Wall times of the study at one thread count.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThreadTiming {
    /// Worker threads of the study's pool.
    pub threads: usize,
    /// Every timed study (s), in the order measured.
    pub times_s: Vec<f64>,
    /// Median wall time (s).
    pub median_s: f64,
    /// Fastest study (s).
    pub min_s: f64,
    /// Speed-up over the baseline: ratio of medians.
    pub speedup: f64,
    /// Speed-up over the baseline: median of the per-round ratios (robust to drifting load).
    pub paired_speedup: f64,
    /// Speed-up over the baseline: ratio of the fastest studies.
    pub speedup_min: f64,
    /// CPU time (user + system, all threads) of every timed study (s); empty where unknown.
    pub cpu_s: Vec<f64>,
    /// Median over the studies of CPU time / wall time: the cores the study
    /// actually got (at most `threads`; less when other processes hold cores).
    pub cores_used: Option<f64>,
}

/// How `run_study` scales with its thread count on a fixed small study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThreadScaling {
    /// What was asked.
    pub config: ThreadConfig,
    /// True for a build with debug assertions (timings then mean little).
    pub debug_build: bool,
    /// Name of the study.
    pub study: String,
    /// Designs in the study.
    pub designs: usize,
    /// Runs per study (designs × samples).
    pub runs: u64,
    /// RHS calls summed over the runs (the work, identical for every thread count).
    pub rhs_calls: u64,
    /// Threads the operating system offers this process.
    pub available_parallelism: usize,
    /// Load averages (1, 5, 15 min) before measuring (Linux only).
    pub load_before: Option<[f64; 3]>,
    /// Load averages after measuring.
    pub load_after: Option<[f64; 3]>,
    /// True when every thread count produced the same records (wall time aside).
    pub identical_results: bool,
    /// One entry per thread count, in the order asked.
    pub timings: Vec<ThreadTiming>,
}

/// The cut-down [`THREAD_STUDY`] writing under `output`.
pub fn thread_study(samples: u32, output: &std::path::Path) -> crate::study::config::StudyPlan {
    use crate::study::config::StudyFile;
    let path = "studies/three_balls.toml";
    let mut file = StudyFile::parse(THREAD_STUDY, path).expect("the bundled study parses");
    file.sampling.samples = samples.max(1);
    file.output = output.display().to_string();
    // The provenance text says what was changed, so the files are not mistaken for the real study.
    let text = format!(
        "{THREAD_STUDY}\n# study bench --thread-scaling: sampling.samples = {}\n",
        file.sampling.samples
    );
    file.plan(&text, path).expect("the bundled study is valid")
}

/// Run [`thread_study`] at every thread count of `config`, interleaved, with
/// its files under `output` (overwritten by every repeat).
pub fn measure_threads(
    config: &ThreadConfig,
    output: &std::path::Path,
) -> Result<ThreadScaling, crate::study::run::RunError> {
    use crate::study::run::{NoProgress, RunOptions, run_study};
    let plan = thread_study(config.samples, output);
    let counts = &config.thread_counts;
    let repeats = config.repeats.max(1);
    let load_before = load_average();
    let mut times = vec![Vec::with_capacity(repeats); counts.len()];
    let mut cpu = vec![Vec::with_capacity(repeats); counts.len()];
    let mut records: Vec<Option<Vec<crate::study::record::RunRecord>>> = vec![None; counts.len()];
    for round in 0..repeats {
        // ABBA: a drifting background load then favours no thread count.
        let order: Vec<usize> = if round % 2 == 0 {
            (0..counts.len()).collect()
        } else {
            (0..counts.len()).rev().collect()
        };
        for i in order {
            let options = RunOptions {
                threads: Some(counts[i].max(1)),
                ..RunOptions::default()
            };
            let cpu_start = process_cpu_seconds();
            let start = Instant::now();
            let out = run_study(&plan, &options, &NoProgress)?;
            times[i].push(start.elapsed().as_secs_f64());
            if let (Some(a), Some(b)) = (cpu_start, process_cpu_seconds()) {
                cpu[i].push(b - a);
            }
            records[i].get_or_insert_with(|| {
                out.runs
                    .into_iter()
                    .map(|mut r| {
                        r.wall_time_s = 0.0;
                        r
                    })
                    .collect()
            });
        }
    }
    let load_after = load_average();
    let base = &times[0];
    let base_median = median(base);
    let base_min = base.iter().copied().fold(f64::INFINITY, f64::min);
    let timings = counts
        .iter()
        .zip(&times)
        .zip(cpu)
        .map(|((&threads, t), cpu_s)| {
            let min_s = t.iter().copied().fold(f64::INFINITY, f64::min);
            let paired: Vec<f64> = base.iter().zip(t).map(|(b, x)| b / x).collect();
            ThreadTiming {
                threads,
                times_s: t.clone(),
                median_s: median(t),
                min_s,
                speedup: base_median / median(t),
                paired_speedup: median(&paired),
                speedup_min: base_min / min_s,
                cores_used: (cpu_s.len() == t.len())
                    .then(|| median(&cpu_s.iter().zip(t).map(|(c, w)| c / w).collect::<Vec<_>>())),
                cpu_s,
            }
        })
        .collect();
    let first = records[0].as_deref().unwrap_or_default();
    Ok(ThreadScaling {
        config: config.clone(),
        debug_build: cfg!(debug_assertions),
        study: plan.name.clone(),
        designs: plan.designs.len(),
        runs: plan.total_runs(),
        rhs_calls: first.iter().map(|r| r.metrics.rhs_calls).sum(),
        available_parallelism: std::thread::available_parallelism().map_or(1, usize::from),
        load_before,
        load_after,
        identical_results: records.iter().all(|r| r.as_deref() == Some(first)),
        timings,
    })
}

/// CPU time (user + system) of this process and all its threads so far, in
/// seconds, from `/proc/self/stat` (`None` elsewhere). Resolution is one
/// clock tick, 10 ms at the usual 100 Hz, which is assumed: reading the real
/// rate would need libc.
pub fn process_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The command name may contain spaces; fields after it start at field 3 (state).
    let rest = &text[text.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    Some((ticks(11)? + ticks(12)?) / 100.0)
}

/// The 1, 5 and 15 minute load averages from `/proc/loadavg` (`None` elsewhere).
pub fn load_average() -> Option<[f64; 3]> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut it = text.split_whitespace().map(|s| s.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
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
}

/// One fidelity's cost and answer on the reference scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FidelityCost {
    /// "full" or "rotating".
    pub fidelity: String,
    /// Integrator used (auto pairing: dp5 inertial, radau5 rotating).
    pub method: String,
    /// Right-hand-side calls.
    pub rhs_calls: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Median wall time per run (s).
    pub wall_s: f64,
    /// Settling time (revolutions).
    pub settling_revs: Option<f64>,
    /// Residual vibration at the end / A_ref.
    pub residual_rel: f64,
}

/// `full` versus `rotating` on the isotropic reference scene over a fixed
/// horizon without early stop, at rtol `rtol`, each with the default method.
pub fn measure_fidelities(revolutions: f64, rtol: f64, repeats: usize) -> Vec<FidelityCost> {
    use crate::metrics::MetricOptions;
    use crate::model::start::StartMode;
    use crate::simulation::{Fidelity, Simulation, SolverSettings};
    [Fidelity::Full, Fidelity::Rotating]
        .into_iter()
        .map(|fidelity| {
            let sim = Simulation {
                scene: reference_scene(3),
                start: StartMode::LockedSteady,
                initial_angles: reference_angles(3),
                solver: SolverSettings {
                    fidelity,
                    rtol,
                    atol: rtol * 1e-2,
                    ..SolverSettings::default()
                },
                metrics: MetricOptions {
                    t_end_revs: revolutions,
                    stop_when_settled: false,
                    ..MetricOptions::default()
                },
            };
            let mut times = Vec::with_capacity(repeats.max(1));
            let mut last = None;
            for _ in 0..repeats.max(1) {
                let clock = std::time::Instant::now();
                let m = sim
                    .run(false)
                    .expect("the reference scene is valid")
                    .metrics;
                times.push(clock.elapsed().as_secs_f64());
                last = Some(m);
            }
            let m = last.expect("at least one repeat");
            FidelityCost {
                fidelity: fidelity.name().to_string(),
                method: m.method.clone(),
                rhs_calls: m.rhs_calls,
                steps: m.steps,
                wall_s: median(&times),
                settling_revs: m.settling_revs,
                residual_rel: m.residual_rel,
            }
        })
        .collect()
}
