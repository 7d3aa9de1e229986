//! Bit-identity of every number the shipped studies and scenes produce.
//!
//! A refactor must not change results. This test runs each shipped study at
//! three samples per design (every run row and the per-design summary) and
//! `study simulate` on each shipped scene, prints every value with Rust's
//! round-trip float formatting, and compares the text with the committed
//! files in `tests/golden/`, numbers and prose apart (`<name>.numbers.txt`,
//! `<name>.prose.txt`, [`split_prose`]). Text equality is bit equality. A
//! deliberate change regenerates one half: `AUTOBAL_BLESS=prose cargo test
//! golden` for wording (a changed number still fails), `AUTOBAL_BLESS=numbers`
//! for numbers, whose commit lists the before/after figures.

use autobal::integrate::Method;
use autobal::scene_file::SceneFile;
use autobal::simulation::{Fidelity, MethodChoice};
use autobal::study::plan::config::StudyFile;
use autobal::study::run::aggregate::summarize;
use autobal::study::run::run_one;
use polars::prelude::DataFrame;
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Samples per design in the golden runs: small, but more than one per design.
const SAMPLES: u32 = 3;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn shipped(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo().join(dir))
        .expect("shipped folder")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

fn dump_frame(df: &DataFrame, out: &mut String) {
    for row in 0..df.height() {
        for column in df.columns() {
            let value = column.get(row).expect("row in range");
            let _ = write!(out, "{}={value:?}; ", column.name());
        }
        out.push('\n');
    }
}

/// Every run row and the summary of one study at `SAMPLES` per design.
fn study_text(path: &Path) -> String {
    let text = std::fs::read_to_string(path).expect("study file");
    let reduced: String = text
        .lines()
        .map(|line| {
            if line.trim_start().starts_with("samples =") {
                format!("samples = {SAMPLES}")
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let shown = path.display().to_string();
    let plan = StudyFile::parse(&reduced, &shown)
        .and_then(|f| f.plan(&reduced, &shown))
        .expect("shipped study is valid");
    let mut out = String::new();
    let runs: Vec<_> = (0..plan.total_runs())
        .map(|id| {
            let mut record = run_one(&plan, id);
            record.wall_time_s = 0.0;
            let _ = writeln!(out, "{record:?}");
            record
        })
        .collect();
    let summary = summarize(&plan, &runs).expect("summary");
    out.push_str("-- summary\n");
    dump_frame(&summary, &mut out);
    out
}

/// `study simulate` of one scene as shipped (every metric and the recorded
/// series), then with each method in each simulated frame, so that every
/// stepper is covered.
fn scene_text(path: &Path) -> String {
    let file = SceneFile::read(path).expect("scene file");
    let simulation = file
        .simulation(&path.display().to_string())
        .expect("valid scene");
    let result = simulation.run(true).expect("scene runs");
    let mut out = format!("{:?}\n", result.metrics);
    let series = result.series.expect("recorded series");
    let columns = [&series.t, &series.x, &series.y, &series.r, &series.eps];
    let _ = writeln!(
        out,
        "series: {} samples, digest {}",
        series.t.len(),
        digest(columns.into_iter().chain(series.psi.iter()))
    );
    for fidelity in [Fidelity::Rotating, Fidelity::Full] {
        for method in [
            MethodChoice::Fixed(Method::Dp5),
            MethodChoice::Fixed(Method::Dop853),
            MethodChoice::Fixed(Method::Radau5),
        ] {
            let mut variant = simulation.clone();
            variant.solver.fidelity = fidelity;
            variant.solver.method = method;
            let _ = match variant.run(false) {
                Ok(r) => writeln!(
                    out,
                    "{} {}: {:?}",
                    fidelity.name(),
                    method.name(),
                    r.metrics
                ),
                Err(e) => writeln!(out, "{} {}: {e}", fidelity.name(), method.name()),
            };
        }
    }
    out
}

/// SHA-256 of the bit patterns of every value, column by column.
fn digest<'a>(columns: impl Iterator<Item = &'a Vec<f64>>) -> String {
    let mut hasher = Sha256::new();
    for column in columns {
        hasher.update((column.len() as u64).to_le_bytes());
        for v in column {
            hasher.update(v.to_bits().to_le_bytes());
        }
    }
    hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// A golden text split into its numbers and its prose: every string
/// literal with a space in it (a reason, a diagnosis, a sentence) is prose,
/// replaced in the numbers by `<prose k>` and listed on its own line as
/// `k: "…"`; everything else (numbers, booleans, enum names, identifiers) is
/// numbers. Numbers are compared field by field at tolerance 0 (text
/// equality of round-trip floats is bit equality); prose separately.
fn split_prose(text: &str) -> (String, String) {
    let (mut numbers, mut prose) = (String::new(), String::new());
    let mut k = 0;
    for line in text.lines() {
        let mut rest = line;
        while let Some(start) = rest.find('"') {
            numbers.push_str(&rest[..start]);
            // The literal's end: the next quote not escaped by a backslash.
            let body = &rest[start + 1..];
            let mut end = None;
            let mut escaped = false;
            for (i, c) in body.char_indices() {
                match c {
                    '\\' if !escaped => escaped = true,
                    '"' if !escaped => {
                        end = Some(i);
                        break;
                    }
                    _ => escaped = false,
                }
            }
            let Some(end) = end else {
                numbers.push_str(&rest[start..]);
                rest = "";
                break;
            };
            let literal = &rest[start..start + end + 2];
            if literal.contains(' ') {
                let _ = write!(numbers, "<prose {k}>");
                let _ = writeln!(prose, "{k}: {literal}");
                k += 1;
            } else {
                numbers.push_str(literal);
            }
            rest = &rest[start + end + 2..];
        }
        numbers.push_str(rest);
        numbers.push('\n');
    }
    (numbers, prose)
}

/// Which half of the golden files a bless may rewrite: `AUTOBAL_BLESS=prose`
/// rewrites the prose only (a changed number still fails), `numbers` the
/// numbers only (changed prose still fails). A changed number therefore
/// needs a bless of its own, named in its commit.
fn bless_mode() -> Option<&'static str> {
    match std::env::var("AUTOBAL_BLESS").ok()?.as_str() {
        "prose" => Some("prose"),
        "numbers" => Some("numbers"),
        other => panic!(
            "AUTOBAL_BLESS={other}: say which half to rewrite, AUTOBAL_BLESS=prose or AUTOBAL_BLESS=numbers"
        ),
    }
}

/// The first field that differs between two numbers lines, as "field:
/// golden → now" (fields separated by ", " or "; ").
fn first_field_difference(expected: &str, actual: &str) -> String {
    let fields = |l: &str| -> Vec<String> {
        l.split("; ")
            .flat_map(|p| p.split(", "))
            .map(str::to_string)
            .collect()
    };
    let (e, a) = (fields(expected), fields(actual));
    match e.iter().zip(&a).find(|(x, y)| x != y) {
        Some((x, y)) => format!("{x} → {y}"),
        None => format!("{} fields → {} fields", e.len(), a.len()),
    }
}

fn check(name: &str, actual: &str, mismatches: &mut Vec<String>) {
    check_in(
        &repo().join("tests/golden"),
        name,
        actual,
        bless_mode(),
        mismatches,
    );
}

/// [`check`] against the files in `dir`, rewriting the half `bless` names.
fn check_in(
    dir: &Path,
    name: &str,
    actual: &str,
    bless: Option<&str>,
    mismatches: &mut Vec<String>,
) {
    let (numbers, prose) = split_prose(actual);
    for (half, now) in [("numbers", &numbers), ("prose", &prose)] {
        let path = dir.join(format!("{name}.{half}.txt"));
        if bless == Some(half) {
            std::fs::create_dir_all(dir).expect("golden folder");
            std::fs::write(&path, now).expect("write golden file");
            continue;
        }
        let expected = std::fs::read_to_string(&path).unwrap_or_default();
        if &expected == now {
            continue;
        }
        let first = expected
            .lines()
            .zip(now.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(expected.lines().count().min(now.lines().count()));
        let (old, new) = (
            expected.lines().nth(first).unwrap_or("<none>"),
            now.lines().nth(first).unwrap_or("<none>"),
        );
        mismatches.push(if half == "numbers" {
            format!(
                "{name}.{half}: line {}: {}",
                first + 1,
                first_field_difference(old, new)
            )
        } else {
            format!(
                "{name}.{half}: line {}\n  golden: {old}\n  now:    {new}",
                first + 1
            )
        });
    }
}

/// A prose bless rewrites the sentences and still fails on a changed
/// number; a numbers bless the other way round.
#[test]
fn a_prose_bless_cannot_move_a_number() {
    let tmp = tempfile::tempdir().unwrap();
    let old = "Run { t: 1.5, reason: \"held for 50 rev\" }\n";
    // Writing the two halves (the first call misses the prose file).
    check_in(tmp.path(), "x", old, Some("numbers"), &mut Vec::new());
    let mut mismatches = Vec::new();
    check_in(tmp.path(), "x", old, Some("prose"), &mut mismatches);
    assert!(mismatches.is_empty(), "{mismatches:?}");
    let new = "Run { t: 1.6, reason: \"held for 50 revolutions\" }\n";
    check_in(tmp.path(), "x", new, Some("prose"), &mut mismatches);
    assert_eq!(mismatches.len(), 1, "{mismatches:?}");
    assert!(
        mismatches[0].contains("t: 1.5 → Run { t: 1.6"),
        "{mismatches:?}"
    );
    // The prose was rewritten; the numbers were not.
    let mut again = Vec::new();
    check_in(
        tmp.path(),
        "x",
        "Run { t: 1.5, reason: \"held for 50 revolutions\" }\n",
        None,
        &mut again,
    );
    assert!(again.is_empty(), "{again:?}");
}

/// The split keeps every character: numbers and prose put back together
/// give the text again, and a number never lands in the prose.
#[test]
fn golden_texts_split_into_numbers_and_prose_without_loss() {
    let text = "Run { t: 1.5, reason: \"r ≤ 0.05 held\", method: \"dp5\", note: \"a \\\"quoted\\\" word\" }\nx=Float64(2.0); d=String(\"no cause\"); \n";
    let (numbers, prose) = split_prose(text);
    assert_eq!(
        numbers,
        "Run { t: 1.5, reason: <prose 0>, method: \"dp5\", note: <prose 1> }\nx=Float64(2.0); d=String(<prose 2>); \n"
    );
    let mut rebuilt = numbers.clone();
    for line in prose.lines() {
        let (k, literal) = line.split_once(": ").unwrap();
        rebuilt = rebuilt.replacen(&format!("<prose {k}>"), literal, 1);
    }
    assert_eq!(rebuilt, text);
    assert!(!prose.contains("1.5") && !prose.contains("2.0"));
}

#[test]
fn shipped_studies_and_scenes_are_bit_identical_to_the_golden_files() {
    let mut mismatches = Vec::new();
    for path in shipped("studies") {
        let name = format!("study-{}", path.file_stem().unwrap().to_string_lossy());
        check(&name, &study_text(&path), &mut mismatches);
    }
    for path in shipped("scenes") {
        let name = format!("scene-{}", path.file_stem().unwrap().to_string_lossy());
        check(&name, &scene_text(&path), &mut mismatches);
    }
    // Scenes kept only for this check: paths the shipped ones do not take.
    for path in shipped("tests/golden/cases") {
        let name = format!("case-{}", path.file_stem().unwrap().to_string_lossy());
        check(&name, &scene_text(&path), &mut mismatches);
    }
    assert!(
        mismatches.is_empty(),
        "results changed (if deliberate: AUTOBAL_BLESS=prose for wording, AUTOBAL_BLESS=numbers for numbers, each in a commit that names it):\n{}",
        mismatches.join("\n")
    );
}
