//! Rolling resistance (balls, rollers) or pivot friction (pendulums): a
//! Coulomb-like torque on each weight opposing its motion relative to the
//! race, which lets the weights stop anywhere inside a dead band instead of
//! at the balanced position.
//!
//! A weight at absolute angle θ = φ + ψ and rate θ̇ on a race of radius l
//! presses on it with N = m (l θ̇² − g_p sin θ − ü·e_θ): its centripetal
//! load, less the in-plane gravity g_p = g cos α (along −Y) that pulls it off
//! the race at the top and onto it at the bottom, less the race centre's
//! own acceleration ü along the weight's radius e_θ. On a horizontal shaft
//! gravity is g/(l θ̇²) of the load: 4 % on a 21 mm race at 1 000 rpm, all
//! of it at 200 rpm. The race-acceleration term is left out: its share is
//! |ü|/(l θ̇²) ≤ A/l for a whirl of amplitude A (2·10⁻³ for 50 µm on a
//! 21 mm race), and keeping it would make the friction torque depend on the
//! rotor's acceleration, a coupling of the mass matrix no force can add.
//! Where N changes sign (a weight slower than √(g/l) on top of a closed
//! race) the weight presses on the race's inner wall: |N| is used. The
//! resisting torque about the axis is μ(ψ̇) |N| l with
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

use super::{BuildSetup, Effect, EffectContext, EffectSpec, Forces};
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

    fn build(&self, setup: &BuildSetup<'_>) -> Option<Box<dyn Effect>> {
        (self.coefficient > 0.0).then(|| {
            Box::new(RollingTorque {
                kinetic: self.coefficient,
                breakaway_excess: self.coefficient * (self.static_ratio - 1.0),
                slip_rate: self.slip_rate * setup.omega,
                mass_track_sq: setup
                    .cargo
                    .iter()
                    .map(|c| c.mass * c.track_radius * c.track_radius)
                    .collect(),
                gravity_over_track: setup
                    .cargo
                    .iter()
                    .map(|c| setup.gravity / c.track_radius)
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
    /// g_p / l per weight (1/s²): the in-plane gravity's share of N / (m l);
    /// 0 without gravity, so N is the centripetal load alone.
    gravity_over_track: Vec<f64>,
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
        for (j, ((f, ml2), &rate)) in forces
            .cargo
            .iter_mut()
            .zip(&self.mass_track_sq)
            .zip(ctx.psi_rate)
            .enumerate()
        {
            let speed = ctx.spin_rate + rate;
            // N·l = m l² |θ̇² − (g_p/l) sin θ|; without gravity the product
            // keeps its old order, so such runs stay bit-identical.
            let g = self.gravity_over_track[j];
            let torque = if g == 0.0 {
                self.coefficient(rate) * ml2 * speed * speed
            } else {
                let load = speed * speed - g * crate::model::trig::sin_cos(ctx.phi + ctx.psi[j]).0;
                self.coefficient(rate) * ml2 * load.abs()
            };
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
    use crate::model::cargo::Cargo;

    fn torque(static_ratio: f64) -> RollingTorque {
        RollingTorque {
            kinetic: 0.002,
            breakaway_excess: 0.002 * (static_ratio - 1.0),
            slip_rate: 0.03,
            mass_track_sq: vec![1.0],
            gravity_over_track: vec![0.0],
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
        assert!(spec.build(&BuildSetup::plane(&[], 300.0)).is_none());
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

    /// The torque on one sliding weight at absolute angle θ (rad) with the
    /// rotor at rate ω, for a gravity share g/l.
    fn sliding_torque(gravity_over_track: f64, theta: f64, omega: f64) -> f64 {
        let t = RollingTorque {
            gravity_over_track: vec![gravity_over_track],
            ..torque(1.0)
        };
        let cargo = [Cargo::point(1.0, 1.0, 0.0, 1.4)];
        // Far above the slip rate: μ = μ_k exactly.
        let rate = 30.0;
        let ctx = EffectContext {
            t: 0.0,
            phi: theta,
            spin_rate: omega - rate,
            spin_accel: 0.0,
            spin_free: false,
            cargo: &cargo,
            psi: &[0.0],
            psi_rate: &[rate],
            rotor_unbalance: (0.0, 0.0),
        };
        let (mut rotor, mut spin, mut on_weight) = ([0.0; 4], 0.0, [0.0]);
        t.apply(
            &ctx,
            &mut Forces {
                rotor: &mut rotor,
                spin: &mut spin,
                cargo: &mut on_weight,
            },
        );
        assert_eq!(spin, -on_weight[0], "the race takes the reaction");
        -on_weight[0]
    }

    #[test]
    fn gravity_lightens_the_load_on_top_and_adds_to_it_at_the_bottom() {
        use std::f64::consts::FRAC_PI_2;
        // θ̇ = 3 rad/s on a unit track: centripetal load 9 per unit mass.
        let omega = 3.0;
        let g = 2.0;
        let free = sliding_torque(0.0, FRAC_PI_2, omega);
        assert!((free - 0.002 * 9.0).abs() < 1e-15);
        let top = sliding_torque(g, FRAC_PI_2, omega);
        let bottom = sliding_torque(g, -FRAC_PI_2, omega);
        let side = sliding_torque(g, 0.0, omega);
        assert!((top / free - 7.0 / 9.0).abs() < 1e-12, "{top}");
        assert!((bottom / free - 11.0 / 9.0).abs() < 1e-12, "{bottom}");
        assert!((side / free - 1.0).abs() < 1e-12, "{side}");
        // Slower than √(g/l) on top, the weight presses on the inner wall.
        let slow = sliding_torque(g, FRAC_PI_2, 1.0);
        assert!((slow - 0.002 * 1.0).abs() < 1e-15, "{slow}");
    }
}
