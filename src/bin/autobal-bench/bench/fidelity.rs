//! The `full` against the `rotating` fidelity on the isotropic reference
//! scene: the same answer, for how many fewer right-hand-side calls.

use super::median;
use super::problem::{reference_angles, reference_scene};
use autobal::metrics::MetricOptions;
use autobal::model::start::StartMode;
use autobal::simulation::{Fidelity, Simulation, SolverSettings};
use serde::Serialize;

/// One fidelity's cost and answer on the reference scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FidelityCost {
    /// "full" or "rotating".
    pub fidelity: String,
    /// Integrator used (auto without early stop: dp5 inertial, radau5 rotating).
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
                    atol: Some(rtol * 1e-2),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotating_frame_needs_ten_times_fewer_rhs_calls_over_a_long_run() {
        // Counts, not times: deterministic for a given build.
        let rows = measure_fidelities(10_000.0, 1e-6, 1);
        let (full, rotating) = (&rows[0], &rows[1]);
        assert_eq!(
            (full.fidelity.as_str(), rotating.fidelity.as_str()),
            ("full", "rotating")
        );
        assert_eq!(full.settling_revs, rotating.settling_revs, "same answer");
        let ratio = full.rhs_calls as f64 / rotating.rhs_calls as f64;
        assert!(ratio >= 10.0, "only {ratio:.1}× fewer RHS calls");
    }
}
