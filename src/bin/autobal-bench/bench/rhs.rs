//! The cost of one right-hand-side call as the number of cargoes grows, and
//! the line through it: a fixed cost per call plus a cost per cargo.
//!
//! No allocation is measured here: `RotorSystem`'s right-hand side keeps its
//! work arrays on the stack (fixed-size head block, cargo forces staged in
//! `dydt`), so its cost is pure arithmetic. `tests/alloc.rs` checks that with
//! a counting allocator, which only a test binary of its own may install.

use super::median;
use super::problem::BenchProblem;
use autobal::integrate::OdeSystem;
use autobal::model::system::RotorSystem;
use serde::Serialize;
use std::hint::black_box;
use std::time::{Duration, Instant};

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

#[cfg(test)]
mod tests {
    use super::*;

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
