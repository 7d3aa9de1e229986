//! The solves `bench/scipy` repeats with SciPy's `solve_ivp`, timed here,
//! with everything the peer needs to check its own translation and answers.

use super::median;
use super::problem::{BenchProblem, OMEGA, status_name};
use autobal::integrate::{Method, OdeSystem, SolveReport, Stats};
use autobal::metrics::reference::a_ref;
use autobal::simulation::scaled_atol;
use serde::Serialize;
use std::hint::black_box;
use std::time::Instant;

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
    /// Relative tolerances (atol = rtol·[`super::problem::ATOL_PER_RTOL`] on the problem's scales).
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
    /// Initial state (`locked_steady` at [`super::problem::reference_angles`]).
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

#[cfg(test)]
mod tests {
    use super::super::problem::{ATOL_PER_RTOL, reference_scene};
    use super::*;

    #[test]
    fn peer_cases_export_what_the_scipy_peer_needs() {
        let config = PeerConfig {
            revolutions: 5.0,
            repeats: 1,
            ..PeerConfig::quick()
        };
        let r = peer_cases(&config);
        let dim = 2 * (2 + config.cargoes);
        assert_eq!((r.y0.len(), r.scale.len()), (dim, dim));
        assert_eq!(r.cases.len(), PEER_METHODS.len() * PEER_RTOLS.len());
        for (i, c) in r.cases.iter().enumerate() {
            assert_eq!(c.method, PEER_METHODS[i / PEER_RTOLS.len()]);
            assert_eq!(c.rtol, PEER_RTOLS[i % PEER_RTOLS.len()]);
            assert_eq!(c.status, "finished");
            assert_eq!(
                (c.atol.len(), c.y_final.len(), c.times_ms.len()),
                (dim, dim, 1)
            );
            // atol is rtol/100 on the scales that the peer recomputes.
            for (a, s) in c.atol.iter().zip(&r.scale) {
                assert!((a / (c.rtol * ATOL_PER_RTOL * s) - 1.0).abs() < 1e-12);
            }
            assert!(c.error_vs_reference < 100.0 * c.rtol, "{c:?}");
        }
        assert!(
            r.reference.cross_check < 1e-9,
            "{:?}",
            r.reference.cross_check
        );
        // The exported RHS samples are the system's own values (the peer checks against them).
        let system = reference_scene(config.cargoes).build().unwrap();
        assert_eq!(r.rhs_samples.len(), 3);
        assert_eq!(r.rhs_samples[0].y, r.y0);
        assert_eq!(r.rhs_samples[2].t, r.t_end);
        for s in &r.rhs_samples {
            let mut d = vec![0.0; dim];
            system.rhs(s.t, &s.y, &mut d);
            assert_eq!(d, s.dydt);
        }
    }
}
