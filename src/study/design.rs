//! One design of the study's grid: the resolved `Design` every run, draw and
//! table row is made for, the one-or-many values the grid is written with,
//! and the most weights a balancer may have.
//!
//! A resolved design is plain data (its balancers, mass, capacity, stall
//! torque), so the parts that work on one design (the couple part, the
//! tolerances, a design per plane, the draws of a run) take it from here
//! rather than from the study file that resolves it ([`super::config`]).

use crate::model::scene::DesignSpec;
use crate::model::speed::SpeedLaw;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// One resolved design of the grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    /// Index in grid order.
    pub id: u32,
    /// The balancer.
    pub spec: DesignSpec,
    /// Resolved ρ.
    pub rho: f64,
    /// Mass of one weight (kg).
    pub weight_mass: f64,
    /// Track radius l = R − r (m).
    pub track_radius: f64,
    /// Balancing capacity (kg·m): S_AB of seed 000 for balls and rollers
    /// (weights pressed together), n m l for pendulums (they can pass each
    /// other); with a design per plane, its weakest plane's.
    pub capacity: f64,
    /// Plane 0's own capacity (kg·m): `capacity` unless planes differ.
    #[serde(skip)]
    pub plane_zero_capacity: f64,
    /// The balancers of planes 1, 2, … when they have designs of their own
    /// (`[[designs.per_plane]]`); empty: `spec` in every plane.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub plane_designs: Vec<Design>,
    /// The motor's stall torque M_s (N·m) when the grid sweeps it
    /// (`designs.stall_torque`); `None`: the scene's own speed law.
    pub stall_torque: Option<f64>,
}

impl Design {
    /// The study's speed law with this design's stall torque, if it has one.
    pub fn speed(&self, law: &SpeedLaw) -> SpeedLaw {
        match (self.stall_torque, law.clone()) {
            (
                Some(torque),
                SpeedLaw::Motor {
                    omega_sync,
                    omega_start,
                    ..
                },
            ) => SpeedLaw::Motor {
                stall_torque: torque,
                omega_sync,
                omega_start,
            },
            (_, law) => law,
        }
    }
}

/// A one-or-many value in the design grid.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(untagged)]
#[schemars(inline)]
pub enum OneOrMany<T> {
    /// A single value.
    One(T),
    /// A list of values.
    Many(Vec<T>),
}

/// Written by hand instead of serde's `untagged`: that one can only say "data
/// did not match any variant"; this one passes on what was wrong with the
/// value (or with which list entry), e.g. "invalid value: integer `-3`,
/// expected u32" or "unknown variant `bal`, expected one of ...".
impl<'de, T: Deserialize<'de>> Deserialize<'de> for OneOrMany<T> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        match toml::Value::deserialize(deserializer)? {
            toml::Value::Array(items) => items
                .into_iter()
                .enumerate()
                .map(|(i, item)| {
                    T::deserialize(item)
                        .map_err(|e| D::Error::custom(format!("entry {}: {}", i + 1, e.message())))
                })
                .collect::<Result<Vec<T>, _>>()
                .map(OneOrMany::Many),
            value => T::deserialize(value).map(OneOrMany::One).map_err(|e| {
                D::Error::custom(format!(
                    "{} (give one value or a list of them)",
                    e.message()
                ))
            }),
        }
    }
}

impl<T: Clone> OneOrMany<T> {
    /// The values as a list.
    pub fn values(&self) -> Vec<T> {
        match self {
            OneOrMany::One(v) => vec![v.clone()],
            OneOrMany::Many(v) => v.clone(),
        }
    }
}

/// Most weights one balancer may have (docs/running-at-scale.md).
pub const MAX_WEIGHTS: u32 = 256;
