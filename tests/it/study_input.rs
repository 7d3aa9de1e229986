//! Bad study input: a clear message naming the key and why, exit code 2, nothing written.

use autobal::study::plan::config::StudyFile;
use proptest::prelude::*;
use std::path::Path;
use std::process::Command;

fn valid(output: &Path) -> String {
    format!(
        r#"name = "bad"
output = "{}"
[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[scene.speed]
mode = "constant"
omega = 300.0
[designs]
kind = "ball"
n = 3
rho = "optimal"
race_radius = 0.05
drag = 10.0
[sampling]
samples = 2
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.8, relative_to = "capacity" }}
[metrics]
t_end_revs = 50
"#,
        output.display()
    )
}

/// Run `study run` on `text`; returns (exit code, stderr).
fn run(dir: &Path, text: &str) -> (Option<i32>, String) {
    let path = dir.join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

/// Apply `edit` to the valid study; expect exit 2, every `needles` in stderr, no output folder.
fn rejects(edit: impl Fn(String) -> String, needles: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let (code, err) = run(tmp.path(), &edit(valid(&results)));
    assert_eq!(code, Some(2), "stderr: {err}");
    for needle in needles {
        assert!(err.contains(needle), "expected {needle:?} in: {err}");
    }
    assert!(!results.exists(), "nothing may be written on bad input");
}

#[test]
fn the_valid_fixture_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let (code, err) = run(tmp.path(), &valid(&results));
    assert_eq!(code, Some(0), "{err}");
    assert!(results.join("bad").join("runs.parquet").exists());
}

#[test]
fn toml_syntax_error_names_line_and_column() {
    rejects(
        |t| t.replace("mass = 10.0", "mass = = 10.0"),
        &["line 4", "column"],
    );
}

#[test]
fn unknown_key_is_named() {
    rejects(
        |t| t.replace("mass = 10.0", "mass = 10.0\nmas = 3.0"),
        &["unknown field `mas`"],
    );
}

#[test]
fn wrong_type_is_named() {
    rejects(
        |t| t.replace("samples = 2", "samples = \"two\""),
        &["samples", "invalid type"],
    );
}

#[test]
fn missing_required_key_is_named() {
    rejects(
        |t| t.replace("race_radius = 0.05\n", ""),
        &["missing field `race_radius`"],
    );
}

#[test]
fn negative_or_zero_physical_values_are_named() {
    rejects(
        |t| t.replace("mass = 10.0", "mass = -10.0"),
        &["scene.rotor.mass", "-10", "positive"],
    );
    rejects(
        |t| t.replace("kx = 1.0e5", "kx = 0.0"),
        &["scene.rotor.kx", "positive"],
    );
    rejects(
        |t| t.replace("omega = 300.0", "omega = 0.0"),
        &["scene.speed.omega", "positive"],
    );
    rejects(
        |t| t.replace("drag = 10.0", "drag = -1.0"),
        &["designs.drag", "-1"],
    );
    rejects(
        |t| t.replace("race_radius = 0.05", "race_radius = 0.0"),
        &["designs.race_radius"],
    );
}

#[test]
fn rho_outside_its_range_and_zero_weights_are_named() {
    rejects(
        |t| t.replace("rho = \"optimal\"", "rho = 0.9"),
        &[
            "designs.rho = 0.9",
            "ρ_max(3)",
            "(in the design ball n = 3)",
        ],
    );
    rejects(
        |t| t.replace("rho = \"optimal\"", "rho = 0.0"),
        &["designs.rho = 0:"],
    );
    rejects(
        |t| t.replace("rho = \"optimal\"", "rho = \"optimum\""),
        &["optimum", "\"optimal\""],
    );
    rejects(
        |t| t.replace("n = 3", "n = 0"),
        &["designs.n", "at least one weight"],
    );
}

#[test]
fn absolute_unbalance_beyond_capacity_is_an_error_unless_allowed() {
    let absolute = |t: String| {
        t.replace("relative_to = \"capacity\"", "relative_to = \"absolute\"")
            .replace("max = 0.8", "max = 0.5")
    };
    rejects(
        absolute,
        &[
            "sampling.unbalance.max",
            "exceeds the capacity",
            "require_balanceable",
        ],
    );
    // Allowed explicitly: the study runs and the runs simply do not settle.
    let tmp = tempfile::tempdir().unwrap();
    let text = valid(&tmp.path().join("results"))
        .replace("relative_to = \"capacity\"", "relative_to = \"absolute\"")
        .replace("max = 0.8", "max = 0.5")
        .replace("samples = 2", "samples = 2\nrequire_balanceable = false");
    let (code, err) = run(tmp.path(), &text);
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn unwritable_output_folder_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let blocker = tmp.path().join("not-a-folder");
    std::fs::write(&blocker, "a file").unwrap();
    let (code, err) = run(tmp.path(), &valid(&blocker));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("cannot be written"), "{err}");
}

#[test]
fn bad_scene_file_for_simulate_exits_2() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("scene.toml");
    std::fs::write(&path, "[rotor]\nmass = 1.0\nkx = 1.0\nky = 1.0\nbx = 0.1\nby = 0.1\n[speed]\nmode = \"constant\"\nomega = -4.0\n[[cargo]]\nmass = 0.01\ntrack_radius = 1.0\ndrag = 0.01\nkappa = 1.4\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["simulate", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("speed.omega = -4"));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    /// Random single-character edits of a valid study never panic the loader:
    /// it answers with a plan or an error.
    #[test]
    fn loader_never_panics_on_mangled_input(pos in 0usize..10_000, byte in 32u8..127, kind in 0u8..3) {
        let text = valid(Path::new("/nonexistent/results"));
        let mut chars: Vec<char> = text.chars().collect();
        let at = pos % chars.len();
        match kind {
            0 => { chars.remove(at); }
            1 => chars[at] = byte as char,
            _ => chars.insert(at, byte as char),
        }
        let mangled: String = chars.into_iter().collect();
        if let Ok(file) = StudyFile::parse(&mangled, "fuzz.toml") {
            let _ = file.plan(&mangled, "fuzz.toml");
        }
    }
}

#[test]
fn plans_too_large_to_run_are_refused_before_anything_is_written() {
    // A million weights once aborted the process after study.toml was
    // written; four billion samples aborted too.
    rejects(
        |t| t.replace("n = 3", "n = 1000000"),
        &["designs.n", "1000000", "at most 256 weights"],
    );
    rejects(
        |t| t.replace("samples = 2", "samples = 4000000000"),
        &["sampling.samples", "4000000000", "more than the 20000000"],
    );
}

#[test]
fn a_significance_level_outside_its_range_is_refused() {
    rejects(
        |t| format!("{t}\n[statistics]\nalpha = 2\n"),
        &["statistics.alpha", "2", "(0, 0.5]"],
    );
    rejects(
        |t| format!("{t}\n[statistics]\nalpha = 0\n"),
        &["statistics.alpha", "0", "(0, 0.5]"],
    );
}

#[test]
fn zero_threads_is_refused_and_too_many_are_capped() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let path = tmp.path().join("ok.toml");
    std::fs::write(&path, valid(&results)).unwrap();
    let zero = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--quiet", "--threads", "0"])
        .output()
        .unwrap();
    assert_eq!(zero.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&zero.stderr).contains("--threads 0"));
    assert!(!results.exists());
    let many = Command::new(env!("CARGO_BIN_EXE_study"))
        .args([
            "run",
            path.to_str().unwrap(),
            "--quiet",
            "--threads",
            "100000",
        ])
        .output()
        .unwrap();
    assert!(
        many.status.success(),
        "{}",
        String::from_utf8_lossy(&many.stderr)
    );
    let err = String::from_utf8_lossy(&many.stderr);
    assert!(
        err.contains("warning: --threads 100000 is more than"),
        "{err}"
    );
}

#[test]
fn sobol_draws_need_a_power_of_two_of_samples() {
    let sobol = |t: String, samples: &str| {
        t.replace(
            "samples = 2\n",
            &format!("samples = {samples}\nsequence = \"sobol\"\n"),
        )
    };
    rejects(
        |t| sobol(t, "3"),
        &["sampling.samples", "3", "power of two", "(e.g. 4)"],
    );
    rejects(
        |t| sobol(t, "70000"),
        &["sampling.samples", "70000", "up to 65536"],
    );
    rejects(
        |t| {
            sobol(t, "4").replace(
                "[metrics]",
                "batch = 3\nstop_when = { median_halfwidth_rel = 0.1 }\n[metrics]",
            )
        },
        &["sampling.batch", "3", "power of two"],
    );
    rejects(
        |t| t.replace("samples = 2\n", "samples = 2\nsequence = \"halton\"\n"),
        &["sequence", "halton"],
    );
    // A power of two runs.
    let tmp = tempfile::tempdir().unwrap();
    let (code, err) = run(tmp.path(), &sobol(valid(&tmp.path().join("r")), "4"));
    assert_eq!(code, Some(0), "{err}");
}
