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
//! On any rotor the race centre is its plane's centre, z = G q (the plane map
//! of [`crate::model::rotor::Rotor::plane_map`]), so the rotor force above is
//! the plane's force mapped by Gᵀ: the same kinetic energy, nothing else
//! changes. `plane` picks one race; absent, every race is off-centre by the
//! same offset and angle (one balancer plane: its race).
//!
//! The terms above are complete for a prescribed speed. A motor or free
//! rotor would also need the ψ-dependent moment of inertia about the axis,
//! m(e_r² + 2 e_r l cos(ψ − θ)), in the mass matrix, which an effect (a
//! force) cannot add: refused.

use super::{BuildSetup, Effect, EffectContext, EffectSpec, Forces, SceneFacts};
use crate::model::cargo::Cargo;
use crate::model::rotor::{DofVec, MAX_DOF};
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
    /// The balancer plane whose race is off-centre (index into the rotor's
    /// planes); absent, every race.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<usize>,
}

impl EffectSpec for RaceEccentricity {
    fn validate(&self, key: &str) -> Result<(), SceneError> {
        non_negative(&format!("{key}.offset"), self.offset)?;
        // No race is off its axis by more than the largest race's radius.
        let most = crate::model::validate::RACE_RADIUS_RANGE.1;
        if self.offset > most {
            return Err(invalid(
                &format!("{key}.offset"),
                self.offset,
                &format!("must be at most {most} m, the largest race radius"),
            ));
        }
        if !self.angle_deg.is_finite() {
            return Err(invalid(
                &format!("{key}.angle_deg"),
                self.angle_deg,
                "must be a finite angle",
            ));
        }
        Ok(())
    }

    /// To hold an off-centre race on the axis the weights must move its
    /// plane's centre by e_r: at most e_r over the plane's compliance, the
    /// largest over the races that are off-centre (e_r·|M − (k + ibω)/ω²| on
    /// the plane rotor, the stiffer axis on anisotropic supports). Several
    /// off-centre races are taken one at a time, an estimate: each plane's
    /// weights also move the others.
    fn capacity_demand(&self, planes: usize, compliance: &dyn Fn(usize) -> Option<f64>) -> f64 {
        if self.offset == 0.0 {
            return 0.0;
        }
        let races: Vec<usize> = match self.plane {
            Some(p) => vec![p],
            None => (0..planes).collect(),
        };
        races
            .into_iter()
            // No steady response (an undamped resonance): any force moves the plane.
            .map(|p| compliance(p).map_or(0.0, |c| self.offset / c))
            .fold(0.0, f64::max)
    }

    /// The weights centre the race on the axis and leave its plane whirling
    /// at exactly r = e_r (docs/model.md): no balancer does better.
    fn whirl_floor(&self) -> Option<(f64, &'static str)> {
        (self.offset > 0.0).then_some((
            self.offset,
            "the race eccentricity e_r (effects.race_eccentricity.offset): the weights centre the race on the axis and leave its plane whirling at r = e_r",
        ))
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
        if let Some(p) = self.plane
            && p >= facts.planes
        {
            return Err(SceneError::Invalid {
                field: format!("{key}.plane"),
                value: p.to_string(),
                reason: format!(
                    "the rotor has {} balancer plane(s), numbered from 0",
                    facts.planes
                ),
            });
        }
        if !facts.prescribed_speed {
            return refuse(
                "race eccentricity needs a prescribed speed (constant or ramp): with a motor or a free rotor its inertia terms are not modelled",
            );
        }
        Ok(())
    }

    fn build(&self, setup: &BuildSetup<'_>) -> Option<Box<dyn Effect>> {
        let off_centre = |c: &Cargo| self.plane.is_none_or(|p| p == c.plane);
        let cargo = setup.cargo;
        (self.offset > 0.0 && cargo.iter().any(off_centre)).then(|| {
            let angle = self.angle_deg.to_radians();
            // Σ over the off-centre planes of m_Σ,p e_r Gᵀ(cos θ, sin θ)
            // and Gᵀ(−sin θ, cos θ): the rotor force's two directions.
            let (mut along, mut across) = ([0.0; MAX_DOF], [0.0; MAX_DOF]);
            for c in cargo.iter().filter(|c| off_centre(c)) {
                let [gu, gv] = setup.plane_maps[c.plane];
                let (s, co) = angle.sin_cos();
                let me = c.mass * self.offset;
                for i in 0..MAX_DOF {
                    along[i] += me * (co * gu[i] + s * gv[i]);
                    across[i] += me * (co * gv[i] - s * gu[i]);
                }
            }
            Box::new(OffCentreRace {
                angle,
                mass_offset_track: cargo
                    .iter()
                    .map(|c| {
                        if off_centre(c) {
                            c.mass * self.offset * c.track_radius
                        } else {
                            0.0
                        }
                    })
                    .collect(),
                along,
                across,
            }) as Box<dyn Effect>
        })
    }
}

/// The built effect, with m_j e_r l_j per weight (0 on a centred race) and
/// the rotor force's generalised directions once per run.
#[derive(Debug, Clone, PartialEq)]
struct OffCentreRace {
    angle: f64,
    mass_offset_track: Vec<f64>,
    /// Gᵀ m_Σ e_r e^{iθ} summed over the off-centre races: the force per φ̇²
    /// at φ = 0 (cos φ part).
    along: DofVec,
    /// Gᵀ of i m_Σ e_r e^{iθ}: the sin φ part.
    across: DofVec,
}

impl Effect for OffCentreRace {
    fn name(&self) -> &'static str {
        "race_eccentricity"
    }

    /// The weights' own mass m_Σ carried at e_r e^{iθ} in each off-centre plane.
    fn locked_forcing(&self, cos_part: &mut DofVec, sin_part: &mut DofVec) {
        for i in 0..MAX_DOF {
            cos_part[i] += self.along[i];
            sin_part[i] += self.across[i];
        }
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
        // m_Σ e_r (φ̇² − iφ̈) e^{i(φ+θ)} mapped by Gᵀ: the plane force at
        // angle φ is cos φ·along + sin φ·across per φ̇², and the φ̈ part is
        // that force turned back by a quarter turn. ctx.phi is 0 in the
        // rotating frame: the force is then in rotor axes.
        let (s, c) = crate::model::trig::sin_cos(ctx.phi);
        let (w2, a) = (rate * rate, accel);
        for i in 0..MAX_DOF {
            let (p, q) = (self.along[i], self.across[i]);
            forces.rotor[i] += w2 * (c * p + s * q) + a * (s * p - c * q);
        }
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
            plane: None,
        };
        assert!(spec.build(&BuildSetup::plane(&[], 300.0)).is_none());
        let facts = SceneFacts {
            planes: 1,
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
            plane: None,
        };
        let key = "effects.race_eccentricity";
        let refused = |spec: &RaceEccentricity, planes, prescribed_speed| match spec.check_scene(
            key,
            &SceneFacts {
                planes,
                prescribed_speed,
            },
        ) {
            Err(SceneError::Invalid { field, .. }) => field,
            other => panic!("expected a refusal, got {other:?}"),
        };
        assert_eq!(refused(&spec, 1, false), format!("{key}.offset"));
        let third = RaceEccentricity {
            plane: Some(2),
            ..spec.clone()
        };
        assert_eq!(refused(&third, 2, true), format!("{key}.plane"));
        for planes in [1, 2] {
            let facts = SceneFacts {
                planes,
                prescribed_speed: true,
            };
            assert!(spec.check_scene(key, &facts).is_ok());
        }
        let negative = RaceEccentricity {
            offset: -1e-5,
            angle_deg: 0.0,
            plane: None,
        };
        assert!(negative.validate(key).is_err());
    }
}
