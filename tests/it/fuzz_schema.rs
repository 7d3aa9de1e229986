//! A fuzz that learns every key from the JSON schemas (`schema/*.json`, what
//! `study schema study|scene` prints): each leaf key path, followed through
//! `$ref`, `properties`, `items` and `oneOf`/`anyOf`, is given hostile values
//! (NaN, ±inf, 0, −1, 1e308, the wrong type, an array one too long and one
//! too short, an empty string, control characters) in a small valid study
//! or scene, so that a key added tomorrow is covered without a new case.
//!
//! Every answer must be exit 0, 1 or 2 (never a panic, a signal or a hang);
//! a refusal (exit 2) leaves the folder as it was and names the key (its
//! last segment at least). A seeded sample of the cases runs within a time
//! box; `AUTOBAL_FUZZ_SEED` and `AUTOBAL_FUZZ_CASES` choose another sample.

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde_json::Value as Json;
use std::collections::BTreeSet;
use std::path::Path;
use std::time::{Duration, Instant};

/// The seed of the sample, printed with every failure.
const SEED: u64 = 20261127;
/// Cases tried at most, and the time they may take together.
const CASES: usize = 1000;
const TIME_BOX: Duration = Duration::from_secs(60);
/// Longest one case may take before it counts as a hang.
const CASE_LIMIT: Duration = Duration::from_secs(60);

/// One segment of a key path: a table key, or the first table of an array
/// of tables (`[[cargo]]`, `[[designs.per_plane]]`).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
enum Segment {
    Key(String),
    First,
}

/// What the schema says a leaf holds, for the wrong type and the lengths.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct Leaf {
    path: Vec<Segment>,
    types: BTreeSet<String>,
    /// minItems of an array leaf.
    min_items: Option<u64>,
}

fn schema(which: &str) -> Json {
    let path = format!("{}/schema/{which}.schema.json", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Follow a `$ref` ("#/definitions/X" or "#/$defs/X") into the root.
fn resolve<'a>(root: &'a Json, node: &'a Json) -> &'a Json {
    match node.get("$ref").and_then(Json::as_str) {
        Some(r) => r
            .trim_start_matches("#/")
            .split('/')
            .try_fold(root, |n, seg| n.get(seg))
            .unwrap_or(node),
        None => node,
    }
}

/// Every leaf key path under `node`, depth-limited (schemas may recurse).
fn leaves(root: &Json, node: &Json, path: &[Segment], out: &mut Vec<Leaf>) {
    if path.len() > 8 {
        return;
    }
    let node = resolve(root, node);
    // An old key kept as an alias is answered by its new name: skip it.
    if node
        .get("description")
        .and_then(Json::as_str)
        .is_some_and(|d| d.starts_with("Old name"))
    {
        return;
    }
    let mut branched = false;
    for key in ["oneOf", "anyOf", "allOf"] {
        if let Some(options) = node.get(key).and_then(Json::as_array) {
            for o in options {
                leaves(root, o, path, out);
            }
            branched = true;
        }
    }
    if let Some(props) = node.get("properties").and_then(Json::as_object) {
        for (k, v) in props {
            let mut p = path.to_vec();
            p.push(Segment::Key(k.clone()));
            leaves(root, v, &p, out);
        }
        return;
    }
    // An array of tables: its first table's keys are leaves too.
    if let Some(items) = node.get("items") {
        let items = resolve(root, items);
        let tables = |n: &Json| resolve(root, n).get("properties").is_some();
        let options = ["oneOf", "anyOf"]
            .iter()
            .filter_map(|k| items.get(*k).and_then(Json::as_array))
            .flatten()
            .any(tables);
        if tables(items) || options {
            let mut p = path.to_vec();
            p.push(Segment::First);
            leaves(root, items, &p, out);
        }
    }
    if path.is_empty() || (branched && node.get("type").is_none()) {
        return;
    }
    let types = match node.get("type") {
        Some(Json::String(t)) => BTreeSet::from([t.clone()]),
        Some(Json::Array(ts)) => ts
            .iter()
            .filter_map(Json::as_str)
            .map(str::to_string)
            .collect(),
        _ if node.get("enum").is_some() || node.get("const").is_some() => {
            BTreeSet::from(["string".to_string()])
        }
        _ => BTreeSet::new(),
    };
    out.push(Leaf {
        path: path.to_vec(),
        types,
        min_items: node.get("minItems").and_then(Json::as_u64),
    });
}

/// Every distinct leaf of a schema, in a stable order.
fn all_leaves(which: &str) -> Vec<Leaf> {
    let root = schema(which);
    let mut out = Vec::new();
    leaves(&root, &root, &[], &mut out);
    // One leaf per path: the oneOf branches of a key merge their types.
    let mut merged: Vec<Leaf> = Vec::new();
    out.sort();
    for l in out {
        match merged.last_mut() {
            Some(m) if m.path == l.path => {
                m.types.extend(l.types);
                m.min_items = m.min_items.or(l.min_items);
            }
            _ => merged.push(l),
        }
    }
    merged
}

/// The hostile values for one leaf, each with a short name for messages.
fn values(leaf: &Leaf) -> Vec<(String, toml::Value)> {
    use toml::Value as V;
    let mut v = vec![
        ("nan".to_string(), V::Float(f64::NAN)),
        ("inf".into(), V::Float(f64::INFINITY)),
        ("-inf".into(), V::Float(f64::NEG_INFINITY)),
        ("0".into(), V::Integer(0)),
        ("-1".into(), V::Integer(-1)),
        ("1e308".into(), V::Float(1e308)),
        ("\"\"".into(), V::String(String::new())),
        ("control".into(), V::String("a\nb\t\u{7}\u{1b}[2J".into())),
    ];
    // The wrong type: a table where a scalar is wanted, a boolean where a
    // number or a name is.
    let wrong = if leaf.types.contains("boolean") {
        V::String("yes".into())
    } else if leaf.types.contains("object") {
        V::Integer(3)
    } else {
        V::Boolean(true)
    };
    v.push(("wrong type".into(), wrong));
    let n = leaf.min_items.unwrap_or(1) as usize;
    let array = |len: usize| V::Array((0..len).map(|i| V::Float(0.1 * (i + 1) as f64)).collect());
    v.push((format!("array of {}", n + 1), array(n + 1)));
    v.push((
        format!("array of {}", n.saturating_sub(1)),
        array(n.saturating_sub(1)),
    ));
    v
}

/// `base` with `value` at `path`, parent tables made as needed.
fn insert(base: &toml::Table, path: &[Segment], value: toml::Value) -> toml::Table {
    let mut doc = base.clone();
    insert_at(&mut doc, path, value);
    doc
}

fn insert_at(table: &mut toml::Table, path: &[Segment], value: toml::Value) {
    use toml::Value as V;
    match path {
        [Segment::Key(k)] => {
            table.insert(k.clone(), value);
        }
        [Segment::Key(k), Segment::First, rest @ ..] => {
            let entry = table
                .entry(k.clone())
                .or_insert_with(|| V::Array(Vec::new()));
            if !matches!(entry, V::Array(a) if matches!(a.first(), Some(V::Table(_)))) {
                *entry = V::Array(vec![V::Table(toml::Table::new())]);
            }
            if let V::Array(a) = entry
                && let Some(V::Table(t)) = a.first_mut()
            {
                insert_at(t, rest, value);
            }
        }
        [Segment::Key(k), rest @ ..] => {
            let entry = table
                .entry(k.clone())
                .or_insert_with(|| V::Table(toml::Table::new()));
            if !matches!(entry, V::Table(_)) {
                *entry = V::Table(toml::Table::new());
            }
            if let V::Table(t) = entry {
                insert_at(t, rest, value);
            }
        }
        _ => {}
    }
}

fn dotted(path: &[Segment]) -> String {
    path.iter()
        .map(|s| match s {
            Segment::Key(k) => k.clone(),
            Segment::First => "[0]".into(),
        })
        .collect::<Vec<_>>()
        .join(".")
        .replace(".[0]", "[0]")
}

/// Whether a refusal names the key: its last segment, or, when the refusal
/// is about the table's shape (a table the case had to create lacks its
/// required key, or the rotor model has no such key), one of its parents.
fn names_the_key(err: &str, path: &[Segment], last: &str) -> bool {
    // A check of the table as a whole (a couple on a rotor that cannot
    // carry one) names the table's dotted key.
    let table_named = !err.contains("TOML parse error")
        && (2..path.len()).any(|n| err.contains(&format!("{} ", dotted(&path[..n]))));
    table_named
        || err.contains(last)
        || ((err.contains("missing field") || err.contains("unknown field"))
            && path
                .iter()
                .any(|s| matches!(s, Segment::Key(k) if err.contains(k.as_str()))))
}

/// Every file under `dir` with its size: what a refusal must leave as it was.
fn snapshot(dir: &Path) -> BTreeSet<(String, u64)> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            let meta = e.metadata().unwrap();
            if meta.is_dir() {
                stack.push(p.clone());
            }
            out.insert((p.display().to_string(), meta.len()));
        }
    }
    out
}

#[test]
fn every_schema_key_with_hostile_values_is_answered_or_refused_by_name() {
    let seed = std::env::var("AUTOBAL_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(SEED);
    let limit = std::env::var("AUTOBAL_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(CASES);
    let mut cases = Vec::new();
    for (which, verb) in [("study", "run"), ("scene", "simulate")] {
        for leaf in all_leaves(which) {
            for (name, value) in values(&leaf) {
                cases.push((which, verb, leaf.clone(), name, value));
            }
        }
    }
    let total = cases.len();
    assert!(total > 500, "only {total} cases: the schema walk lost keys");
    cases.shuffle(&mut Xoshiro256PlusPlus::seed_from_u64(seed));
    let start = Instant::now();
    let mut failures = Vec::new();
    let mut tried = 0;
    for (i, (which, verb, leaf, name, value)) in cases.into_iter().take(limit).enumerate() {
        if start.elapsed() > TIME_BOX {
            break;
        }
        tried += 1;
        let tmp = tempfile::tempdir().unwrap();
        let results = tmp.path().join("results");
        let base_text = if which == "study" {
            crate::bad_input::study(&results)
        } else {
            crate::bad_input::scene()
        };
        let base: toml::Table = toml::from_str(&base_text).unwrap();
        let mut doc = insert(&base, &leaf.path, value);
        if which == "study" {
            // Whatever the case says, the results go to this case's folder.
            doc.insert("output".into(), results.display().to_string().into());
        }
        let text = toml::to_string(&doc).unwrap();
        let file = tmp.path().join("case.toml");
        std::fs::write(&file, &text).unwrap();
        let before = snapshot(tmp.path());
        let args: Vec<&str> = if verb == "run" {
            vec![verb, file.to_str().unwrap(), "--quiet"]
        } else {
            vec![verb, file.to_str().unwrap()]
        };
        let (code, err) = crate::fuzz_input::run_boxed_in(tmp.path(), &args, CASE_LIMIT);
        let key = dotted(&leaf.path);
        let last = match leaf.path.last() {
            Some(Segment::Key(k)) => k.clone(),
            _ => key.clone(),
        };
        let why = if !matches!(code, Some(0..=2)) || err.contains("panicked") {
            Some(format!("exit {code:?}"))
        } else if code == Some(2) && snapshot(tmp.path()) != before {
            Some("a refusal changed the folder".into())
        } else if code == Some(2) && !names_the_key(&err, &leaf.path, &last) {
            Some(format!("the refusal does not name `{last}`"))
        } else {
            None
        };
        if let Some(why) = why {
            failures.push(format!(
                "seed {seed}, case {i} of {total}: {which} key {key} = {name}: {why}\n{err}\n--- {which} file:\n{text}"
            ));
        }
    }
    eprintln!(
        "fuzz_schema: seed {seed}: {tried} of {total} cases in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert!(tried >= 20, "only {tried} cases ran within the time box");
    assert!(
        failures.is_empty(),
        "{} of {tried} cases failed:\n{}",
        failures.len(),
        failures.join("\n=====\n")
    );
}
