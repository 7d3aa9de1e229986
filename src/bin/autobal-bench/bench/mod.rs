//! `autobal-bench`'s measurements: performance benchmarks of the ODE core.
//! Functions measure and return plain structs; `bench_cmd` prints them and
//! `docs/benchmarks.md` explains them.
//!
//! Timings are only meaningful relative to each other within one run: every
//! series is measured interleaved (round after round over all cases, medians
//! over the rounds), so that load from other processes hits all cases alike.
//! Counts (steps, RHS calls) are exact and deterministic.
//!
//! - [`problem`]: the reference scene and problem every series solves;
//! - [`rhs`]: the cost of one right-hand side against the cargo count;
//! - [`solve`]: the cost of whole solves per method and tolerance;
//! - [`fidelity`]: the rotating frame against the full model;
//! - [`peer`]: the cases the SciPy peer (`bench/scipy`) repeats;
//! - [`threads`]: a small study at several thread counts;
//! - [`lean_inputs`]: the main job's runs for the lean reference (`bench/lean`);
//! - [`looks`]: what racing's looks cost on the main job.

pub mod fidelity;
pub mod lean_inputs;
pub mod looks;
pub mod peer;
pub mod problem;
pub mod rhs;
pub mod solve;
pub mod threads;

use autobal::integrate::Method;
use problem::CARGO_COUNTS;
use rhs::{RhsScaling, measure_rhs};
use serde::Serialize;
use solve::{METHODS, RTOLS, SolveCost, measure_solves};

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
    autobal::stats::quantile::median(values).expect("every series times at least once")
}

#[cfg(test)]
mod tests {
    use super::*;
    use autobal::integrate::Method;

    /// The quick configuration trimmed further: one batch, one repeat, 10 revolutions.
    fn tiny() -> BenchConfig {
        BenchConfig {
            rhs_samples: 1,
            rhs_batch_us: 20,
            revolutions: 10.0,
            solve_repeats: 1,
            reference_rtol: Some(1e-11),
            ..BenchConfig::quick()
        }
    }

    #[test]
    fn bench_report_has_every_case_and_consistent_counts() {
        let report = run(&tiny());

        let ns: Vec<usize> = report.rhs.points.iter().map(|p| p.cargoes).collect();
        assert_eq!(ns, CARGO_COUNTS);
        for p in &report.rhs.points {
            assert_eq!(p.dim, 2 * (2 + p.cargoes));
            assert!(p.calls_per_batch >= 1 && p.batches == 1);
            assert!(p.ns_per_call > 0.0 && p.ns_per_call.is_finite());
        }
        assert!(report.rhs.fit.is_some());

        assert_eq!(report.solves.len(), METHODS.len() * RTOLS.len());
        for (i, s) in report.solves.iter().enumerate() {
            assert_eq!(s.method, METHODS[i / RTOLS.len()]);
            assert_eq!(s.rtol, RTOLS[i % RTOLS.len()]);
            assert_eq!(s.status, "finished");
            // The solver's statistics agree with a wrapper that counts the calls.
            assert_eq!(s.counted_rhs_calls, s.stats.rhs_calls, "{s:?}");
            if s.method == Method::Dp5 {
                // f(t0), one call for the initial step guess, six per attempted step (FSAL).
                assert_eq!(
                    s.stats.rhs_calls,
                    2 + 6 * (s.stats.steps + s.stats.rejected),
                    "{s:?}"
                );
                assert_eq!((s.stats.jacobians, s.stats.factorizations), (0, 0));
            }
            let err = s.error_vs_reference.unwrap();
            assert!(err < 100.0 * s.rtol, "error {err:e} at rtol {:e}", s.rtol);
        }
        for method in METHODS {
            let rows: Vec<_> = report
                .solves
                .iter()
                .filter(|s| s.method == *method)
                .collect();
            for w in rows.windows(2) {
                // RTOLS is decreasing: tighter tolerance, more steps, smaller error.
                assert!(w[1].stats.steps > w[0].stats.steps);
                assert!(w[1].error_vs_reference < w[0].error_vs_reference);
            }
        }
    }

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
