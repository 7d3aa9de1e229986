//! Viscous resistance of each weight to motion relative to its race, β_j l_j² ψ̇_j
//! (seed 004, eqs 15–18): it slows the weight and, by reaction, drives the rotor.
//!
//! Unlike the other effects drag has no table of its own in a scene: β is a
//! design parameter of each cargo (`drag = …`), so the effect reads it from
//! the cargoes and is present whenever any weight has drag.

use super::{Effect, EffectContext, Forces, IntrinsicEffect};
use crate::model::cargo::Cargo;

/// Viscous drag of every cargo relative to the rotor.
#[derive(Debug, Clone, PartialEq)]
pub struct Drag {
    /// β_j l_j² per cargo, computed once per run: (β·l)·l is exactly the
    /// product the right-hand side used to form per call, so it is bit-identical.
    coefficient: Vec<f64>,
}

impl IntrinsicEffect for Drag {
    fn from_cargo(cargo: &[Cargo], _omega: f64) -> Option<Self> {
        cargo.iter().any(|c| c.drag != 0.0).then(|| Drag {
            coefficient: cargo
                .iter()
                .map(|c| c.drag * c.track_radius * c.track_radius)
                .collect(),
        })
    }
}

impl Effect for Drag {
    fn name(&self) -> &'static str {
        "drag"
    }

    fn apply(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        // The reaction on the spin is summed in cargo order, as it always was.
        let mut spin = *forces.spin;
        for ((f, k), rate) in forces
            .cargo
            .iter_mut()
            .zip(&self.coefficient)
            .zip(ctx.psi_rate)
        {
            let drag = k * rate;
            *f -= drag;
            spin += drag;
        }
        *forces.spin = spin;
    }

    fn rotor_forces_from_weights(&self) -> bool {
        // A torque on the spin and the weights only.
        false
    }
}
