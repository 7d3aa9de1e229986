//! A speed sweep: one scene simulated at constant speed over a grid of
//! speeds, each point reported with seed 003's criterion (zero
//! approximation, and its closed form for the rotor on two supports), the
//! linear stability of the balanced state, and what the simulation did.

use crate::design::criterion::{dynamic_ranges, static_ranges};
use crate::metrics::Outcome;
use crate::model::linear::analyse;
use crate::model::rotor::RotorModel;
use crate::model::scene::SceneError;
use crate::model::speed::SpeedLaw;
use crate::model::zero_approx::criterion_margin;
use crate::simulation::Simulation;
use polars::prelude::*;
use rayon::prelude::*;
use serde::Serialize;

/// One speed of a sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepPoint {
    /// Speed ω (rad/s).
    pub omega: f64,
    /// Largest eigenvalue of the criterion's quadratic form (negative: balancing predicted).
    pub criterion_margin: f64,
    /// The criterion (zero approximation, computed for this rotor) predicts balancing.
    pub criterion: bool,
    /// Seed 003's closed-form ranges (static for one plane, dynamic for more), two-support rotors only.
    pub closed_form: Option<bool>,
    /// The balanced state is linearly stable (None: no balanced state or not analysable).
    pub linear_stable: Option<bool>,
    /// Slowest decay rate σ of the linearisation (1/s).
    pub slowest_decay: Option<f64>,
    /// The simulated run settled (balancing occurred).
    pub settled: bool,
    /// Outcome of the simulated run.
    pub outcome: Outcome,
    /// Settling time (s), if settled.
    pub settling_time: Option<f64>,
    /// Residual vibration over A_ref.
    pub residual_rel: f64,
    /// Balancing error ε at the end of the run.
    pub balancing_error: f64,
}

/// `points` speeds evenly spaced from `lo` to `hi` inclusive.
pub fn speed_grid(lo: f64, hi: f64, points: usize) -> Vec<f64> {
    match points {
        0 => Vec::new(),
        1 => vec![lo],
        _ => (0..points)
            .map(|i| lo + (hi - lo) * i as f64 / (points - 1) as f64)
            .collect(),
    }
}

/// The closed-form prediction of seed 003 for a two-support rotor at ω.
fn closed_form(rotor: &RotorModel, omega: f64) -> Option<bool> {
    let c = rotor.as_rotor().closed_form_criterion().ok()?;
    let p = c.params;
    let ranges = if c.planes.len() == 1 {
        static_ranges(&p, c.planes[0]).ok()?
    } else {
        dynamic_ranges(&p).ok()?
    };
    Some(ranges.contains(omega))
}

/// Simulate `template` at each speed (constant speed laws; runs in parallel,
/// results in speed order).
pub fn run_sweep(template: &Simulation, speeds: &[f64]) -> Result<Vec<SweepPoint>, SceneError> {
    speeds
        .par_iter()
        .with_max_len(1) // one simulation per job, as runs (study::run)
        .map(|&omega| {
            let mut sim = template.clone();
            sim.scene.speed = SpeedLaw::Constant { omega };
            let system = sim.scene.build()?;
            let margin = criterion_margin(&system, omega);
            let linear = analyse(&system, None).ok();
            let run = sim.run(false)?.metrics;
            Ok(SweepPoint {
                omega,
                criterion_margin: margin,
                criterion: margin < 0.0,
                closed_form: closed_form(&sim.scene.rotor, omega),
                linear_stable: linear.as_ref().map(|l| l.stable),
                slowest_decay: linear.as_ref().map(|l| l.slowest_decay),
                settled: run.settled,
                outcome: run.outcome,
                settling_time: run.settling_time,
                residual_rel: run.residual_rel,
                balancing_error: run.balancing_error,
            })
        })
        .collect()
}

/// The speed intervals (first, last grid speed) over which `holds` is true.
pub fn ranges(points: &[SweepPoint], holds: impl Fn(&SweepPoint) -> bool) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut start: Option<f64> = None;
    let mut last = 0.0;
    for p in points {
        match (holds(p), start) {
            (true, None) => start = Some(p.omega),
            (false, Some(s)) => {
                out.push((s, last));
                start = None;
            }
            _ => {}
        }
        last = p.omega;
    }
    if let Some(s) = start {
        out.push((s, last));
    }
    out
}

/// The sweep as a table, one row per speed.
pub fn to_dataframe(points: &[SweepPoint]) -> PolarsResult<DataFrame> {
    let col = |f: fn(&SweepPoint) -> f64| points.iter().map(f).collect::<Vec<f64>>();
    df!(
        "omega" => col(|p| p.omega),
        "criterion_margin" => col(|p| p.criterion_margin),
        "criterion" => points.iter().map(|p| p.criterion).collect::<Vec<bool>>(),
        "closed_form" => points.iter().map(|p| p.closed_form).collect::<Vec<Option<bool>>>(),
        "linear_stable" => points.iter().map(|p| p.linear_stable).collect::<Vec<Option<bool>>>(),
        "slowest_decay" => points.iter().map(|p| p.slowest_decay).collect::<Vec<Option<f64>>>(),
        "settled" => points.iter().map(|p| p.settled).collect::<Vec<bool>>(),
        "outcome" => points.iter().map(|p| p.outcome.name()).collect::<Vec<&str>>(),
        "settling_time" => points.iter().map(|p| p.settling_time).collect::<Vec<Option<f64>>>(),
        "residual_rel" => col(|p| p.residual_rel),
        "balancing_error" => col(|p| p.balancing_error),
    )
}
