//! Physical effects. A scene enables only what it needs, and the assembled
//! right-hand side then contains only those terms: no gravity term at all
//! when the axis is vertical, no contact model unless asked, no drag when no
//! weight has any.
//!
//! To add an effect: write one file with the effect (implementing [`Effect`])
//! and its scene parameters (implementing [`EffectSpec`]), then add one line
//! to the `effect_registry!` call below. Code outside the scene can also
//! add an effect to a built system ([`crate::model::system::RotorSystem::with_effect`]).

pub mod contact;
pub mod drag;
pub mod gravity;
pub mod race_eccentricity;
pub mod rolling;

use super::cargo::Cargo;
use super::rotor::DofVec;
use super::validate::SceneError;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The state an effect may read.
pub struct EffectContext<'a> {
    /// Time.
    pub t: f64,
    /// Spin angle φ.
    pub phi: f64,
    /// Spin rate φ̇.
    pub spin_rate: f64,
    /// Spin acceleration φ̈ of a prescribed speed law (0 when φ is free).
    pub spin_accel: f64,
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
    /// Whether the forces it writes on the rotor coordinates depend on the
    /// weights' states: the rotor's head equation then has weight terms only
    /// the effect knows, and implicit solvers take them by differences. The
    /// default, true, is always safe; an effect that writes no such force
    /// says false and lets them form the head rows exactly.
    fn rotor_forces_from_weights(&self) -> bool {
        true
    }
    /// The rotating force per φ̇² the effect adds when the weights are
    /// locked to the rotor, as generalised forces on the rotor coordinates:
    /// `cos_part`·cos φ + `sin_part`·sin φ (added into both). What a locked
    /// start's forced response must include; nothing by default.
    fn locked_forcing(&self, _cos_part: &mut DofVec, _sin_part: &mut DofVec) {}
}

/// What an effect is built from: the weights, the nominal speed and where
/// each balancer plane sits on the rotor.
pub struct BuildSetup<'a> {
    /// The cargoes, each tagged with its plane.
    pub cargo: &'a [Cargo],
    /// Nominal spin speed ω (rad/s).
    pub omega: f64,
    /// Map (G_u, G_v) of each balancer plane
    /// ([`crate::model::rotor::Rotor::plane_map`]).
    pub plane_maps: &'a [[DofVec; 2]],
    /// Gravity in the rotor plane, g cos α along −Y (m/s²; 0 without the
    /// gravity effect): what presses a weight on its race besides its
    /// centripetal load, for effects that need the contact force.
    pub gravity: f64,
    /// The system holds contact between the weights as rigid constraints
    /// itself, so the contact effect adds no force.
    pub rigid_contact: bool,
}

/// The plane rotor's one plane: its centre is the rotor's (x, y).
const PLANE_ROTOR_MAP: [[DofVec; 2]; 1] = [[[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]];

impl<'a> BuildSetup<'a> {
    /// The set-up on a rotor with one balancer plane at its (x, y) (the
    /// plane rotor, and the rotating frame written for it).
    pub fn plane(cargo: &'a [Cargo], omega: f64) -> Self {
        BuildSetup {
            cargo,
            omega,
            plane_maps: &PLANE_ROTOR_MAP,
            gravity: 0.0,
            rigid_contact: false,
        }
    }
}

/// What an effect may need to know of the rest of the scene to accept it.
#[derive(Debug, Clone, Copy)]
pub struct SceneFacts {
    /// Number of balancer planes (races) the rotor carries.
    pub planes: usize,
    /// The speed law is prescribed (constant or ramp), not a motor or free.
    pub prescribed_speed: bool,
}

/// An effect's parameters as a scene file gives them (`[effects.<key>]`).
pub trait EffectSpec {
    /// Check the parameters; `key` is the field prefix, e.g. `effects.gravity`.
    fn validate(&self, _key: &str) -> Result<(), SceneError> {
        Ok(())
    }
    /// Refuse a scene the effect's equations do not cover.
    fn check_scene(&self, _key: &str, _facts: &SceneFacts) -> Result<(), SceneError> {
        Ok(())
    }
    /// The effect for this set-up; `None` when it would add nothing, so the
    /// right-hand side skips it altogether.
    fn build(&self, setup: &BuildSetup<'_>) -> Option<Box<dyn Effect>>;
    /// Why the rotating-frame formulation cannot include this effect, if so.
    fn rotating_frame_obstacle(&self) -> Option<&'static str> {
        None
    }
    /// The unbalance (kg·m) the weights must supply besides the rotor's own,
    /// given each plane's compliance (m of plane-centre motion per kg·m of
    /// unbalance turning in that plane, `None` at an undamped resonance);
    /// 0 for an effect that asks nothing of the weights' capacity.
    fn capacity_demand(&self, _planes: usize, _compliance: &dyn Fn(usize) -> Option<f64>) -> f64 {
        0.0
    }
    /// The smallest whirl (m) any balancer leaves with this effect on, and
    /// what sets it; `None` when the effect sets no such floor.
    fn whirl_floor(&self) -> Option<(f64, &'static str)> {
        None
    }
    /// True when the effect makes the equations stiff by construction, so
    /// that the `auto` method starts implicit instead of waiting for a
    /// stiffness test to notice.
    fn stiff(&self) -> bool {
        false
    }
}

/// An effect with no scene table of its own: it reads its parameters from
/// the cargoes, and is present whenever they call for it.
pub trait IntrinsicEffect: Effect + Sized + 'static {
    /// The effect for these cargoes at nominal speed `omega`; `None` when it
    /// would add nothing.
    fn from_cargo(cargo: &[Cargo], omega: f64) -> Option<Self>;
}

/// Serde default of an effect that every scene has unless its file says otherwise.
fn effect_on<T: Default>() -> Option<T> {
    Some(T::default())
}

/// Declares every effect once: the intrinsic ones (built from the cargoes)
/// and the optional ones, each with its scene key, parameter type and serde
/// default (`#[serde(default)]`: off unless a file asks; `#[serde(default =
/// "effect_on::<Spec>")]`: on in every scene unless a file switches it off;
/// the type is spelt out for the schema, which calls the default alone). The
/// right-hand side applies them in this order, which is the order of the
/// floating-point additions into each force, so a new effect goes last.
macro_rules! effect_registry {
    (
        intrinsic: [$($intrinsic:ty),* $(,)?],
        optional: { $( $(#[$doc:meta])* $key:ident: $spec:ty ),* $(,)? } $(,)?
    ) => {
        /// Add the intrinsic effects these cargoes call for, in application order.
        fn build_intrinsic(cargo: &[Cargo], omega: f64, list: &mut Vec<Box<dyn Effect>>) {
            $(
                if let Some(effect) = <$intrinsic as IntrinsicEffect>::from_cargo(cargo, omega) {
                    list.push(Box::new(effect));
                }
            )*
        }

        /// Which optional effects a scene enables, with their parameters.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
        #[serde(deny_unknown_fields)]
        pub struct Effects {
            $(
                $(#[$doc])*
                pub $key: Option<$spec>,
            )*
        }

        impl Default for Effects {
            /// What a file that names no effect gets: each registry line's
            /// serde default, read from an empty table so that code and
            /// files cannot disagree.
            fn default() -> Self {
                toml::from_str("").expect("an empty effects table is valid")
            }
        }

        impl Effects {
            /// The enabled optional effects with their keys, in application order.
            fn enabled(&self) -> impl Iterator<Item = (&'static str, &dyn EffectSpec)> {
                [$((stringify!($key), self.$key.as_ref().map(|s| s as &dyn EffectSpec))),*]
                    .into_iter()
                    .filter_map(|(key, spec)| Some((key, spec?)))
            }
        }
    };
}

effect_registry! {
    intrinsic: [
        drag::Drag,
    ],
    optional: {
        /// Gravity in the plane of the rotor (absent: none, e.g. a vertical axis).
        #[serde(default)]
        gravity: gravity::Gravity,
        /// Contact between neighbouring weights of finite size: on unless a
        /// file says `enabled = false` (then weights pass through each
        /// other, as the analytic theory assumes).
        #[serde(default = "effect_on::<contact::ContactSpec>")]
        contact: contact::ContactSpec,
        /// Rolling resistance (pivot friction for pendulums): absent, none.
        #[serde(default)]
        rolling_resistance: rolling::RollingResistance,
        /// The race's centre off the rotation axis: absent, none.
        #[serde(default)]
        race_eccentricity: race_eccentricity::RaceEccentricity,
    },
}

impl Effects {
    /// Check the parameters of every enabled effect, and that the scene is
    /// one its equations cover; the first problem found is returned.
    pub fn validate(&self, facts: &SceneFacts) -> Result<(), SceneError> {
        for (key, spec) in self.enabled() {
            let key = format!("effects.{key}");
            spec.validate(&key)?;
            spec.check_scene(&key, facts)?;
        }
        Ok(())
    }

    /// Build the effects for this set-up, intrinsic ones first; an effect
    /// that would add nothing is left out.
    pub fn build(&self, setup: &BuildSetup<'_>) -> Vec<Box<dyn Effect>> {
        let setup = &BuildSetup {
            gravity: self
                .gravity
                .as_ref()
                .map_or(0.0, gravity::Gravity::in_plane),
            ..*setup
        };
        let mut list = Vec::new();
        build_intrinsic(setup.cargo, setup.omega, &mut list);
        list.extend(self.enabled().filter_map(|(_, spec)| spec.build(setup)));
        list
    }

    /// Whether an enabled effect is stiff by construction.
    pub fn stiff(&self) -> bool {
        self.enabled().any(|(_, spec)| spec.stiff())
    }

    /// The unbalance (kg·m) the enabled effects ask of the weights besides
    /// the rotor's own (see [`EffectSpec::capacity_demand`]).
    pub fn capacity_demand(&self, planes: usize, compliance: &dyn Fn(usize) -> Option<f64>) -> f64 {
        self.enabled()
            .map(|(_, spec)| spec.capacity_demand(planes, compliance))
            .sum()
    }

    /// The highest whirl floor among the enabled effects (see
    /// [`EffectSpec::whirl_floor`]), with what sets it.
    pub fn whirl_floor(&self) -> Option<(f64, &'static str)> {
        self.enabled()
            .filter_map(|(_, spec)| spec.whirl_floor())
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// Why an enabled effect rules out the rotating-frame formulation, if one does.
    pub fn rotating_frame_obstacle(&self) -> Option<&'static str> {
        self.enabled()
            .find_map(|(_, spec)| spec.rotating_frame_obstacle())
    }
}
