//! Optional physical effects. A scene enables only what it needs, and the
//! assembled right-hand side then contains only those terms: no gravity term
//! at all when the axis is vertical, no contact model unless asked.
//!
//! To add an effect: write one file implementing [`Effect`], add its
//! parameters to [`Effects`] and one line to [`Effects::build`].

pub mod contact;
pub mod gravity;

use super::cargo::Cargo;
use super::rotor::DofVec;
use serde::{Deserialize, Serialize};

/// The state an effect may read.
pub struct EffectContext<'a> {
    /// Time.
    pub t: f64,
    /// Spin angle φ.
    pub phi: f64,
    /// Spin rate φ̇.
    pub spin_rate: f64,
    /// True when φ is a free coordinate (torques on it matter).
    pub spin_free: bool,
    /// The cargoes.
    pub cargo: &'a [Cargo],
    /// Cargo angles relative to the rotor, ψ_j = φ_j − φ.
    pub psi: &'a [f64],
    /// Cargo relative rates ψ̇_j.
    pub psi_rate: &'a [f64],
    /// Rotor's own static unbalance (kg·m) and its direction at φ = 0.
    pub rotor_unbalance: (f64, f64),
}

/// Generalised forces an effect adds to.
pub struct Forces<'a> {
    /// On the rotor coordinates.
    pub rotor: &'a mut DofVec,
    /// On the spin angle φ (ignored when the speed is prescribed).
    pub spin: &'a mut f64,
    /// On each cargo angle.
    pub cargo: &'a mut [f64],
}

/// A physical effect that contributes generalised forces.
pub trait Effect: Send + Sync + std::fmt::Debug {
    /// Short name recorded in outputs.
    fn name(&self) -> &'static str;
    /// Add this effect's forces for the given state.
    fn apply(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>);
}

/// Which optional effects a scene enables, with their parameters.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Effects {
    /// Gravity in the plane of the rotor (absent: none, e.g. a vertical axis).
    #[serde(default)]
    pub gravity: Option<gravity::Gravity>,
    /// Contact between neighbouring weights of finite size (absent: weights
    /// pass through each other, as the analytic theory assumes).
    #[serde(default)]
    pub contact: Option<contact::ContactSpec>,
}

impl Effects {
    /// Build the enabled effects for these cargoes at nominal speed `omega`;
    /// an effect that would add nothing is left out.
    pub fn build(&self, cargo: &[Cargo], omega: f64) -> Vec<Box<dyn Effect>> {
        let mut list: Vec<Box<dyn Effect>> = Vec::new();
        if let Some(g) = &self.gravity
            && g.in_plane() != 0.0
        {
            list.push(Box::new(g.clone()));
        }
        if let Some(c) = &self.contact
            && let Some(effect) = contact::Contact::new(c, cargo, omega)
        {
            list.push(Box::new(effect));
        }
        list
    }
}
