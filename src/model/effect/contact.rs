//! Contact between neighbouring weights of finite size in the same race.
//!
//! The analytic theory lets weights pass through each other; real balls and
//! rollers cannot come closer than 2α = 2 arcsin(r/l) (centre to centre, as an
//! angle about the race centre). By default contact is rigid: the system
//! holds touching weights together as constraints
//! ([`crate::model::rigid_contact`]) and this effect adds no force. With
//! `model = "penalty"` this effect adds a stiff, damped penalty
//! between every pair in the same plane that overlaps: torque k_θ δ + c_θ δ̇
//! (never pulling), with δ the angular overlap. The stiffness puts the contact
//! frequency at `frequency_ratio` × the nominal speed, so the weights' packing
//! is resolved by the integrator without making the problem needlessly stiff.
//! Up to [`ALL_PAIRS_UP_TO`] weights every pair is checked; beyond, only
//! neighbours along the race (weights sorted by angle, per plane), which
//! keeps a call O(n log n) instead of O(n²): two weights can only overlap if
//! no third sits between them, short of a third weight already sunk into both.

use super::{BuildSetup, Effect, EffectContext, EffectSpec, Forces};
use crate::model::cargo::Cargo;
use crate::model::race_ring::{MAX_RING, for_each_neighbour_pair};
use crate::model::rigid_contact::RigidContact;
use crate::model::validate::{SceneError, invalid};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Parameters of the contact effect in a scene or study file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Weights are solid: contact is on in every scene unless a file sets
    /// this to false, and then the outputs say so.
    #[serde(default = "enabled_by_default")]
    pub enabled: bool,
    /// Penalty contact: its natural frequency as a multiple of the nominal
    /// spin speed (default 20).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency_ratio: Option<f64>,
    /// Penalty contact: the damping ratio of a contact (default 2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<f64>,
    /// How contact is modelled: `rigid` (weights that touch move as one
    /// until the force between them would pull: no overlap, no stiffness;
    /// the default) or `penalty` (a stiff spring and damper between
    /// overlapping weights).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<ContactModel>,
    /// Rigid contact: the ratio of parting to closing speed in an impact,
    /// 0 (a dead impact in oil, the default) to below 1. Unused by `penalty`,
    /// whose `damping_ratio` sets the rebound.
    #[serde(default)]
    pub restitution: f64,
}

/// How contact between weights is modelled.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ContactModel {
    /// A stiff, damped spring between overlapping weights (never pulling).
    Penalty,
    /// Touching weights move as one cluster; impacts and partings are
    /// located as events ([`crate::model::rigid_contact`]). The default:
    /// on every shipped study it gives the same decisions as penalty
    /// contact at less cost, with no overlap and no stiffness to choose.
    #[default]
    Rigid,
}

impl ContactModel {
    /// The name files use.
    pub fn name(self) -> &'static str {
        match self {
            ContactModel::Penalty => "penalty",
            ContactModel::Rigid => "rigid",
        }
    }
}

fn enabled_by_default() -> bool {
    true
}

/// 20 × ω with an over-damped contact (ζ = 2: a spring that never pulls
/// still rebounds, at about 5 % of the closing speed whatever its
/// stiffness; tests/it/rigid_contact.rs) keeps the overlap
/// below 2 % of 2α on every shipped study (worst: 1.3 % on the low-speed
/// gravity study; tests/it/contact.rs), at no measurable cost. The former
/// 10 × ω, ζ = 0.5 let balls sink 6 % into each other under gravity.
const DEFAULT_RATIO: f64 = 20.0;

const DEFAULT_DAMPING: f64 = 2.0;

impl Default for ContactSpec {
    fn default() -> Self {
        ContactSpec {
            enabled: true,
            frequency_ratio: None,
            damping_ratio: None,
            model: None,
            restitution: 0.0,
        }
    }
}

impl ContactSpec {
    /// Contact on, with the model asked for.
    pub fn with_model(model: ContactModel) -> Self {
        ContactSpec {
            enabled: true,
            model: Some(model),
            ..ContactSpec::default()
        }
    }

    /// The model in force: the file's, or rigid.
    pub fn model(&self) -> ContactModel {
        self.model.unwrap_or_default()
    }

    /// Penalty contact's frequency over the nominal speed.
    pub fn frequency_ratio(&self) -> f64 {
        self.frequency_ratio.unwrap_or(DEFAULT_RATIO)
    }

    /// Penalty contact's damping ratio.
    pub fn damping_ratio(&self) -> f64 {
        self.damping_ratio.unwrap_or(DEFAULT_DAMPING)
    }

    /// The same contact with another model, its other model's keys dropped.
    pub fn switched_to(&self, model: ContactModel) -> Self {
        let mut spec = self.clone();
        spec.model = Some(model);
        match model {
            ContactModel::Rigid => {
                spec.frequency_ratio = None;
                spec.damping_ratio = None;
            }
            ContactModel::Penalty => spec.restitution = 0.0,
        }
        spec
    }

    /// A key given for the other model than the one in force, as (key, the model it belongs to).
    fn other_models_key(&self) -> Option<(&'static str, f64, ContactModel)> {
        match self.model() {
            ContactModel::Rigid => self
                .frequency_ratio
                .map(|v| ("frequency_ratio", v, ContactModel::Penalty))
                .or(self
                    .damping_ratio
                    .map(|v| ("damping_ratio", v, ContactModel::Penalty))),
            ContactModel::Penalty => (self.restitution != 0.0).then_some((
                "restitution",
                self.restitution,
                ContactModel::Rigid,
            )),
        }
    }
}

impl EffectSpec for ContactSpec {
    fn validate(&self, key: &str) -> Result<(), SceneError> {
        // Below 1 the contact is softer than the whirl it must stop (weights
        // pass through each other); far above, every touch costs steps
        // for no change in the result.
        if !(1.0..=1e4).contains(&self.frequency_ratio()) {
            return Err(invalid(
                &format!("{key}.frequency_ratio"),
                self.frequency_ratio(),
                "contact frequency over the nominal speed: 1 to 10000 (default 20)",
            ));
        }
        if !(0.0..=1e3).contains(&self.damping_ratio()) {
            return Err(invalid(
                &format!("{key}.damping_ratio"),
                self.damping_ratio(),
                "a damping ratio from 0 to 1000 (default 2: a dead impact)",
            ));
        }
        if !(0.0..1.0).contains(&self.restitution) {
            return Err(invalid(
                &format!("{key}.restitution"),
                self.restitution,
                "parting over closing speed in an impact: 0 (a dead impact, the default) up to below 1",
            ));
        }
        // A setting that cannot take effect is refused, naming both keys.
        if let Some((name, value, belongs)) = self.other_models_key() {
            let model = self.model().name();
            let default = if self.model.is_none() {
                " (the default)"
            } else {
                ""
            };
            return Err(invalid(
                &format!("{key}.{name}"),
                value,
                &format!(
                    "is used by {} contact only, and {key}.model is \"{model}\"{default}: set model = \"{}\" or remove {name}",
                    belongs.name(),
                    belongs.name()
                ),
            ));
        }
        if !self.enabled && self.model == Some(ContactModel::Rigid) {
            return Err(SceneError::Invalid {
                field: format!("{key}.model"),
                value: "rigid".into(),
                reason: format!(
                    "asks for rigid contact while {key}.enabled = false switches contact off: remove one of the two"
                ),
            });
        }
        Ok(())
    }

    fn build(&self, setup: &BuildSetup<'_>) -> Option<Box<dyn Effect>> {
        // Rigid contact is no force: the system holds it as constraints
        // (and a system that cannot is refused rigid contact up front).
        if setup.rigid_contact || self.model() == ContactModel::Rigid {
            return None;
        }
        Contact::new(self, setup.cargo, setup.omega).map(|c| Box::new(c) as Box<dyn Effect>)
    }
}

impl ContactSpec {
    /// The rigid contact of these cargoes for a system that can hold it,
    /// when it is the model in force and a weight has a size; `omega` sets
    /// the scale of its force tolerance.
    pub fn rigid(&self, cargo: &[Cargo], omega: f64) -> Option<RigidContact> {
        let wanted = self.model() == ContactModel::Rigid;
        (self.enabled && wanted && cargo.iter().any(|c| c.radius > 0.0))
            .then(|| RigidContact::new(cargo, omega, self.restitution))
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
        let w = spec.frequency_ratio() * omega;
        let half_angle = cargo.iter().map(Cargo::contact_half_angle).collect();
        // Two equal inertias I in contact through k: the relative mode has k·2/I.
        let stiffness = cargo.iter().map(|c| 0.5 * c.inertia() * w * w).collect();
        let damping = cargo
            .iter()
            .map(|c| spec.damping_ratio() * c.inertia() * w)
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
    // Within one turn `rem_euclid` is d or d + 2π (fmod returns d exactly
    // when |d| < 2π): the same bits without the fmod call, which was 2 % of
    // a study's time in the gap gauge and the contact effect.
    let w = if (0.0..TAU).contains(&d) {
        d
    } else if d < 0.0 && d > -TAU {
        d + TAU
    } else {
        d.rem_euclid(TAU)
    };
    if w > PI { w - TAU } else { w }
}

/// Up to this many weights every pair is checked: for a handful of weights
/// the pairs are fewer than a sort costs, and the shipped studies (n ≤ 8)
/// keep their exact arithmetic.
pub const ALL_PAIRS_UP_TO: usize = 8;

impl Contact {
    /// The contact torque between cargoes j and k, if they overlap.
    #[inline]
    fn pair(&self, j: usize, k: usize, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        let gap = self.half_angle[j] + self.half_angle[k];
        let d = wrapped(ctx.psi[k] - ctx.psi[j]);
        let overlap = gap - d.abs();
        if overlap <= 0.0 {
            return;
        }
        let dir = if d >= 0.0 { 1.0 } else { -1.0 };
        let overlap_rate = -dir * (ctx.psi_rate[k] - ctx.psi_rate[j]);
        let k_pair = self.stiffness[j].min(self.stiffness[k]);
        let c_pair = self.damping[j].min(self.damping[k]);
        let torque = (k_pair * overlap + c_pair * overlap_rate).max(0.0);
        forces.cargo[k] += dir * torque;
        forces.cargo[j] -= dir * torque;
    }

    /// Every pair of sized cargoes in the same plane.
    fn all_pairs(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        let n = ctx.psi.len();
        for j in 0..n {
            if self.half_angle[j] == 0.0 {
                continue;
            }
            for k in j + 1..n {
                if self.half_angle[k] == 0.0 || self.plane[k] != self.plane[j] {
                    continue;
                }
                self.pair(j, k, ctx, forces);
            }
        }
    }

    /// Neighbours along the race only, plane by plane ([`crate::model::race_ring`]).
    fn neighbours(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        for_each_neighbour_pair(
            ctx.psi.len(),
            |j| self.plane[j],
            |j| self.half_angle[j] > 0.0,
            |j| ctx.psi[j],
            |j, k| self.pair(j, k, ctx, forces),
        );
    }
}

impl Effect for Contact {
    fn name(&self) -> &'static str {
        "contact"
    }

    fn apply(&self, ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        let n = ctx.psi.len();
        if n <= ALL_PAIRS_UP_TO || n > MAX_RING {
            self.all_pairs(ctx, forces);
        } else {
            self.neighbours(ctx, forces);
        }
    }

    fn rotor_forces_from_weights(&self) -> bool {
        // Equal and opposite between two weights: nothing on the rotor.
        false
    }
}

#[cfg(test)]
mod wrap_tests {
    use super::*;

    #[test]
    fn the_fast_path_gives_the_bits_of_rem_euclid() {
        let slow = |d: f64| {
            let w = d.rem_euclid(TAU);
            if w > PI { w - TAU } else { w }
        };
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut cases = vec![0.0, -0.0, PI, -PI, TAU, -TAU, 1e-300, -1e-300, 7.0, -7.0];
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            cases.push(((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 30.0);
        }
        for d in cases {
            assert_eq!(wrapped(d).to_bits(), slow(d).to_bits(), "d = {d}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::test_stream::uniform;

    /// For many weights, the neighbour search finds exactly the forces of the
    /// exhaustive one, on packed states where many pairs overlap, in one
    /// plane and in two.
    #[test]
    fn neighbours_give_the_forces_of_all_pairs() {
        let mut seed = 7;
        for n in [9_usize, 16, 33, 64, 200] {
            for planes in [1, 2] {
                // Weights that fill 90 % of the race when packed (a race
                // holds no more).
                let per_plane = n.div_ceil(planes) as f64;
                let radius = 0.05 * (0.9 * std::f64::consts::PI / per_plane).sin();
                let cargo: Vec<Cargo> = (0..n)
                    .map(|j| Cargo {
                        radius,
                        plane: j % planes,
                        ..Cargo::point(0.01, 0.05, 0.1, 1.4)
                    })
                    .collect();
                let contact = Contact::new(&ContactSpec::default(), &cargo, 300.0).unwrap();
                // Packed: the angular pitch a little under 2α, so neighbours overlap.
                let pitch = 2.0 * cargo[0].contact_half_angle() * 0.97;
                let psi: Vec<f64> = (0..n)
                    .map(|j| (j / planes) as f64 * pitch + 0.2 * pitch * uniform(&mut seed) - 7.0)
                    .collect();
                let rate: Vec<f64> = (0..n).map(|_| uniform(&mut seed) - 0.5).collect();
                let ctx = EffectContext {
                    t: 0.0,
                    phi: 0.0,
                    spin_rate: 300.0,
                    spin_accel: 0.0,
                    spin_free: false,
                    cargo: &cargo,
                    psi: &psi,
                    psi_rate: &rate,
                    rotor_unbalance: (0.0, 0.0),
                };
                let run = |neighbours: bool| {
                    let (mut rotor, mut spin) = ([0.0; crate::model::rotor::MAX_DOF], 0.0);
                    let mut cargo_f = vec![0.0; n];
                    let mut forces = Forces {
                        rotor: &mut rotor,
                        spin: &mut spin,
                        cargo: &mut cargo_f,
                    };
                    if neighbours {
                        contact.neighbours(&ctx, &mut forces);
                    } else {
                        contact.all_pairs(&ctx, &mut forces);
                    }
                    cargo_f
                };
                let (fast, exact) = (run(true), run(false));
                let scale = exact.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
                assert!(scale > 0.0, "n = {n}: the state must hold overlaps");
                for (a, b) in fast.iter().zip(&exact) {
                    assert!(
                        (a - b).abs() <= 1e-12 * scale,
                        "n = {n}, planes = {planes}: {a} vs {b}"
                    );
                }
            }
        }
    }
}
