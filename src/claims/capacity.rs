//! Claim 1 by simulation: weights of finite size (the contact effect) pressed
//! together by an unbalance they cannot cancel carry exactly their capacity;
//! scanning ρ shows where it peaks, next to Table 1 and half-race fill.

use super::normalisation::design_capacity;
use crate::design::geometry::{rho_half_race, rho_max};
use crate::design::optimum::optimal_rho;
use crate::model::balancer::Kind;
use crate::model::effect::contact::ContactSpec;
use crate::model::scene::{DesignSpec, RhoChoice};
use crate::model::start::StartMode;
use crate::simulation::Simulation;
use crate::study::plan::config::StudyPlan;
use rayon::prelude::*;
use serde::Serialize;

/// Analytic and simulated capacity of one (kind, n, ρ).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CapacityPoint {
    /// Balancer kind.
    pub kind: Kind,
    /// Number of weights.
    pub n: u32,
    /// Radius ratio.
    pub rho: f64,
    /// S_AB of eq 5 (kg·m).
    pub analytic: f64,
    /// |Σ m l e^{iψ}| at the end of a run with an unbalance of 1.5 n m l (kg·m).
    pub simulated: f64,
}

/// Points of the ρ scan for n weights: a grid up to 98 % of ρ_max plus the
/// Table-1 optimum and the half-race radius.
fn scan(kind: Kind, n: u32) -> Vec<f64> {
    let top = 0.98 * rho_max(n).unwrap_or(0.5).min(0.5);
    let mut v: Vec<f64> = (1..=10).map(|i| top * f64::from(i) / 10.0).collect();
    if let Ok(o) = optimal_rho(kind.model().shape(), n) {
        v.push(o.rho);
    }
    if let Ok(h) = rho_half_race(n) {
        v.push(h);
    }
    v.sort_by(f64::total_cmp);
    v
}

/// Run the capacity scan for every kind of the plan and each n.
pub fn capacity_experiment(base: &StudyPlan, ns: &[u32]) -> Vec<CapacityPoint> {
    let g = &base.file.designs;
    let drag = g.drag.values()[0];
    let points: Vec<(Kind, u32, f64)> = g
        .kind
        .values()
        .into_iter()
        .filter(|k| *k != Kind::Pendulum)
        .flat_map(|k| {
            ns.iter()
                .flat_map(move |&n| scan(k, n).into_iter().map(move |r| (k, n, r)))
        })
        .collect();
    points
        .par_iter()
        .with_max_len(1) // one simulation per job, as runs (study::run)
        .filter_map(|&(kind, n, rho)| {
            let spec = DesignSpec {
                kind,
                n,
                rho: RhoChoice::Value(rho),
                race_radius: g.race_radius,
                density: g.density,
                roller_height: g.roller_height,
                drag,
                plane: 0,
            };
            let design = base.file.resolve_design(0, spec).ok()?;
            let ml = design.weight_mass * design.track_radius;
            let mut scene = base.scene(&design, 1.5 * f64::from(n) * ml, 0.0);
            scene.effects.contact = Some(ContactSpec::default());
            // Start spread around 90° so the weights must travel and press together.
            let angles = (0..n)
                .map(|j| (90.0 + 25.0 * f64::from(j)).to_radians())
                .collect();
            let mut metrics = base.file.metrics.clone();
            metrics.stop_when_settled = false;
            metrics.t_end_revs = metrics.t_end_revs.min(400.0);
            let sim = Simulation {
                scene,
                start: StartMode::LockedSteady,
                initial_angles: angles,
                solver: base.file.solver.clone(),
                metrics,
            };
            let m = sim.run(false).ok()?.metrics;
            let (sx, sy) = m.final_rel_angles_deg.iter().fold((0.0, 0.0), |(x, y), a| {
                let r = a.to_radians();
                (x + ml * r.cos(), y + ml * r.sin())
            });
            Some(CapacityPoint {
                kind,
                n,
                rho,
                analytic: design_capacity(g, kind, n, rho)?,
                simulated: sx.hypot(sy),
            })
        })
        .collect()
}
