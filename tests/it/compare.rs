//! `study compare`: paired when the designs met the same unbalances,
//! refused pairing (with the reason) and a log-rank test when they did not.

use autobal::study::plan::config::StudyFile;
use autobal::study::run::{NoProgress, RunOptions, run_study};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A two-design study (β = 10 and 50) run into `out` with `seed`.
fn run(out: &Path, seed: u64) -> PathBuf {
    let text = format!(
        r#"
name = "pair"
seed = {seed}
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
drag = [10.0, 50.0]

[sampling]
samples = 24
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.8, relative_to = "capacity" }}

[metrics]
t_end_revs = 800
"#,
        out.display()
    );
    let plan = StudyFile::parse(&text, "pair.toml")
        .and_then(|f| f.plan(&text, "pair.toml"))
        .unwrap();
    run_study(&plan, &RunOptions::default(), &NoProgress)
        .unwrap()
        .dir
}

fn compare(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("compare")
        .args(args)
        // Whole sentences, not wrapped to 80 columns, for the assertions.
        .arg("--wide")
        .output()
        .unwrap()
}

#[test]
fn designs_of_one_study_are_paired_and_foreign_samples_are_not() {
    let tmp = tempfile::tempdir().unwrap();
    let a = run(&tmp.path().join("a"), 7);
    let b = run(&tmp.path().join("b"), 8);
    let (a_s, b_s) = (a.to_str().unwrap(), b.to_str().unwrap());

    // Two designs of one study met the same unbalances: paired.
    let out = compare(&[a_s, "--designs", "0,1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("paired on 24 samples"), "{text}");
    // β = 10 settles sooner than β = 50 on every shared sample (the golden
    // study shows the same ordering at 800 revolutions).
    assert!(text.contains("A settles sooner in 100 %"), "{text}");
    assert!(
        text.contains("verdict: A is better than B on the restricted mean settling time"),
        "{text}"
    );
    // Every measure is listed with its test; the verdict names the one it rests on.
    for line in [
        "median settling time: A",
        "p90 settling time: A",
        "p95 residual/A_ref: A",
    ] {
        assert!(text.contains(line), "{line:?} in {text}");
    }
    assert!(text.contains("paired_t p"), "{text}");
    // The sign test's difference is the median of the paired differences,
    // and "∞" is explained only where one is printed.
    assert!(
        text.contains("median settling time: A")
            && text.contains("median of the paired differences A − B"),
        "{text}"
    );
    let infinite = text
        .lines()
        .any(|l| l.starts_with("paired difference") && l.contains('∞') && !l.contains("(∞:"));
    assert!(!infinite, "{text}");
    if !text
        .lines()
        .filter(|l| l.starts_with("paired difference"))
        .any(|l| l.matches('∞').count() > 1)
    {
        assert!(!text.contains("(∞: B did not settle"), "{text}");
    }
    // --rank-by switches the measure the verdict rests on.
    let out = compare(&[a_s, "--designs", "0,1", "--rank-by", "median"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("verdict: A is better than B on the median settling time"),
        "{text}"
    );
    // A closed stdout ends the verb quietly, without a panic.
    let mut child = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["compare", a_s, "--designs", "0,1"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");

    // The same design in two studies of different seeds: the samples differ,
    // so pairing is refused with the reason and the log-rank test is used.
    let out = compare(&[a_s, b_s, "--designs", "0,0"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(
        text.contains("not paired: sample 0 met a different unbalance"),
        "{text}"
    );
    assert!(text.contains("log-rank test"), "{text}");
    // The same design under two seeds should not be told apart.
    assert!(text.contains("verdict: not distinguishable"), "{text}");

    // Bad input: exit 2 with a sentence naming what is wrong.
    let out = compare(&[a_s]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--designs"));
    let out = compare(&[a_s, "--designs", "0,9"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no design 9"));
    let out = compare(&[tmp.path().to_str().unwrap(), "--designs", "0,1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no finished study"));
    let out = compare(&[a_s, "--designs", "0,1", "--alpha", "2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--alpha"));
}

/// An absolute-unbalance study draws one unbalance in kg·m per sample for
/// every design, whatever its capacity: 3 and 4 balls met the same loads
/// and pair, although their fractions of capacity differ (before, compare
/// refused them on the fraction). The statement says what they shared.
#[test]
fn absolute_unbalances_pair_designs_of_different_capacity_and_say_so() {
    let tmp = tempfile::tempdir().unwrap();
    let text = format!(
        r#"
name = "absolute"
seed = 11
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
n = [3, 4]
rho = 0.25
race_radius = 0.05
drag = 10.0
[sampling]
samples = 8
unbalance = {{ distribution = "uniform", min = 1e-3, max = 3e-3, relative_to = "absolute" }}
[metrics]
t_end_revs = 400
"#,
        tmp.path().join("out").display()
    );
    let plan = StudyFile::parse(&text, "absolute.toml")
        .and_then(|f| f.plan(&text, "absolute.toml"))
        .unwrap();
    let dir = run_study(&plan, &RunOptions::default(), &NoProgress)
        .unwrap()
        .dir;
    let out = compare(&[dir.to_str().unwrap(), "--designs", "0,1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("paired on 8 samples that met the same unbalance in kg·m"),
        "{text}"
    );
    // The main job's form, relative to capacity, says so too.
    let rel = run(&tmp.path().join("rel"), 7);
    let out = compare(&[rel.to_str().unwrap(), "--designs", "0,1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("met the same fraction of each design's capacity"),
        "{text}"
    );
}
