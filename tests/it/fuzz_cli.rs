//! Random hostile command lines on every verb (issue 33): each verb's
//! options are read from its own `--help`, so a new option is fuzzed
//! without editing this file. Whatever the values, `study` answers with
//! exit code 0, 1 or 2 — never a panic, a signal or a hang — and a refusal
//! (exit 2) leaves the working folder exactly as it was, with no temporary
//! file anywhere. Seeded, so a failure reproduces.

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// Values a flag may be given (no absolute path: whatever a verb accepts is
/// written inside the test's folder).
const VALUES: &[&str] = &[
    "-1",
    "0",
    "1e308",
    "nan",
    "inf",
    "x",
    "",
    "99999999999",
    "18446744073709551616",
    "3.5",
    "2",
    "1..0",
    "0.5..8",
    "2x0",
    "3x3",
    // Paths stay inside the working folder: the test may run as root.
    "results",
    "corpus.toml",
    "missing/dir/f.svg",
    "out.svg",
    "out.parquet",
    "1/2",
    "3/2",
    "median",
    "0,0",
];

/// Command lines per verb.
const ROUNDS: usize = 6;

/// Longest a command may take before it counts as a hang.
const TIME_BOX: Duration = Duration::from_secs(90);

/// A verb and its positional arguments (relative to the working folder).
fn verbs() -> Vec<Vec<&'static str>> {
    vec![
        vec!["run", "corpus.toml"],
        vec!["merge", "results/corpus"],
        vec!["simulate", "scene.toml"],
        vec!["design"],
        vec!["optimize", "corpus.toml"],
        vec!["compare", "results/corpus"],
        vec!["claims", "corpus.toml"],
        vec!["tradeoff", "corpus.toml"],
        vec!["check", "corpus.toml"],
        vec!["baseline", "corpus.toml"],
        vec!["plot", "run", "scene.toml"],
        vec!["plot", "study", "results/corpus"],
        vec!["plot", "design"],
        vec!["plot", "map", "scene.toml"],
        vec!["report", "results/corpus"],
        vec!["linear", "scene.toml"],
        vec!["criterion", "scene.toml"],
        vec!["sweep", "scene.toml", "--omega", "1..4"],
        vec![
            "map",
            "scene.toml",
            "--omega",
            "1..4",
            "--unbalance",
            "0.001..0.002",
        ],
        vec!["bench", "--quick"],
        vec!["completions", "bash"],
        vec!["schema", "study"],
    ]
}

/// (flag, takes a value) of every option `study <verb> --help` lists.
fn options(verb: &[&str]) -> Vec<(String, bool)> {
    let words: Vec<&str> = verb
        .iter()
        .take_while(|w| !w.contains('.'))
        .copied()
        .collect();
    let help = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(&words)
        .arg("--help")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&help.stdout).to_string();
    let mut out = Vec::new();
    for line in text.lines() {
        let t = line.trim_start();
        let Some(at) = t.find("--") else { continue };
        if !(t.starts_with("--") || t.starts_with('-') && t.get(2..4) == Some(", ")) {
            continue;
        }
        let rest = &t[at..];
        let flag: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '-')
            .collect();
        if flag == "--help" || flag == "--version" || flag.len() < 3 {
            continue;
        }
        let takes_value = rest[flag.len()..].trim_start().starts_with('<');
        out.push((flag, takes_value));
    }
    out
}

/// Every entry below `dir`, sorted, with each file's length.
fn snapshot(dir: &Path) -> Vec<(PathBuf, u64)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            let len = e
                .metadata()
                .map_or(0, |m| if m.is_file() { m.len() } else { 0 });
            out.push((p.strip_prefix(dir).unwrap().to_path_buf(), len));
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    out.sort();
    out
}

fn run_boxed(cwd: &Path, args: &[String]) -> (Option<i32>, String) {
    crate::fuzz_input::run_boxed_in(cwd, args, TIME_BOX)
}

#[test]
fn hostile_options_on_every_verb_never_crash_hang_or_write_before_refusing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let study = crate::bad_input::study(Path::new("results")).replace(
        "[sampling]\nsamples = 2",
        "[optimize]\nobjective = \"capacity\"\nfree = [\"rho\"]\n[sampling]\nsamples = 1",
    );
    assert!(study.contains("[optimize]"));
    std::fs::write(dir.join("corpus.toml"), &study).unwrap();
    std::fs::write(dir.join("scene.toml"), crate::bad_input::scene()).unwrap();
    let first = run_boxed(dir, &["run".into(), "corpus.toml".into(), "--quiet".into()]);
    assert_eq!(first.0, Some(0), "{}", first.1);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(20261126);
    let mut failures = Vec::new();
    let mut tried = 0;
    let mut read = 0;
    for verb in verbs() {
        let options = options(&verb);
        assert!(
            matches!(verb[0], "completions" | "schema") || !options.is_empty(),
            "no options read from {verb:?} --help"
        );
        read += options.len();
        for _ in 0..ROUNDS {
            let mut args: Vec<String> = verb.iter().map(|s| s.to_string()).collect();
            let mut used = Vec::new();
            for _ in 0..rng.random_range(1..=3usize) {
                let Some((flag, takes_value)) =
                    options.get(rng.random_range(0..options.len().max(1)))
                else {
                    break;
                };
                // A flag given twice is clap's refusal, not the verb's.
                if used.contains(flag) {
                    continue;
                }
                used.push(flag.clone());
                args.push(flag.clone());
                if *takes_value {
                    args.push(VALUES[rng.random_range(0..VALUES.len())].to_string());
                }
            }
            let before = snapshot(dir);
            let (code, err) = run_boxed(dir, &args);
            tried += 1;
            let after = snapshot(dir);
            if !matches!(code, Some(0..=2)) || err.contains("panicked") {
                failures.push(format!("{args:?}: exit {code:?}: {err}"));
            } else if code == Some(2) && after != before {
                failures.push(format!("{args:?}: exit 2 but the folder changed: {err}"));
            }
            if let Some((p, _)) = after
                .iter()
                .find(|(p, _)| p.to_string_lossy().contains(".tmp-") || p.ends_with(".lock"))
            {
                failures.push(format!("{args:?}: left {} behind", p.display()));
            }
        }
    }
    assert!(tried >= 120, "only {tried} command lines");
    assert!(read >= 60, "only {read} options read from the verbs' help");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
