//! Rolling resistance (balls, rollers) or pivot friction (pendulums): a
//! Coulomb-like torque on each weight opposing its motion relative to the
//! race, which lets the weights stop anywhere inside a dead band instead of
//! at the balanced position.
//!
//! A weight at absolute angular speed φ̇ + ψ̇ on a race of radius l presses on
//! it with N = m l (φ̇ + ψ̇)² (centrifugal; gravity and the rotor's own
//! acceleration are small beside it at operating speed and left out). The
//! resisting torque about the axis is μ(ψ̇) N l with
//!
//!   μ(v) = [μ_k + (μ_s − μ_k) exp(−(v / (STRIBECK_PER_SLIP·v_s))²)] tanh(v / v_s),
//!
//! μ_k the kinetic coefficient (rolling-resistance lever over ball radius, or
//! pivot friction torque over N l), μ_s = `static_ratio`·μ_k the breakaway
//! value, and v_s = `slip_rate`·ω the regularisation: below it the sign
//! function is smoothed, so a "stuck" weight creeps at a rate of order v_s
//! instead of switching between stick and slip by events. The dead band this
//! leaves is derived in `docs/model.md` (at rest every weight needs
//! |Im[w e^{−iψ_j}]| ≤ μ_s l) and checked in `tests/it/rolling_resistance.rs`.

use super::{Effect, EffectContext, EffectSpec, Forces};
use crate::model::cargo::Cargo;
use crate::model::validate::{SceneError, invalid, non_negative};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The Stribeck velocity (where breakaway friction has fallen to μ_k) as a
/// multiple of the regularisation rate v_s.
pub const STRIBECK_PER_SLIP: f64 = 10.0;

/// Rolling resistance of every weight, `[effects.rolling_resistance]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RollingResistance {
    /// Kinetic coefficient μ_k (dimensionless): resisting torque over N·l.
    /// About 0.001–0.005 for hardened steel balls in a steel race.
    pub coefficient: f64,
    /// Breakaway over kinetic coefficient μ_s/μ_k (≥ 1; 1: plain Coulomb).
    #[serde(default = "unit_ratio")]
    pub static_ratio: f64,
    /// Regularisation rate v_s as a fraction of the nominal speed ω: relative
    /// rates well below it count as sticking.
    #[serde(default = "default_slip_rate")]
    pub slip_rate: f64,
}

fn unit_ratio() -> f64 {
    1.0
}

fn default_slip_rate() -> f64 {
    1e-7
}

impl EffectSpec for RollingResistance {
    fn validate(&self, key: &str) -> Result<(), SceneError> {
        non_negative(&format!("{key}.coefficient"), self.coefficient)?;
        if !(self.static_ratio >= 1.0 && self.static_ratio.is_finite()) {
            return Err(invalid(
                &format!("{key}.static_ratio"),
                self.static_ratio,
                "must be at least 1 (breakaway friction is not below kinetic)",
            ));
        }
        if !(self.slip_rate > 0.0 && self.slip_rate <= 0.1) {
            return Err(invalid(
                &format!("{key}.slip_rate"),
                self.slip_rate,
                "must lie in (0, 0.1] (a fraction of the nominal speed)",
            ));
        }
        Ok(())
    }

    /// The regularised sign is a damping μ N l / v_s, 10⁷ times the
    /// friction torque's scale per rad/s at the default v_s = 1e-7 ω.
    fn stiff(&self) -> bool {
        self.coefficient > 0.0
    }

    fn build(&self, cargo: &[Cargo], omega: f64) -> Option<Box<dyn Effect>> {
        (self.coefficient > 0.0).then(|| {
            Box::new(RollingTorque {
                kinetic: self.coefficient,
                breakaway_excess: self.coefficient * (self.static_ratio - 1.0),
                slip_rate: self.slip_rate * omega,
                mass_track_sq: cargo
                    .iter()
                    .map(|c| c.mass * c.track_radius * c.track_radius)
                    .collect(),
            }) as Box<dyn Effect>
        })
    }
}

/// The built effect: coefficients and m_j l_j² per weight, once per run.
#[derive(Debug, Clone, PartialEq)]
struct RollingTorque {
    kinetic: f64,
    breakaway_excess: f64,
    /// v_s (rad/s).
    slip_rate: f64,
    mass_track_sq: Vec<f64>,
}

impl RollingTorque {
    /// μ(v), odd in v.
    fn coefficient(&self, rate: f64) -> f64 {
        let x = rate / self.slip_rate;
        let stribeck = x / STRIBECK_PER_SLIP;
        (self.kinetic + self.breakaway_excess * (-stribeck * stribeck).exp()) * x.tanh()
    }
}

impl Effect for RollingTorque {
    fn name(&self) -> &'static str {
        "rolling_resistance"
    }

    fn apply(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        let mut spin = *forces.spin;
        for ((f, ml2), &rate) in forces
            .cargo
            .iter_mut()
            .zip(&self.mass_track_sq)
            .zip(ctx.psi_rate)
        {
            let speed = ctx.spin_rate + rate;
            // N·l = m l² (φ̇ + ψ̇)².
            let torque = self.coefficient(rate) * ml2 * speed * speed;
            *f -= torque;
            spin += torque;
        }
        *forces.spin = spin;
    }

    fn rotor_forces_from_weights(&self) -> bool {
        // A torque on the spin and the weights only.
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn torque(static_ratio: f64) -> RollingTorque {
        RollingTorque {
            kinetic: 0.002,
            breakaway_excess: 0.002 * (static_ratio - 1.0),
            slip_rate: 0.03,
            mass_track_sq: vec![1.0],
        }
    }

    #[test]
    fn coefficient_is_odd_zero_at_rest_and_kinetic_when_sliding() {
        let t = torque(1.5);
        assert_eq!(t.coefficient(0.0), 0.0);
        for v in [1e-3, 0.03, 0.3, 3.0] {
            assert_eq!(t.coefficient(-v), -t.coefficient(v));
        }
        // Far above the Stribeck rate only μ_k is left.
        assert!((t.coefficient(30.0) - 0.002).abs() < 1e-12);
        // Near the slip rate the breakaway excess is felt: above μ_k·tanh.
        assert!(t.coefficient(0.06) > 0.002 * (2.0f64).tanh());
        // Never above μ_s.
        for k in 0..2000 {
            let v = f64::from(k) * 1e-3;
            assert!(t.coefficient(v) <= 0.003 + 1e-15, "v = {v}");
        }
    }

    #[test]
    fn zero_coefficient_builds_nothing() {
        let spec = RollingResistance {
            coefficient: 0.0,
            static_ratio: 1.0,
            slip_rate: 1e-4,
        };
        assert!(spec.build(&[], 300.0).is_none());
    }

    #[test]
    fn bad_parameters_name_the_field() {
        let spec = |c, s, r| RollingResistance {
            coefficient: c,
            static_ratio: s,
            slip_rate: r,
        };
        let key = "effects.rolling_resistance";
        let field = |s: RollingResistance| match s.validate(key) {
            Err(SceneError::Invalid { field, .. }) => field,
            other => panic!("expected an invalid field, got {other:?}"),
        };
        assert_eq!(field(spec(-1.0, 1.0, 1e-4)), format!("{key}.coefficient"));
        assert_eq!(field(spec(0.01, 0.5, 1e-4)), format!("{key}.static_ratio"));
        assert_eq!(field(spec(0.01, 1.0, 0.0)), format!("{key}.slip_rate"));
        assert!(spec(0.01, 1.2, 1e-4).validate(key).is_ok());
    }
}
