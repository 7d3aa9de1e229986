//! Gravity in the rotor plane, g cos α for an axis inclined at α to the
//! horizon (seed 004, eqs 12, 15–18). The support equations are written about
//! the static equilibrium, so only the cargoes and, at variable speed, the
//! rotor's own unbalance feel it.

use super::{BuildSetup, Effect, EffectContext, EffectSpec, Forces};
use crate::model::validate::{SceneError, invalid, non_negative};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Gravity acting along −Y in the rotor plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Gravity {
    /// Gravitational acceleration g (m/s²).
    #[serde(default = "standard_gravity")]
    pub g: f64,
    /// Angle α of the rotor axis to the horizon (degrees): 0 horizontal axis
    /// (full gravity in the plane), 90 vertical axis (none).
    #[serde(default)]
    pub axis_inclination_deg: f64,
}

fn standard_gravity() -> f64 {
    9.81
}

impl Gravity {
    /// The in-plane component g cos α (exactly 0 for a vertical axis).
    pub fn in_plane(&self) -> f64 {
        if self.axis_inclination_deg.abs() == 90.0 {
            0.0
        } else {
            self.g * self.axis_inclination_deg.to_radians().cos()
        }
    }
}

impl EffectSpec for Gravity {
    fn validate(&self, key: &str) -> Result<(), SceneError> {
        non_negative(&format!("{key}.g"), self.g)?;
        if !(-90.0..=90.0).contains(&self.axis_inclination_deg) {
            return Err(invalid(
                &format!("{key}.axis_inclination_deg"),
                self.axis_inclination_deg,
                "must lie in [-90, 90] degrees",
            ));
        }
        Ok(())
    }

    fn build(&self, _setup: &BuildSetup<'_>) -> Option<Box<dyn Effect>> {
        (self.in_plane() != 0.0).then(|| Box::new(self.clone()) as Box<dyn Effect>)
    }

    fn rotating_frame_obstacle(&self) -> Option<&'static str> {
        (self.in_plane() != 0.0).then_some("gravity in the plane turns in the rotating frame")
    }
}

impl Effect for Gravity {
    fn name(&self) -> &'static str {
        "gravity"
    }

    fn apply(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        let g = self.in_plane();
        for (j, cargo) in ctx.cargo.iter().enumerate() {
            forces.cargo[j] -=
                cargo.mass * g * cargo.track_radius * crate::model::trig::cos(ctx.phi + ctx.psi[j]);
        }
        if ctx.spin_free {
            let (me, angle) = ctx.rotor_unbalance;
            *forces.spin -= me * g * crate::model::trig::cos(ctx.phi + angle);
        }
    }

    fn rotor_forces_from_weights(&self) -> bool {
        // On the weights and the spin only.
        false
    }
}
