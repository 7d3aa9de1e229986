//! Rotor models: the rigid-body (or elastic) coordinates that carry the
//! balancer planes. One file per model; each implements [`Rotor`].
//!
//! The equations of every model share one structure (MODEL-NOTES, seed 004):
//! the rotor's coordinates h (k ≤ [`MAX_DOF`]) and, when the speed is free,
//! the spin angle φ form a small "head" block; every cargo adds one diagonal
//! row coupled only to that block. [`crate::model::system`] eliminates the
//! cargo rows and solves the head block, so a rotor model only has to say
//! what its own mass, forces, unbalance and balancer planes are.

pub mod flexible;
pub mod plane;
pub mod two_support;

pub use flexible::FlexibleShaft;
pub use plane::PlaneRotor;
pub use two_support::TwoSupportRotor;

use serde::{Deserialize, Serialize};

/// Largest number of rotor coordinates a model may have (x, y and two tilts).
pub const MAX_DOF: usize = 4;

/// A fixed-size vector over the rotor coordinates (only the first `dof()` used).
pub type DofVec = [f64; MAX_DOF];

/// What a rotor model contributes to the equations of motion.
///
/// Conventions every model keeps: coordinates come in pairs (q₀, q₁), (q₂, q₃)
/// that turn like the vector (x, y) under a rotation about the spin axis (the
/// rotating-frame linearisation in [`crate::model::linear`] relies on it), and
/// `forces` is linear in q and q̇ (the forced response relies on it).
pub trait Rotor: Send + Sync + std::fmt::Debug {
    /// Short name used in output rows.
    fn name(&self) -> &'static str;
    /// Number of rotor coordinates k (2 for the plane rotor: x, y).
    fn dof(&self) -> usize;
    /// Number of balancer planes the rotor carries.
    fn planes(&self) -> usize;
    /// Rows G_u, G_v of the map from rotor coordinates to the displacement
    /// (u, v) of balancer plane `plane`'s centre.
    fn plane_map(&self, plane: usize) -> [DofVec; 2];
    /// Constant mass matrix of the rotor alone over its coordinates (k × k).
    fn mass_matrix(&self) -> [DofVec; MAX_DOF];
    /// Polar moment of inertia J_P of the rotor about its spin axis.
    fn spin_inertia(&self) -> f64;
    /// Elastic, damping and gyroscopic forces on the rotor coordinates,
    /// added into `f`, at spin speed `spin_rate`.
    fn forces(&self, q: &[f64], qd: &[f64], spin_rate: f64, f: &mut DofVec);
    /// Mass-matrix column coupling the rotor coordinates with φ̈ through the
    /// rotor's own unbalance (and gyroscopic terms), at spin angle φ and
    /// coordinates q (∂²T/∂q̇∂φ̇).
    fn spin_coupling(&self, phi: f64, q: &[f64]) -> DofVec;
    /// Centrifugal forces of the rotor's own unbalance at spin angle φ and
    /// rate φ̇ (the −d/dt of [`Rotor::spin_coupling`] times φ̇), added into `f`.
    fn unbalance_forces(&self, phi: f64, spin_rate: f64, f: &mut DofVec);
    /// Static unbalance of the rotor itself (kg·m) and its direction at φ = 0,
    /// for gravity torques and balancing-error metrics.
    fn static_unbalance(&self) -> (f64, f64);
    /// Size (kg·m) of the rotor's own unbalance as [`Rotor::unbalance_size`] measures it.
    fn own_unbalance(&self) -> f64;
    /// Size (kg·m) of a rotating unbalance given by its generalised force per
    /// φ̇² on the rotor coordinates at φ = 0: |U| for the plane rotor, the
    /// largest bearing-equivalent unbalance for a rotor on two supports.
    fn unbalance_size(&self, f: &DofVec) -> f64;
}

/// The registered rotor models, chosen in files by `model = "…"` in the
/// `[rotor]` table (`"plane"` when absent, so older files stay valid).
/// A new model: one file implementing [`Rotor`] plus a variant here.
#[derive(Debug, Clone, PartialEq)]
pub enum RotorModel {
    /// The plane rotor of seed 004 ([`plane`]).
    Plane(PlaneRotor),
    /// The rigid rotor on two elastic supports of seed 003 ([`two_support`]).
    TwoSupport(TwoSupportRotor),
    /// The flexible (Stodola–Green) shaft of seed 002 ([`flexible`]).
    Flexible(FlexibleShaft),
}

impl RotorModel {
    /// The model's name as written in files.
    pub fn name(&self) -> &'static str {
        self.as_rotor().name()
    }

    /// The model behind the [`Rotor`] interface.
    pub fn as_rotor(&self) -> &dyn Rotor {
        match self {
            RotorModel::Plane(r) => r,
            RotorModel::TwoSupport(r) => r,
            RotorModel::Flexible(r) => r,
        }
    }

    /// A boxed copy for the ODE system.
    pub fn build(&self) -> Box<dyn Rotor> {
        match self {
            RotorModel::Plane(r) => Box::new(r.clone()),
            RotorModel::TwoSupport(r) => Box::new(r.clone()),
            RotorModel::Flexible(r) => Box::new(r.clone()),
        }
    }

    /// Check every parameter (field names prefixed `rotor.`).
    pub fn validate(&self) -> Result<(), crate::model::validate::SceneError> {
        match self {
            RotorModel::Plane(r) => r.validate(),
            RotorModel::TwoSupport(r) => r.validate(),
            RotorModel::Flexible(r) => r.validate(),
        }
    }

    /// Replace the rotor's own unbalance by a sampled one of size U (kg·m) at
    /// direction θ: the plane rotor's M e; for several balancer planes, a
    /// point unbalance U in every plane (what each plane's balancer must take).
    pub fn set_unbalance(&mut self, unbalance: f64, direction: f64) {
        match self {
            RotorModel::Plane(r) => {
                r.eccentricity = unbalance / r.mass;
                r.unbalance_angle = direction;
            }
            RotorModel::Flexible(r) => {
                r.eccentricity = unbalance / r.mass;
                r.unbalance_angle = direction;
            }
            RotorModel::TwoSupport(r) => {
                r.static_unbalance = 0.0;
                r.moment_unbalance = 0.0;
                r.unbalances = r
                    .planes
                    .iter()
                    .map(|&z| two_support::PointUnbalance {
                        s: unbalance,
                        z,
                        angle: direction,
                    })
                    .collect();
            }
        }
    }

    /// The same rotor without its own unbalance (direction kept where it is a field).
    pub fn without_unbalance(&self) -> Self {
        let mut r = self.clone();
        match &mut r {
            RotorModel::Plane(p) => p.eccentricity = 0.0,
            RotorModel::Flexible(f) => f.eccentricity = 0.0,
            RotorModel::TwoSupport(t) => {
                t.static_unbalance = 0.0;
                t.moment_unbalance = 0.0;
                t.unbalances.clear();
            }
        }
        r
    }
}

impl From<PlaneRotor> for RotorModel {
    fn from(r: PlaneRotor) -> Self {
        RotorModel::Plane(r)
    }
}

impl From<FlexibleShaft> for RotorModel {
    fn from(r: FlexibleShaft) -> Self {
        RotorModel::Flexible(r)
    }
}

impl From<TwoSupportRotor> for RotorModel {
    fn from(r: TwoSupportRotor) -> Self {
        RotorModel::TwoSupport(r)
    }
}

/// How a model is written: its fields plus `model = "name"`.
#[derive(Serialize)]
#[serde(tag = "model", rename_all = "snake_case")]
enum Tagged<'a> {
    Plane(&'a PlaneRotor),
    TwoSupport(&'a TwoSupportRotor),
    Flexible(&'a FlexibleShaft),
}

impl Serialize for RotorModel {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            RotorModel::Plane(r) => Tagged::Plane(r),
            RotorModel::TwoSupport(r) => Tagged::TwoSupport(r),
            RotorModel::Flexible(r) => Tagged::Flexible(r),
        }
        .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for RotorModel {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        // serde has no default tag: read the table, take `model` out, then
        // deserialize the rest as the chosen model (unknown keys still named).
        let mut table = toml::Table::deserialize(deserializer)?;
        let model = match table.remove("model") {
            None => "plane".to_string(),
            Some(toml::Value::String(s)) => s,
            Some(other) => {
                return Err(D::Error::custom(format!(
                    "rotor.model = {other}: expected a name such as \"plane\", \"two_support\" or \"flexible\""
                )));
            }
        };
        let value = toml::Value::Table(table);
        match model.as_str() {
            "plane" => value.try_into().map(RotorModel::Plane),
            "two_support" => value.try_into().map(RotorModel::TwoSupport),
            "flexible" => value.try_into().map(RotorModel::Flexible),
            other => {
                return Err(D::Error::custom(format!(
                    "rotor.model = \"{other}\": expected \"plane\", \"two_support\" or \"flexible\""
                )));
            }
        }
        .map_err(|e| D::Error::custom(format!("rotor ({model}): {}", e.message())))
    }
}
