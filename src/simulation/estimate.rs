//! The two rungs of the fidelity ladder that are not integrated: the
//! closed-form slow mode (`analytic`) and the eigenvalues of the balanced
//! state (`linear`), each giving a settling estimate and nothing it cannot.

use super::Simulation;
use crate::metrics::{Outcome, RunMetrics};
use crate::model::quasi_static::slow_mode;
use crate::model::system::RotorSystem;
use std::f64::consts::PI;

impl Simulation {
    /// The linearised estimate: settled when the balanced state is stable,
    /// with t_s = ln((r₀/A_ref)/δ)/σ from the run's initial amplitude r₀.
    pub(super) fn linear(&self, system: &RotorSystem, y0: &[f64], omega: f64) -> RunMetrics {
        let mut m = self.analytic_base(system, omega);
        m.method = "eigenvalues".into();
        match crate::model::linear::analyse(system, None) {
            Ok(report) if report.stable && report.slowest_decay > 0.0 => {
                let r0 = y0[0].hypot(y0[1]) / m.a_ref;
                let delta = self.metrics.delta;
                let t = (r0.max(delta) / delta).ln() / report.slowest_decay;
                let rev = 2.0 * PI / omega;
                RunMetrics {
                    settled: true,
                    settling_time: Some(t),
                    settling_revs: Some(t / rev),
                    hold_complete: true,
                    hold_certified: false,
                    outcome: Outcome::Settled,
                    reason: format!(
                        "linear estimate ln((r0/A_ref)/δ)/σ with σ = {:.4e} 1/s ({} neutral directions set aside)",
                        report.slowest_decay, report.neutral
                    ),
                    ..m
                }
            }
            Ok(report) => RunMetrics {
                reason: format!(
                    "linear: the balanced state is unstable (σ = {:.3e} 1/s)",
                    report.slowest_decay
                ),
                ..m
            },
            Err(e) => RunMetrics {
                reason: format!("linear: {e}"),
                ..m
            },
        }
    }

    /// Metrics of a run that was not integrated (estimates fill in what they know).
    fn analytic_base(&self, system: &RotorSystem, omega: f64) -> RunMetrics {
        let a_ref = crate::metrics::reference::a_ref(system, omega);
        RunMetrics::not_integrated(a_ref, Outcome::NotSettled, String::new(), "closed_form")
    }

    /// The closed-form estimate: settled when the slow mode decays, with
    /// t_s = ln(1/δ)/|Re λ|; no residual, no steps.
    pub(super) fn analytic(&self, system: &RotorSystem, omega: f64) -> RunMetrics {
        let rev = 2.0 * PI / omega;
        let base = self.analytic_base(system, omega);
        match slow_mode(&self.scene) {
            Ok(mode) if mode.decay_rate < 0.0 => {
                let t = (1.0 / self.metrics.delta).ln() / -mode.decay_rate;
                RunMetrics {
                    settled: true,
                    settling_time: Some(t),
                    settling_revs: Some(t / rev),
                    hold_complete: true,
                    hold_certified: false,
                    p_final: mode.p,
                    outcome: Outcome::Settled,
                    reason: format!(
                        "analytic estimate ln(1/δ)/|Re λ| with λ = {:.4e} 1/s at p = {:.3}",
                        mode.decay_rate, mode.p
                    ),
                    ..base
                }
            }
            Ok(mode) => RunMetrics {
                p_final: mode.p,
                reason: format!(
                    "analytic: the slow mode does not decay (Re λ = {:.3e})",
                    mode.decay_rate
                ),
                ..base
            },
            Err(e) => RunMetrics {
                reason: format!("analytic: {e}"),
                ..base
            },
        }
    }
}
