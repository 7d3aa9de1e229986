//! One design of the study's grid: the resolved `Design` every run, draw and
//! table row is made for, the one-or-many values the grid is written with,
//! and the most weights a balancer may have.
//!
//! A resolved design is plain data (its balancers, mass, capacity, stall
//! torque), so the parts that work on one design (the couple part, the
//! tolerances, a design per plane, the draws of a run) take it from here
//! rather than from the study file that resolves it ([`crate::study::plan::config`]).

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
    /// A roller's length h (m), the part's other dimension; `None` for
    /// balls and pendulums.
    pub fn roller_length(&self) -> Option<f64> {
        (self.spec.kind == crate::model::balancer::Kind::Roller).then_some(self.spec.roller_height)
    }

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

/// The design as a part to build, in the units a drawing uses: "3 balls of
/// 36.4 mm diameter, 197.3 g each, in a race of radius 50 mm, drag 10
/// N·s/m per weight" (`kind` as in files; diameter 2ρR).
pub fn part_text(
    kind: &str,
    n: u32,
    (rho, race_radius): (f64, f64),
    weight_mass: f64,
    drag: f64,
    roller_length: Option<f64>,
) -> String {
    let sig = |v: f64| crate::number_text::significant(v, 4);
    let diameter = sig(2.0 * rho * race_radius * 1e3);
    let weights = match (kind, roller_length) {
        ("roller", Some(h)) => format!(
            "{n} rollers of {diameter} mm diameter and {} mm length",
            sig(h * 1e3)
        ),
        ("roller", None) => format!("{n} rollers of {diameter} mm diameter"),
        ("pendulum", _) => format!("{n} pendulums with bobs of {diameter} mm"),
        _ => format!("{n} balls of {diameter} mm diameter"),
    };
    format!(
        "{weights}, {} g each, in a race of radius {} mm, drag {} N·s/m per weight",
        sig(weight_mass * 1e3),
        sig(race_radius * 1e3),
        sig(drag)
    )
}

#[cfg(test)]
mod part_tests {
    use super::part_text;

    #[test]
    fn a_design_reads_as_a_part_with_its_dimensions() {
        // Three steel balls, ρ = 0.3638 of a 50 mm race: 36.38 mm across.
        assert_eq!(
            part_text("ball", 3, (0.3638, 0.05), 0.1973, 10.0, None),
            "3 balls of 36.38 mm diameter, 197.3 g each, in a race of radius 50 mm, drag 10 N·s/m per weight"
        );
        assert!(
            part_text("roller", 4, (0.25, 0.1), 0.5, 2.0, Some(0.015))
                .starts_with("4 rollers of 50 mm diameter and 15 mm length")
        );
    }
}
