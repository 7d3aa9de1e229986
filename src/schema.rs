//! JSON Schemas of the study and scene files (`study schema`), derived from
//! the types the parser fills, so that they cannot drift from it. Editors
//! with a TOML language server (taplo, Even Better TOML) read them through
//! the `#:schema` line of the shipped files or `.taplo.toml`
//! (docs/study-file.md, docs/scene-file.md).
//!
//! The schemas say what parses, plus the closed lists of names the parser
//! takes as strings (ρ rules, methods); the numeric domains (positive masses,
//! tolerances in range, …) stay with the validation that runs before a study
//! starts, which names the key and the reason.

use crate::integrate::Method;
use crate::scene_file::SceneFile;
use crate::simulation::MethodChoice;
use crate::study::plan::config::StudyFile;
use schemars::generate::SchemaSettings;
use schemars::transform::{Transform, transform_subschemas};
use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde_json::Value;
use std::borrow::Cow;

/// The schema of a study file (`study run`, `study optimize`, …).
pub fn study_schema() -> Value {
    schema_for::<StudyFile>("autobal study file")
}

/// The schema of a scene file (`study simulate`, `study linear`, …).
pub fn scene_schema() -> Value {
    schema_for::<SceneFile>("autobal scene file")
}

/// Draft 7: the newest draft taplo's validator and completion understand
/// (definitions under `definitions`, no `$ref` siblings).
fn schema_for<T: JsonSchema>(title: &str) -> Value {
    let mut settings = SchemaSettings::draft07();
    // First: what it leaves behind (a `$ref` with a description beside it)
    // is then moved into `allOf` by draft 7's own transforms.
    settings.transforms.insert(0, Box::new(ForToml));
    let mut schema = settings.into_generator().into_root_schema_for::<T>();
    schema.insert("title".into(), title.into());
    schema.to_value()
}

/// Shapes schemars' output for TOML files and the people who edit them.
///
/// TOML has no null: an absent key is how a file leaves an `Option` unset,
/// so the `null` alternatives and null defaults schemars gives every
/// `Option`, which editors would offer in completion, go. Descriptions are
/// doc comments: their wrapped lines are joined (a hover is narrower or
/// wider than the source) and rustdoc links lose their brackets.
#[derive(Debug, Clone)]
struct ForToml;

impl Transform for ForToml {
    fn transform(&mut self, schema: &mut Schema) {
        transform_subschemas(self, schema);
        let Some(object) = schema.as_object_mut() else {
            return;
        };
        if let Some(Value::String(text)) = object.get_mut("description") {
            *text = readable(text);
        }
        match object.get_mut("default") {
            Some(Value::Null) => {
                object.remove("default");
            }
            Some(default) => drop_nulls(default),
            None => {}
        }
        if let Some(Value::Array(types)) = object.get_mut("type") {
            types.retain(|t| t != "null");
            if types.len() == 1 {
                let only = types.remove(0);
                object.insert("type".into(), only);
            }
        }
        let Some(Value::Array(alternatives)) = object.get_mut("anyOf") else {
            return;
        };
        alternatives.retain(|a| a.get("type").and_then(Value::as_str) != Some("null"));
        if alternatives.len() != 1 {
            return;
        }
        let Some(Value::Object(only)) = alternatives.pop() else {
            return;
        };
        object.remove("anyOf");
        for (key, value) in only {
            object.entry(key).or_insert(value);
        }
    }
}

/// A default table as a TOML file would write it: unset options left out.
fn drop_nulls(value: &mut Value) {
    match value {
        Value::Object(map) => {
            map.retain(|_, v| !v.is_null());
            map.values_mut().for_each(drop_nulls);
        }
        Value::Array(items) => items.iter_mut().for_each(drop_nulls),
        _ => {}
    }
}

/// A doc comment as prose: paragraphs kept, the lines within each joined,
/// ``[`name`]`` links shown as `` `name` ``.
fn readable(doc: &str) -> String {
    doc.split("\n\n")
        .map(|paragraph| {
            paragraph
                .lines()
                .map(str::trim)
                .collect::<Vec<_>>()
                .join(" ")
        })
        .collect::<Vec<_>>()
        .join("\n\n")
        .replace("[`", "`")
        .replace("`]", "`")
}

/// `solver.method` is read from a string (`try_from`), which schemars would
/// describe as any string; here it lists the names the parser accepts.
/// (Written here, not beside the type, to keep the solver's files untouched
/// by the schema.)
impl JsonSchema for MethodChoice {
    fn schema_name() -> Cow<'static, str> {
        "MethodChoice".into()
    }

    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        let names: Vec<&str> = std::iter::once(MethodChoice::Auto.name())
            .chain(Method::ALL.iter().map(|m| m.name()))
            .collect();
        json_schema!({
            "type": "string",
            "enum": names,
        })
    }
}
