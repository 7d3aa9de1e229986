//! Bit-identity of every number the shipped studies and scenes produce.
//!
//! A refactor must not change results. This test runs each shipped study at
//! three samples per design (every run row and the per-design summary) and
//! `study simulate` on each shipped scene, prints every value with Rust's
//! round-trip float formatting, and compares the text with the committed
//! files in `tests/golden/`. Text equality is bit equality. A deliberate
//! change regenerates them with `AUTOBAL_BLESS=1 cargo test golden` and lists
//! the before/after figures in its commit message.

use autobal::integrate::Method;
use autobal::scene_file::SceneFile;
use autobal::simulation::{Fidelity, MethodChoice};
use autobal::study::aggregate::summarize;
use autobal::study::config::StudyFile;
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

fn check(name: &str, actual: &str, mismatches: &mut Vec<String>) {
    let path = repo().join("tests/golden").join(format!("{name}.txt"));
    if std::env::var_os("AUTOBAL_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().expect("parent")).expect("golden folder");
        std::fs::write(&path, actual).expect("write golden file");
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_default();
    if expected != actual {
        let first = expected
            .lines()
            .zip(actual.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(expected.lines().count().min(actual.lines().count()));
        mismatches.push(format!(
            "{name}: first difference at line {}\n  golden: {}\n  now:    {}",
            first + 1,
            expected.lines().nth(first).unwrap_or("<none>"),
            actual.lines().nth(first).unwrap_or("<none>"),
        ));
    }
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
        "results changed (re-bless with AUTOBAL_BLESS=1 only if deliberate):\n{}",
        mismatches.join("\n")
    );
}
