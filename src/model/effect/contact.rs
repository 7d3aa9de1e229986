//! Contact between neighbouring weights of finite size in the same race.
//!
//! The analytic theory lets weights pass through each other; real balls and
//! rollers cannot come closer than 2α = 2 arcsin(r/l) (centre to centre, as an
//! angle about the race centre). This effect adds a stiff, damped penalty
//! between every pair in the same plane that overlaps: torque k_θ δ + c_θ δ̇
//! (never pulling), with δ the angular overlap. The stiffness puts the contact
//! frequency at `frequency_ratio` × the nominal speed, so the weights' packing
//! is resolved by the integrator without making the problem needlessly stiff.
//! Pairs are checked exhaustively: O(n²), fine for the n ≤ 64 of a balancer,
//! and only when a scene asks for contact.

use super::{Effect, EffectContext, EffectSpec, Forces};
use crate::model::cargo::Cargo;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Parameters of the contact effect in a scene or study file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Weights are solid: contact is on in every scene unless a file sets
    /// this to false, and then the outputs say so.
    #[serde(default = "enabled_by_default")]
    pub enabled: bool,
    /// Contact natural frequency as a multiple of the nominal spin speed.
    #[serde(default = "default_ratio")]
    pub frequency_ratio: f64,
    /// Damping ratio of a contact.
    #[serde(default = "default_damping")]
    pub damping_ratio: f64,
}

fn enabled_by_default() -> bool {
    true
}

/// 20 × ω with an over-damped contact (ζ = 2, no rebound) keeps the overlap
/// below 2 % of 2α on every shipped study (worst: 1.3 % on the low-speed
/// gravity study; tests/it/contact.rs), at no measurable cost. The former
/// 10 × ω, ζ = 0.5 let balls sink 6 % into each other under gravity.
fn default_ratio() -> f64 {
    20.0
}

fn default_damping() -> f64 {
    2.0
}

impl Default for ContactSpec {
    fn default() -> Self {
        ContactSpec {
            enabled: true,
            frequency_ratio: default_ratio(),
            damping_ratio: default_damping(),
        }
    }
}

impl EffectSpec for ContactSpec {
    fn build(&self, cargo: &[Cargo], omega: f64) -> Option<Box<dyn Effect>> {
        Contact::new(self, cargo, omega).map(|c| Box::new(c) as Box<dyn Effect>)
    }
}

/// The built effect: per-cargo contact angles and per-pair coefficients.
#[derive(Debug, Clone)]
pub struct Contact {
    /// Half the minimum centre angle of each cargo (α_j).
    half_angle: Vec<f64>,
    /// Plane of each cargo.
    plane: Vec<usize>,
    /// Torsional stiffness per unit overlap for each cargo's inertia.
    stiffness: Vec<f64>,
    /// Torsional damping for each cargo's inertia.
    damping: Vec<f64>,
}

impl Contact {
    /// Build for these cargoes; `None` when no cargo has a size (nothing to add).
    pub fn new(spec: &ContactSpec, cargo: &[Cargo], omega: f64) -> Option<Self> {
        if !spec.enabled || cargo.iter().all(|c| c.radius <= 0.0) {
            return None;
        }
        let w = spec.frequency_ratio * omega;
        let half_angle = cargo.iter().map(Cargo::contact_half_angle).collect();
        // Two equal inertias I in contact through k: the relative mode has k·2/I.
        let stiffness = cargo.iter().map(|c| 0.5 * c.inertia() * w * w).collect();
        let damping = cargo
            .iter()
            .map(|c| spec.damping_ratio * c.inertia() * w)
            .collect();
        Some(Contact {
            half_angle,
            plane: cargo.iter().map(|c| c.plane).collect(),
            stiffness,
            damping,
        })
    }

    /// (α_j, k_θ, c_θ, plane) of cargo j: what a re-implementation of this effect needs.
    pub fn cargo_coefficients(&self, j: usize) -> (f64, f64, f64, usize) {
        (
            self.half_angle[j],
            self.stiffness[j],
            self.damping[j],
            self.plane[j],
        )
    }
}

/// Angle b − a wrapped to (−π, π].
pub fn wrapped(d: f64) -> f64 {
    let w = d.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

impl Effect for Contact {
    fn name(&self) -> &'static str {
        "contact"
    }

    fn apply(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        let n = ctx.psi.len();
        for j in 0..n {
            if self.half_angle[j] == 0.0 {
                continue;
            }
            for k in j + 1..n {
                if self.half_angle[k] == 0.0 || self.plane[k] != self.plane[j] {
                    continue;
                }
                let gap = self.half_angle[j] + self.half_angle[k];
                let d = wrapped(ctx.psi[k] - ctx.psi[j]);
                let overlap = gap - d.abs();
                if overlap <= 0.0 {
                    continue;
                }
                let dir = if d >= 0.0 { 1.0 } else { -1.0 };
                let overlap_rate = -dir * (ctx.psi_rate[k] - ctx.psi_rate[j]);
                let k_pair = self.stiffness[j].min(self.stiffness[k]);
                let c_pair = self.damping[j].min(self.damping[k]);
                let torque = (k_pair * overlap + c_pair * overlap_rate).max(0.0);
                forces.cargo[k] += dir * torque;
                forces.cargo[j] -= dir * torque;
            }
        }
    }
}
