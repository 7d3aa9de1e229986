//! Uncertain physics: scene keys nobody measured exactly, given a
//! distribution in the study's `[uncertain]` table and drawn per sample.
//!
//! Any numeric key of the scene's rotor, speed law or effects may be
//! uncertain (`"effects.rolling_resistance.coefficient"`, `"rotor.k1"`,
//! `"rotor.planes[0]"`). Each key draws from a stream of its own (the
//! study seed mixed with the key's name, [`Purpose::Uncertain`]): adding a
//! key changes no other draw, and with common random numbers sample k of
//! every design meets the same physics. A draw is one uniform through the
//! distribution's inverse CDF, so that a Sobol study stratifies each key.
//!
//! The draw is written into the built scene through its serialized form, so
//! that every rotor model and every effect takes uncertain keys without a
//! line of its own; the scene's own checks then judge the drawn value. Up
//! front ([`validate`]) each key must exist in the scene, be a float, not
//! be overwritten per run by the study (the sampled unbalance), and both
//! ends of its distribution must pass the scene's checks.

use crate::invalid_key::InvalidKey;
use crate::model::validate::shown;
use schemars::JsonSchema;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, Normal};
use std::collections::BTreeMap;
use std::sync::Arc;

/// `[uncertain]`: scene keys (dotted, relative to the scene) and their
/// distributions; columns `scene.<key>` in runs.parquet.
pub type UncertainSpec = BTreeMap<String, UncertainDistribution>;

/// Prefix of an uncertain key's column in runs.parquet.
pub const COLUMN_PREFIX: &str = "scene.";

/// Half-width, in standard deviations, of a normal given without `truncate`:
/// every drawn value must be a valid scene, so the support is bounded.
pub const DEFAULT_NORMAL_HALF_WIDTH: f64 = 6.0;

/// The tables under which a key may lie: what a scene's physics holds.
const ROOTS: [&str; 3] = ["rotor", "speed", "effects"];

/// The distribution of one uncertain key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(
    tag = "distribution",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "a table with `distribution` = \"uniform\", \"log_uniform\" or \"normal\" and its keys"
)]
pub enum UncertainDistribution {
    /// Uniform on [min, max] (a direction: 0 to 360).
    Uniform {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Log-uniform on [min, max], 0 < min: a coefficient known to its order of magnitude.
    LogUniform {
        /// Lower bound (> 0).
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Normal(mean, sd), truncated to `truncate` = [lo, hi] (default mean ± 6 sd).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        sd: f64,
        /// Bounds of the drawn values; default mean ± 6 sd.
        #[serde(default)]
        truncate: Option<[f64; 2]>,
    },
}

impl UncertainDistribution {
    /// The smallest and largest value a draw can take.
    pub fn support(&self) -> (f64, f64) {
        match *self {
            Self::Uniform { min, max } | Self::LogUniform { min, max } => (min, max),
            Self::Normal { mean, sd, truncate } => truncate.map_or(
                (
                    mean - DEFAULT_NORMAL_HALF_WIDTH * sd,
                    mean + DEFAULT_NORMAL_HALF_WIDTH * sd,
                ),
                |[lo, hi]| (lo, hi),
            ),
        }
    }

    /// The value at probability `u` in [0, 1) (the inverse CDF): one
    /// uniform per draw, so a Sobol coordinate maps to one key.
    pub fn quantile(&self, u: f64) -> f64 {
        let (lo, hi) = self.support();
        let x = match *self {
            Self::Uniform { min, max } => min + (max - min) * u,
            Self::LogUniform { min, max } => (min.ln() + (max.ln() - min.ln()) * u).exp(),
            Self::Normal { mean, sd, .. } => {
                let normal = Normal::new(mean, sd).expect("validated: sd > 0, finite");
                let (p_lo, p_hi) = (normal.cdf(lo), normal.cdf(hi));
                normal.inverse_cdf(p_lo + (p_hi - p_lo) * u)
            }
        };
        // The inverse CDF's rounding may step past a bound by an ulp.
        x.clamp(lo, hi)
    }

    /// The domain of the distribution's own keys (names relative to its table).
    pub fn check(&self) -> Result<(), InvalidKey> {
        let finite = |k: &str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(InvalidKey::new(k, shown(v), "must be finite"))
            }
        };
        let ordered = |min: f64, max: f64, lo_key: &str, hi_key: &str| {
            finite(lo_key, min)?;
            finite(hi_key, max)?;
            if max > min {
                Ok(())
            } else {
                Err(InvalidKey::new(
                    hi_key,
                    shown(max),
                    format!(
                        "must be above {lo_key} ({}); a value known exactly belongs in the scene, not in [uncertain]",
                        shown(min)
                    ),
                ))
            }
        };
        match *self {
            Self::Uniform { min, max } => ordered(min, max, "min", "max"),
            Self::LogUniform { min, max } => {
                ordered(min, max, "min", "max")?;
                if min > 0.0 {
                    Ok(())
                } else {
                    Err(InvalidKey::new(
                        "min",
                        shown(min),
                        "must be positive: a log-uniform spans orders of magnitude above 0",
                    ))
                }
            }
            Self::Normal { mean, sd, truncate } => {
                finite("mean", mean)?;
                if !(sd.is_finite() && sd > 0.0) {
                    return Err(InvalidKey::new(
                        "sd",
                        shown(sd),
                        "must be positive and finite",
                    ));
                }
                if let Some([lo, hi]) = truncate {
                    ordered(lo, hi, "truncate[0]", "truncate[1]")?;
                    if !(lo <= mean + 5.0 * sd && hi >= mean - 5.0 * sd) {
                        return Err(InvalidKey::new(
                            "truncate",
                            format!("[{}, {}]", shown(lo), shown(hi)),
                            "lies more than 5 sd from the mean: the normal puts almost nothing there",
                        ));
                    }
                }
                Ok(())
            }
        }
    }
}

/// One key's drawn value in a run.
#[derive(Debug, Clone, PartialEq)]
pub struct UncertainValue {
    /// The dotted scene key.
    pub key: Arc<str>,
    /// The drawn value, in the key's unit.
    pub value: f64,
}

/// Every key's value for one run, in the spec's (sorted) key order, from
/// `uniform(key)`: the key's own uniform draw in [0, 1).
pub fn draw(spec: &UncertainSpec, mut uniform: impl FnMut(&str) -> f64) -> Vec<UncertainValue> {
    spec.iter()
        .map(|(key, d)| {
            let u = uniform(key);
            UncertainValue {
                key: Arc::from(key.as_str()),
                value: d.quantile(u),
            }
        })
        .collect()
}

/// One step of a dotted key: a table key, optionally indexed (`planes[0]`).
fn steps(key: &str) -> Vec<(&str, Option<usize>)> {
    key.split('.')
        .map(|part| match part.split_once('[') {
            Some((name, rest)) => (name, rest.strip_suffix(']').and_then(|i| i.parse().ok())),
            None => (part, None),
        })
        .collect()
}

/// The value at a dotted key of a serialized scene, if there is one.
fn at<'a>(root: &'a mut toml::Value, key: &str) -> Result<&'a mut toml::Value, String> {
    let mut here = root;
    let mut path = String::new();
    for (name, index) in steps(key) {
        let table = here
            .as_table_mut()
            .ok_or_else(|| format!("`{path}` is not a table"))?;
        let known: Vec<String> = table.keys().cloned().collect();
        here = table.get_mut(name).ok_or_else(|| {
            let within = if path.is_empty() { "the scene" } else { &path };
            format!(
                "the scene sets no `{name}` in {within} (it has: {}); give the key a nominal value in the scene first",
                known.join(", ")
            )
        })?;
        if !path.is_empty() {
            path.push('.');
        }
        path.push_str(name);
        if let Some(i) = index {
            let len = here.as_array().map_or(0, Vec::len);
            here = here
                .as_array_mut()
                .and_then(|a| a.get_mut(i))
                .ok_or_else(|| format!("`{path}` has no element [{i}] (it has {len})"))?;
        }
    }
    Ok(here)
}

/// The float at a dotted key of `scene`, read through its serialized form.
pub fn read<T: Serialize>(scene: &T, key: &str) -> Result<f64, String> {
    let mut value = toml::Value::try_from(scene).map_err(|e| e.to_string())?;
    match at(&mut value, key)? {
        toml::Value::Float(x) => Ok(*x),
        toml::Value::Integer(_) => Err(
            "a whole-number key (a count or an index) cannot take a continuous distribution".into(),
        ),
        other => Err(format!("holds a {}, not a number", other.type_str())),
    }
}

/// `scene` with each key set to its drawn value, through its serialized
/// form (the scene's own deserializer reads the result).
pub fn apply<T: Serialize + DeserializeOwned>(
    scene: &T,
    values: &[UncertainValue],
) -> Result<T, String> {
    let mut tree = toml::Value::try_from(scene).map_err(|e| e.to_string())?;
    for v in values {
        let slot = at(&mut tree, &v.key).map_err(|e| format!("{}: {e}", v.key))?;
        *slot = toml::Value::Float(v.value);
    }
    tree.try_into().map_err(|e: toml::de::Error| {
        format!("the drawn scene does not read back: {}", e.message())
    })
}

/// Check every key up front, naming it (`uncertain."<key>"`): its
/// distribution's domain, that `scene` sets it as a float under rotor,
/// speed or effects, and that `check` accepts the scene with the key at
/// either end of its support (the others nominal).
pub fn validate<T: Serialize + DeserializeOwned>(
    spec: &UncertainSpec,
    scene: &T,
    check: impl Fn(&T) -> Result<(), InvalidKey>,
) -> Result<(), InvalidKey> {
    for (key, d) in spec {
        let named = |e: InvalidKey| e.under(&format!("uncertain.\"{key}\""));
        d.check().map_err(named)?;
        let refuse = |value: String, reason: String| {
            InvalidKey::new(format!("uncertain.\"{key}\""), value, reason)
        };
        let root = key.split(['.', '[']).next().unwrap_or_default();
        if !ROOTS.contains(&root) {
            return Err(refuse(
                key.clone(),
                format!(
                    "an uncertain key lies under the scene's {} tables (e.g. \"effects.rolling_resistance.coefficient\"), relative to [scene]",
                    ROOTS.join(", ")
                ),
            ));
        }
        read(scene, key).map_err(|reason| refuse(key.clone(), reason))?;
        let (lo, hi) = d.support();
        for (end, value) in [("lowest", lo), ("highest", hi)] {
            let drawn = [UncertainValue {
                key: Arc::from(key.as_str()),
                value,
            }];
            let varied = apply(scene, &drawn).map_err(|reason| refuse(shown(value), reason))?;
            check(&varied).map_err(|e| {
                refuse(
                    shown(value),
                    format!(
                        "the {end} value the distribution can draw is not a valid scene: {} = {}: {}",
                        e.key, e.value, e.reason
                    ),
                )
            })?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    struct Toy {
        rotor: ToyRotor,
    }
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    struct ToyRotor {
        k: f64,
        planes: Vec<f64>,
        count: u32,
    }

    fn toy() -> Toy {
        Toy {
            rotor: ToyRotor {
                k: 1000.0,
                planes: vec![0.1, -0.2],
                count: 3,
            },
        }
    }

    #[test]
    fn keys_are_read_and_written_through_the_serialized_scene() {
        let t = toy();
        assert_eq!(read(&t, "rotor.k"), Ok(1000.0));
        assert_eq!(read(&t, "rotor.planes[1]"), Ok(-0.2));
        assert!(
            read(&t, "rotor.count")
                .unwrap_err()
                .contains("whole-number")
        );
        assert!(
            read(&t, "rotor.kx")
                .unwrap_err()
                .contains("it has: count, k, planes")
        );
        assert!(
            read(&t, "rotor.planes[2]")
                .unwrap_err()
                .contains("no element [2]")
        );
        let v = |key: &str, value| UncertainValue {
            key: Arc::from(key),
            value,
        };
        let out = apply(&t, &[v("rotor.k", 1234.5), v("rotor.planes[0]", 0.3)]).unwrap();
        assert_eq!(out.rotor.k, 1234.5);
        assert_eq!(out.rotor.planes, vec![0.3, -0.2]);
        assert_eq!(out.rotor.count, 3);
    }

    /// The quantile maps [0, 1) onto the support, monotone, and the
    /// truncated normal's median is its mean when the bounds are symmetric.
    #[test]
    fn quantiles_cover_the_support() {
        let n = UncertainDistribution::Normal {
            mean: 10.0,
            sd: 2.0,
            truncate: None,
        };
        assert_eq!(n.support(), (-2.0, 22.0));
        assert!((n.quantile(0.5) - 10.0).abs() < 1e-12);
        assert!((n.quantile(0.841_344_746) - 12.0).abs() < 1e-3);
        let l = UncertainDistribution::LogUniform {
            min: 1e-4,
            max: 1e-2,
        };
        assert!((l.quantile(0.5) - 1e-3).abs() < 1e-15);
        assert!((l.quantile(0.0) - 1e-4).abs() < 1e-18);
        let mut last = f64::NEG_INFINITY;
        for i in 0..100 {
            let x = n.quantile(f64::from(i) / 100.0);
            assert!(x > last && (-2.0..=22.0).contains(&x));
            last = x;
        }
    }

    #[test]
    fn bad_distributions_name_their_key() {
        let bad = [
            (UncertainDistribution::Uniform { min: 1.0, max: 1.0 }, "max"),
            (
                UncertainDistribution::LogUniform { min: 0.0, max: 1.0 },
                "min",
            ),
            (
                UncertainDistribution::Normal {
                    mean: 0.0,
                    sd: -1.0,
                    truncate: None,
                },
                "sd",
            ),
            (
                UncertainDistribution::Normal {
                    mean: 0.0,
                    sd: 1.0,
                    truncate: Some([6.0, 9.0]),
                },
                "truncate",
            ),
        ];
        for (d, key) in bad {
            assert_eq!(d.check().unwrap_err().key, key, "{d:?}");
        }
    }

    #[test]
    fn validate_refuses_invalid_ends_and_keys_outside_the_physics() {
        let t = toy();
        let spec = |min, max| -> UncertainSpec {
            [(
                "rotor.k".to_string(),
                UncertainDistribution::Uniform { min, max },
            )]
            .into()
        };
        let positive = |s: &Toy| {
            if s.rotor.k > 0.0 {
                Ok(())
            } else {
                Err(InvalidKey::new(
                    "rotor.k",
                    shown(s.rotor.k),
                    "must be positive",
                ))
            }
        };
        assert_eq!(validate(&spec(500.0, 1500.0), &t, positive), Ok(()));
        let e = validate(&spec(-5.0, 1500.0), &t, positive).unwrap_err();
        assert_eq!(e.key, "uncertain.\"rotor.k\"");
        assert!(e.reason.contains("lowest value"), "{e}");
        let outside: UncertainSpec = [(
            "start.x".to_string(),
            UncertainDistribution::Uniform { min: 0.0, max: 1.0 },
        )]
        .into();
        assert!(validate(&outside, &t, positive).is_err());
    }
}
