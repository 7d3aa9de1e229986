//! Viscous resistance of each weight to motion relative to its race, β_j l_j² ψ̇_j
//! (seed 004, eqs 15–18): it slows the weight and, by reaction, drives the rotor.
//!
//! Unlike the other effects drag has no table of its own in a scene: β is a
//! design parameter of each cargo (`drag = …`), so the effect reads it from
//! the cargoes and is present whenever any weight has drag.

use super::{Effect, EffectContext, Forces, IntrinsicEffect};
use crate::model::cargo::Cargo;

/// Viscous drag of every cargo relative to the rotor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Drag;

impl IntrinsicEffect for Drag {
    fn from_cargo(cargo: &[Cargo], _omega: f64) -> Option<Self> {
        cargo.iter().any(|c| c.drag != 0.0).then_some(Drag)
    }
}

impl Effect for Drag {
    fn name(&self) -> &'static str {
        "drag"
    }

    fn apply(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        for (j, c) in ctx.cargo.iter().enumerate() {
            // Same products in the same order as before drag was an effect:
            // results stay bit-identical.
            let drag = c.drag * c.track_radius * c.track_radius * ctx.psi_rate[j];
            forces.cargo[j] -= drag;
            *forces.spin += drag;
        }
    }
}
