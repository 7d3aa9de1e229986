//! Two numbers, exactly: the type of every fixed-length pair a user writes
//! (bounds `[lo, hi]`, axial positions `[z1, z2]`). serde reads `[f64; 2]`
//! from the first two elements of a longer array and drops the rest, so a
//! third bound ran silently; this type refuses any other length, and its
//! schema says minItems = maxItems = 2.

use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::de::{Error, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// `[a, b]`: two numbers, no more and no fewer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair(pub [f64; 2]);

impl Serialize for Pair {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Pair {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Two;
        impl<'de> Visitor<'de> for Two {
            type Value = Pair;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an array of exactly two numbers, [a, b]")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Pair, A::Error> {
                // Read every element, so that the count in the message is
                // the one the user wrote.
                let mut values = Vec::with_capacity(2);
                while let Some(v) = seq.next_element::<f64>()? {
                    values.push(v);
                }
                match values[..] {
                    [a, b] => Ok(Pair([a, b])),
                    _ => Err(A::Error::custom(format!(
                        "{} element(s): expected an array of exactly two numbers, [a, b]",
                        values.len()
                    ))),
                }
            }
        }
        deserializer.deserialize_seq(Two)
    }
}

impl JsonSchema for Pair {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Pair".into()
    }

    // Inline, so that each key's own description stays beside its schema.
    fn inline_schema() -> bool {
        true
    }

    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "description": "Exactly two numbers, [a, b].",
            "type": "array",
            "items": { "type": "number", "format": "double" },
            "minItems": 2,
            "maxItems": 2
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize)]
    struct Holder {
        at: Pair,
    }

    #[test]
    fn two_numbers_are_read_and_any_other_count_is_refused() {
        let ok: Holder = toml::from_str("at = [1.0, 2.5]").unwrap();
        assert_eq!(ok.at, Pair([1.0, 2.5]));
        for bad in ["at = [1.0]", "at = []", "at = [1.0, 2.0, 3.0]"] {
            let err = toml::from_str::<Holder>(bad).err().expect(bad).to_string();
            assert!(err.contains("exactly two numbers"), "{bad}: {err}");
        }
    }
}
