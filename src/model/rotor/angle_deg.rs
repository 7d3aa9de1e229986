//! Angles written in degrees in files and held in radians in code: the
//! serde adapter for a rotor's direction keys (`…_deg`), and the refusal of
//! the radian keys they replace.
//!
//! Every angle a user writes is in degrees (docs/study-file.md); the rotor's
//! unbalance directions were radians until 2026-11-27, so `unbalance_angle =
//! 90` silently meant 90 rad. The old names are refused with the new one
//! rather than accepted in either unit, so no file changes meaning quietly.

use serde::{Deserialize, Deserializer, Serializer};

/// Write a radian field as degrees (`#[serde(with = "angle_deg")]`).
pub fn serialize<S: Serializer>(radians: &f64, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_f64(radians.to_degrees())
}

/// Read degrees into a radian field (`#[serde(with = "angle_deg")]`).
pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    f64::deserialize(deserializer).map(f64::to_radians)
}

/// The radian keys of a rotor table and of its `[[rotor.unbalances]]`, with
/// the degree keys that replaced them.
const RENAMED: &[(&str, &str)] = &[
    ("unbalance_angle", "unbalance_angle_deg"),
    ("static_angle", "static_angle_deg"),
    ("moment_angle", "moment_angle_deg"),
];

/// The point-unbalance key renamed the same way.
const POINT_RENAMED: (&str, &str) = ("angle", "angle_deg");

/// An error naming the new key when a rotor table uses a retired radian key.
pub fn refuse_radian_keys(table: &toml::Table) -> Result<(), String> {
    let message = |old: &str, new: &str| {
        format!(
            "rotor.{old}: this key (radians) is now `{new}`, in degrees; write the angle in degrees under the new name"
        )
    };
    for (old, new) in RENAMED {
        if table.contains_key(*old) {
            return Err(message(old, new));
        }
    }
    if let Some(toml::Value::Array(points)) = table.get("unbalances") {
        let (old, new) = POINT_RENAMED;
        for (i, point) in points.iter().enumerate() {
            if point.as_table().is_some_and(|t| t.contains_key(old)) {
                return Err(message(&format!("unbalances[{i}].{old}"), new));
            }
        }
    }
    Ok(())
}
