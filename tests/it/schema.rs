//! `study schema` and the committed JSON Schemas: they are what the command
//! prints (`AUTOBAL_BLESS=1 cargo test schema` rewrites them after a change
//! to the config types), every shipped study and scene validates against
//! them, and they reject what the parser rejects.

use autobal::scene_file::SceneFile;
use autobal::study::plan::config::StudyFile;
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Kind {
    Study,
    Scene,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Study => "study",
            Kind::Scene => "scene",
        }
    }

    fn schema_path(self) -> PathBuf {
        repo().join(format!("schema/{}.schema.json", self.name()))
    }

    fn validator(self) -> jsonschema::Validator {
        let text = std::fs::read_to_string(self.schema_path()).expect("committed schema");
        let schema: Value = serde_json::from_str(&text).expect("schema is JSON");
        assert!(
            jsonschema::meta::is_valid(&schema),
            "{} schema is not a valid draft-07 schema",
            self.name()
        );
        jsonschema::draft7::new(&schema).expect("schema compiles")
    }

    /// Whether the parser, then the checks run before anything starts,
    /// accept the text: (parses, valid).
    fn parser_verdict(self, text: &str) -> (bool, bool) {
        match self {
            Kind::Study => match StudyFile::parse(text, "case.toml") {
                Err(_) => (false, false),
                Ok(file) => (true, file.plan(text, "case.toml").is_ok()),
            },
            Kind::Scene => match SceneFile::parse(text, "case.toml") {
                Err(_) => (false, false),
                Ok(file) => (true, file.simulation("case.toml").is_ok()),
            },
        }
    }
}

/// The schema's complaints about a TOML text (which must be valid TOML).
fn schema_errors(validator: &jsonschema::Validator, text: &str) -> Vec<String> {
    let instance: Value = toml::from_str(text).expect("valid TOML");
    validator
        .iter_errors(&instance)
        .map(|e| format!("{}: {e}", e.instance_path()))
        .collect()
}

fn toml_files(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo().join(dir))
        .expect("shipped folder")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no TOML files in {dir}");
    files
}

/// Every shipped study and scene file, with its kind.
fn shipped() -> Vec<(PathBuf, Kind)> {
    let mut files = Vec::new();
    files.extend(toml_files("studies").into_iter().map(|p| (p, Kind::Study)));
    files.extend(toml_files("scenes").into_iter().map(|p| (p, Kind::Scene)));
    files.extend(
        toml_files("tests/golden/cases")
            .into_iter()
            .map(|p| (p, Kind::Scene)),
    );
    files
}

#[test]
fn committed_schemas_are_what_study_schema_prints() {
    let bless = std::env::var_os("AUTOBAL_BLESS").is_some();
    let mut stale = Vec::new();
    for kind in [Kind::Study, Kind::Scene] {
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["schema", kind.name()])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let printed = String::from_utf8(out.stdout).unwrap();
        let generated = match kind {
            Kind::Study => autobal::schema::study_schema(),
            Kind::Scene => autobal::schema::scene_schema(),
        };
        assert_eq!(
            printed,
            serde_json::to_string_pretty(&generated).unwrap() + "\n"
        );
        let path = kind.schema_path();
        if bless {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, &printed).unwrap();
        } else if std::fs::read_to_string(&path).ok().as_deref() != Some(printed.as_str()) {
            stale.push(path.display().to_string());
        }
    }
    assert!(
        stale.is_empty(),
        "{} differ from `study schema`: the config types changed; regenerate with AUTOBAL_BLESS=1 cargo test schema and commit them",
        stale.join(", ")
    );
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["schema", "recipe"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("recipe"));
}

#[test]
fn the_schemas_describe_keys_with_their_units() {
    let study = autobal::schema::study_schema().to_string();
    let scene = autobal::schema::scene_schema().to_string();
    for (schema, needles) in [
        (
            &study,
            &["Race radius R (m)", "N·s/m", "kg·m", "(degrees)"][..],
        ),
        (
            &scene,
            &[
                "Rotor mass M (kg)",
                "Support stiffness along X (N/m)",
                "(rad/s)",
                "(N·m²)",
            ][..],
        ),
    ] {
        for needle in needles {
            assert!(schema.contains(needle), "no {needle:?}");
        }
    }
}

#[test]
fn every_shipped_study_and_scene_validates_and_names_its_schema() {
    let validators = [Kind::Study.validator(), Kind::Scene.validator()];
    let mut failures = Vec::new();
    let files = shipped();
    for (path, kind) in &files {
        let text = std::fs::read_to_string(path).unwrap();
        let shown = path.strip_prefix(repo()).unwrap().display().to_string();
        assert!(kind.parser_verdict(&text).0, "{shown} does not parse");
        let errors = schema_errors(&validators[*kind as usize], &text);
        if !errors.is_empty() {
            failures.push(format!("{shown}: {}", errors.join("; ")));
        }
        // Every shipped file carries the line (`studies/regression.toml` too:
        // its baseline was refreshed with the line in its text).
        let dir = path.parent().unwrap();
        let first = text.lines().next().unwrap_or("");
        let target = first.strip_prefix("#:schema ").map(|t| dir.join(t));
        if target.as_ref().and_then(|t| t.canonicalize().ok())
            != kind.schema_path().canonicalize().ok()
        {
            failures.push(format!(
                "{shown}: first line {first:?} is not `#:schema <relative path to {}.schema.json>`",
                kind.name()
            ));
        }
    }
    assert!(files.len() >= 14, "{} files", files.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The bad-input corpus: whatever the parser refuses (types, names, unknown
/// keys) the schema refuses too, and the schema refuses nothing that the
/// checks before a run would let through.
#[test]
fn the_schema_refuses_what_the_parser_refuses_and_nothing_valid() {
    let tmp = tempfile::tempdir().unwrap();
    let mut cases: Vec<(Kind, String)> = Vec::new();
    let study = crate::bad_input::study(&tmp.path().join("results"));
    for (from, to, _) in crate::bad_input::STUDY_CASES {
        cases.push((Kind::Study, study.replacen(from, to, 1)));
    }
    let scene = crate::bad_input::scene();
    for (from, to, _) in crate::bad_input::SCENE_CASES {
        cases.push((Kind::Scene, scene.replacen(from, to, 1)));
    }
    // Beyond the corpus, with the schema's expected verdict: the untagged,
    // flattened and hand-written parts of the format, and an old key name.
    let hand = [
        (
            Kind::Study,
            "[scene.rotor]",
            "[scene.rotor]\nmodel = \"plain\"",
            true,
        ),
        (
            Kind::Study,
            "rho = \"optimal\"",
            "rho = [\"optimal\", \"half_race\", 0.25]",
            false,
        ),
        (
            Kind::Study,
            "rho = \"optimal\"",
            "rho = [\"optimal\", \"half_race\", \"0.3\"]",
            true,
        ),
        (
            Kind::Study,
            "direction = \"uniform\"",
            "direction = { fixed = 30.0 }",
            false,
        ),
        (
            Kind::Study,
            "direction = \"uniform\"",
            "direction = { fixed = \"north\" }",
            true,
        ),
        (
            Kind::Study,
            "initial = \"clustered\"",
            "initial = { balanced_for_shift = 90.0 }",
            false,
        ),
        (
            Kind::Study,
            "max = 0.8, relative_to = \"capacity\" }",
            "max = 0.8, relative_to = \"absolute\" }",
            false,
        ),
        (
            Kind::Study,
            "max = 0.8, relative_to = \"capacity\" }",
            "max = 0.8, mean = 0.5, relative_to = \"capacity\" }",
            true,
        ),
        // Units are never guessed: a study without relative_to is refused.
        (Kind::Study, ", relative_to = \"capacity\" }", " }", true),
        (
            Kind::Study,
            "max = 0.8, relative_to = \"capacity\" }",
            "max = 0.8, relative_to = \"total\" }",
            true,
        ),
        (
            Kind::Study,
            "samples = 2",
            "samples = 2\nstop_when = { win_probability_halfwidth = 0.05 }",
            false,
        ),
        (
            Kind::Study,
            "rtol = 1e-6",
            "rtol = 1e-6\nmethod = \"radau5\"",
            false,
        ),
        (Kind::Scene, "[rotor]", "[rotor]\nmodel = \"plane\"", false),
        (
            Kind::Scene,
            "[rotor]",
            "[rotor]\nmodel = \"two_support\"",
            true,
        ),
        (
            Kind::Scene,
            "[start]",
            "[effects.gravity]\naxis_inclination_deg = 0.0\n[start]",
            false,
        ),
    ];
    let validators = [Kind::Study.validator(), Kind::Scene.validator()];
    for (kind, from, to, refuse) in hand {
        let base = if kind == Kind::Study { &study } else { &scene };
        assert!(base.contains(from), "fixture lacks {from:?}");
        let text = base.replacen(from, to, 1);
        let errors = schema_errors(&validators[kind as usize], &text);
        assert_eq!(!errors.is_empty(), refuse, "{kind:?} {to:?}: {errors:?}");
        cases.push((kind, text));
    }
    let mut failures = Vec::new();
    let mut refused = 0;
    for (kind, text) in &cases {
        if toml::from_str::<toml::Table>(text).is_err() {
            continue;
        }
        let (parses, valid) = kind.parser_verdict(text);
        let errors = schema_errors(&validators[*kind as usize], text);
        if !errors.is_empty() {
            refused += 1;
        }
        let changed = || {
            let base = if *kind == Kind::Study { &study } else { &scene };
            text.lines()
                .filter(|l| !base.lines().any(|b| b == *l))
                .collect::<Vec<_>>()
                .join(" | ")
        };
        if !parses && errors.is_empty() {
            failures.push(format!(
                "{kind:?} `{}`: the parser refuses it, the schema does not",
                changed()
            ));
        }
        if valid && !errors.is_empty() {
            failures.push(format!(
                "{kind:?} `{}`: valid, but the schema says {}",
                changed(),
                errors.join("; ")
            ));
        }
    }
    assert!(
        refused >= 20,
        "the schema refused only {refused} of {} cases",
        cases.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
