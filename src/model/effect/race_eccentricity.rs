//! Race eccentricity: the race's centre sits e_r off the rotation axis, at
//! angle θ in the rotor frame, and the weights run round that centre.
//!
//! Exactly, not as an added unbalance: a weight's position is
//! p_j = z + e_r e^{i(φ+θ)} + l e^{i(φ+ψ_j)}, so the kinetic energy gains
//! m e_r l φ̇ (φ̇ + ψ̇_j) cos(ψ_j − θ) and the rotor cross term
//! m Re[z̄̇ i φ̇ e_r e^{i(φ+θ)}]. Lagrange's equations then add
//! - to each weight, the torque Q_j = −m_j e_r l_j [φ̇² sin(ψ_j − θ) + φ̈ cos(ψ_j − θ)]
//!   (centrifugal force pulls a weight towards the far side of the race, ψ = θ);
//! - to the rotor, the force m_Σ e_r (φ̇² − iφ̈) e^{i(φ+θ)} of the weights'
//!   mass carried off the axis (m_Σ the weights' total mass).
//!
//! At rest in the rotating frame each weight then needs
//! Im[(w + e_r e^{iθ}) e^{−iψ_j}] = 0: three or more weights not on one line
//! centre the race on the axis, w = −e_r e^{iθ}, and the rotor is left
//! whirling at exactly r = e_r whatever the weights' mass (derivation in
//! docs/model.md, test in tests/it/race_eccentricity.rs).
//!
//! The terms above are complete for a prescribed speed on the plane rotor. A
//! motor or free rotor would also need the ψ-dependent moment of inertia
//! about the axis, m(e_r² + 2 e_r l cos(ψ − θ)), in the mass matrix, which an
//! effect (a force) cannot add; a rotor with several planes would need to
//! know which race is off-centre. Both are refused.

use super::{Effect, EffectContext, EffectSpec, Forces, SceneFacts};
use crate::model::cargo::Cargo;
use crate::model::validate::{SceneError, invalid, non_negative};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The race's centre off the axis, `[effects.race_eccentricity]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RaceEccentricity {
    /// Distance e_r of the race centre from the rotation axis (m).
    pub offset: f64,
    /// Direction θ of the race centre in the rotor frame, measured like
    /// `rotor.unbalance_angle` and the weights' angles (degrees).
    #[serde(default)]
    pub angle_deg: f64,
}

impl EffectSpec for RaceEccentricity {
    fn validate(&self, key: &str) -> Result<(), SceneError> {
        non_negative(&format!("{key}.offset"), self.offset)?;
        if !self.angle_deg.is_finite() {
            return Err(invalid(
                &format!("{key}.angle_deg"),
                self.angle_deg,
                "must be a finite angle",
            ));
        }
        Ok(())
    }

    fn check_scene(&self, key: &str, facts: &SceneFacts) -> Result<(), SceneError> {
        if self.offset == 0.0 {
            return Ok(());
        }
        let refuse = |why: &str| {
            Err(SceneError::Invalid {
                field: format!("{key}.offset"),
                value: self.offset.to_string(),
                reason: why.to_string(),
            })
        };
        if !facts.plane_rotor {
            return refuse("race eccentricity is modelled for the plane rotor only (one race)");
        }
        if !facts.prescribed_speed {
            return refuse(
                "race eccentricity needs a prescribed speed (constant or ramp): with a motor or a free rotor its inertia terms are not modelled",
            );
        }
        Ok(())
    }

    fn build(&self, cargo: &[Cargo], _omega: f64) -> Option<Box<dyn Effect>> {
        (self.offset > 0.0).then(|| {
            let angle = self.angle_deg.to_radians();
            Box::new(OffCentreRace {
                angle,
                mass_offset_track: cargo
                    .iter()
                    .map(|c| c.mass * self.offset * c.track_radius)
                    .collect(),
                mass_offset: cargo.iter().map(|c| c.mass).sum::<f64>() * self.offset,
            }) as Box<dyn Effect>
        })
    }
}

/// The built effect, with m_j e_r l_j and m_Σ e_r once per run.
#[derive(Debug, Clone, PartialEq)]
struct OffCentreRace {
    angle: f64,
    mass_offset_track: Vec<f64>,
    mass_offset: f64,
}

impl Effect for OffCentreRace {
    fn name(&self) -> &'static str {
        "race_eccentricity"
    }

    /// The weights' own mass m_Σ carried at e_r e^{iθ}.
    fn locked_unbalance(&self) -> (f64, f64) {
        let (s, c) = self.angle.sin_cos();
        (self.mass_offset * c, self.mass_offset * s)
    }

    fn apply(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        let (rate, accel) = (ctx.spin_rate, ctx.spin_accel);
        for ((f, mel), psi) in forces
            .cargo
            .iter_mut()
            .zip(&self.mass_offset_track)
            .zip(ctx.psi)
        {
            let (s, c) = crate::model::trig::sin_cos(psi - self.angle);
            *f -= mel * (rate * rate * s + accel * c);
        }
        // ctx.phi is 0 in the rotating frame: the force is then in rotor axes.
        let (s, c) = crate::model::trig::sin_cos(ctx.phi + self.angle);
        let (radial, tangential) = (self.mass_offset * rate * rate, self.mass_offset * accel);
        forces.rotor[0] += radial * c + tangential * s;
        forces.rotor[1] += radial * s - tangential * c;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_offset_builds_nothing_and_any_scene_accepts_it() {
        let spec = RaceEccentricity {
            offset: 0.0,
            angle_deg: 30.0,
        };
        assert!(spec.build(&[], 300.0).is_none());
        let facts = SceneFacts {
            plane_rotor: false,
            prescribed_speed: false,
        };
        assert!(
            spec.check_scene("effects.race_eccentricity", &facts)
                .is_ok()
        );
    }

    #[test]
    fn refuses_what_it_does_not_model_naming_the_field() {
        let spec = RaceEccentricity {
            offset: 1e-5,
            angle_deg: 0.0,
        };
        let key = "effects.race_eccentricity";
        for facts in [
            SceneFacts {
                plane_rotor: false,
                prescribed_speed: true,
            },
            SceneFacts {
                plane_rotor: true,
                prescribed_speed: false,
            },
        ] {
            match spec.check_scene(key, &facts) {
                Err(SceneError::Invalid { field, .. }) => {
                    assert_eq!(field, format!("{key}.offset"))
                }
                other => panic!("expected a refusal, got {other:?}"),
            }
        }
        let negative = RaceEccentricity {
            offset: -1e-5,
            angle_deg: 0.0,
        };
        assert!(negative.validate(key).is_err());
    }
}
