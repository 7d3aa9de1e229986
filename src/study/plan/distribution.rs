//! The distributions users write in `[sampling]`: the unbalance's magnitude
//! (a distribution and the scale it is in), its direction and the start
//! positions of the weights, with their domain check and their draw.
//!
//! They are plain values with no reference to a plan or a design, so the
//! parts of the study file that sample values of their own (the couple
//! part, [`crate::study::plan::couple`]) and the draws of a run ([`crate::study::plan::sample`]) share
//! them without importing the study file that holds them.

use crate::invalid_key::InvalidKey;
use crate::model::validate::shown;
use rand::RngExt;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Unbalance magnitude U = M e: a distribution, absolute (kg·m) or as a
/// fraction of each design's balancing capacity.
// No deny_unknown_fields here: serde cannot combine it with `flatten`; the
// flattened distribution rejects unknown keys itself.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[schemars(transform = close_unbalance_tables)]
pub struct UnbalanceSpec {
    /// The distribution.
    #[serde(flatten)]
    pub distribution: Distribution,
    /// Required: "capacity" (a fraction of each design's capacity, no unit)
    /// or "absolute" (kg·m). Never guessed: the same numbers mean a 10⁴-fold
    /// different unbalance under the two.
    #[serde(default)]
    pub relative_to: Option<Scale>,
}

/// [`UnbalanceSpec`]'s keys as serde reads them (the flattened
/// distribution), read from the table's text so that errors name the key.
#[derive(Deserialize)]
struct UnbalanceFields {
    #[serde(flatten)]
    distribution: Distribution,
    #[serde(default)]
    relative_to: Option<Scale>,
}

impl<'de> Deserialize<'de> for UnbalanceSpec {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let table = toml::Table::deserialize(deserializer)?;
        let f: UnbalanceFields = crate::input_file::from_table(&table).map_err(D::Error::custom)?;
        Ok(UnbalanceSpec {
            distribution: f.distribution,
            relative_to: f.relative_to,
        })
    }
}

impl UnbalanceSpec {
    /// The scale the values are in (`relative_to`; [`crate::study::plan::config::StudyFile::plan`]
    /// refuses a study without it, so a plan's spec always has one).
    pub fn scale(&self) -> Scale {
        self.relative_to.unwrap_or(Scale::Capacity)
    }
}

/// schemars flattens the distribution as one alternative per distribution
/// beside `relative_to`, and none of them closed: a misspelt key would pass
/// the schema that the parser refuses. Each alternative gets `relative_to`
/// and forbids other keys, as the parser does.
fn close_unbalance_tables(schema: &mut schemars::Schema) {
    let shared = schema
        .remove("properties")
        .and_then(|p| p.as_object().cloned())
        .unwrap_or_default();
    let shared_required = schema
        .remove("required")
        .and_then(|r| r.as_array().cloned())
        .unwrap_or_default();
    let Some(alternatives) = schema
        .get_mut("oneOf")
        .and_then(serde_json::Value::as_array_mut)
    else {
        return;
    };
    for alternative in alternatives.iter_mut().filter_map(|a| a.as_object_mut()) {
        if let Some(properties) = alternative
            .get_mut("properties")
            .and_then(serde_json::Value::as_object_mut)
        {
            properties.extend(shared.clone());
        }
        if let Some(required) = alternative
            .entry("required")
            .or_insert_with(|| serde_json::Value::Array(Vec::new()))
            .as_array_mut()
        {
            required.extend(shared_required.iter().cloned());
            // Units are never guessed: `relative_to` is required, though
            // the field is an Option so that the parser can name both
            // choices in its message.
            if !required.iter().any(|r| r == "relative_to") {
                required.push("relative_to".into());
            }
        }
        alternative.insert("additionalProperties".into(), false.into());
    }
}

/// Scale of sampled unbalances.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Scale {
    /// A fraction of the design's capacity.
    Capacity,
    /// kg·m.
    Absolute,
}

/// A distribution of a positive quantity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(
    tag = "distribution",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "a table with `distribution` = \"fixed\", \"uniform\", \"log_uniform\" or \"normal_truncated\" and its keys"
)]
pub enum Distribution {
    /// Always the same value.
    Fixed {
        /// The value (a fraction of capacity, or kg·m with `relative_to = "absolute"`).
        value: f64,
    },
    /// Uniform on [min, max].
    Uniform {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Log-uniform on [min, max] (min > 0).
    LogUniform {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Normal(mean, std) truncated to [min, max] (rejection sampling).
    NormalTruncated {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        std: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
}

impl Distribution {
    /// Largest value the distribution can produce.
    pub fn upper(&self) -> f64 {
        match *self {
            Distribution::Fixed { value } => value,
            Distribution::Uniform { max, .. }
            | Distribution::LogUniform { max, .. }
            | Distribution::NormalTruncated { max, .. } => max,
        }
    }

    /// The key that holds [`Distribution::upper`]: `value` or `max`.
    pub fn upper_key(&self) -> &'static str {
        match self {
            Distribution::Fixed { .. } => "value",
            _ => "max",
        }
    }
}

/// Unbalance direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum DirectionSpec {
    /// Uniform on [0, 2π).
    #[default]
    Uniform,
    /// A fixed angle (degrees).
    Fixed(f64),
}

/// Initial cargo positions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum InitialSpec {
    /// Pressed together (touching) around a uniformly random direction.
    #[default]
    Clustered,
    /// Uniformly random positions without overlap (weights of radius r cannot
    /// come closer than 2α).
    Uniform,
    /// Evenly spaced (a regular polygon).
    Even,
    /// Balanced for an unbalance of the same magnitude turned by this many
    /// degrees (the `step` start: e.g. 90 for the paper's Fig. 1 argument).
    BalancedForShift(f64),
}

/// The domain of a distribution's keys: (key, value, reason) on failure.
pub fn check(d: &Distribution) -> Result<(), InvalidKey> {
    let pos = |k: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(InvalidKey::new(
                k.to_string(),
                shown(v),
                "must be positive and finite",
            ))
        }
    };
    match *d {
        Distribution::Fixed { value } => pos("value", value),
        Distribution::Uniform { min, max } | Distribution::LogUniform { min, max } => {
            pos("min", min)?;
            pos("max", max)?;
            if max < min {
                return Err(InvalidKey::new("max", shown(max), "must not be below min"));
            }
            Ok(())
        }
        Distribution::NormalTruncated {
            mean,
            std,
            min,
            max,
        } => {
            pos("std", std)?;
            pos("min", min)?;
            pos("max", max)?;
            if max <= min {
                return Err(InvalidKey::new(
                    "max",
                    shown(max),
                    "must be above min (a single value is `distribution = \"fixed\"`)",
                ));
            }
            if !mean.is_finite() {
                return Err(InvalidKey::new("mean", shown(mean), "must be finite"));
            }
            // Rejection sampling needs a reasonable acceptance rate.
            if (min - mean) / std > 5.0 || (mean - max) / std > 5.0 {
                return Err(InvalidKey::new(
                    "mean",
                    shown(mean),
                    "lies more than 5 std outside [min, max]",
                ));
            }
            let mass = crate::study::plan::truncated::accepted_mass(mean, std, min, max);
            if mass < crate::study::plan::truncated::MIN_ACCEPTED_MASS {
                return Err(InvalidKey::new(
                    "std",
                    shown(std),
                    "leaves less than 0.1 % of the normal inside [min, max]: each draw would need over 1 000 tries; narrow std or widen [min, max]",
                ));
            }
            Ok(())
        }
    }
}

/// One value of distribution `d` from `rng`.
pub fn draw_value<R: rand::Rng + ?Sized>(d: &Distribution, rng: &mut R) -> f64 {
    match *d {
        Distribution::Fixed { value } => value,
        Distribution::Uniform { min, max } => min + (max - min) * rng.random::<f64>(),
        Distribution::LogUniform { min, max } => {
            (min.ln() + (max.ln() - min.ln()) * rng.random::<f64>()).exp()
        }
        Distribution::NormalTruncated {
            mean,
            std,
            min,
            max,
        } => crate::study::plan::truncated::draw(rng, mean, std, min, max),
    }
}
