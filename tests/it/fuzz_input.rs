//! Random mutations of the shipped studies and scenes: whatever a file says,
//! `study` answers with exit code 0, 1 or 2 — never a panic, a signal or a
//! hang (each process is time-boxed). Seeded, so a failure reproduces.

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Values a mutation may put where a value was.
const VALUES: &[&str] = &[
    "-1",
    "0",
    "1e308",
    "-1e-300",
    "\"x\"",
    "true",
    "[]",
    "[1, 2]",
    "nan",
    "inf",
    "-inf",
    "3.5",
    "{}",
    "1e-20",
    "99999999999",
    "\"optimal\"",
    "[0.1, \"half_race\"]",
    "2",
];

/// Mutations per shipped file.
const MUTATIONS: usize = 3;

/// Longest a refused or tiny run may take before it counts as a hang.
const TIME_BOX: Duration = Duration::from_secs(60);

fn shipped(dir: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> =
        std::fs::read_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
    v.sort();
    v
}

/// One random edit: a value replaced, a line dropped, or a line doubled.
fn mutate(text: &str, rng: &mut Xoshiro256PlusPlus) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let assignments: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].contains(" = ") && !lines[i].trim_start().starts_with('#'))
        .collect();
    let i = assignments[rng.random_range(0..assignments.len())];
    match rng.random_range(0..3) {
        0 => {
            let key = lines[i].split(" = ").next().unwrap().to_string();
            lines[i] = format!("{key} = {}", VALUES[rng.random_range(0..VALUES.len())]);
        }
        1 => {
            lines.remove(i);
        }
        _ => {
            let line = lines[i].clone();
            lines.insert(i, line);
        }
    }
    lines.join("\n")
}

/// Keep a study small whatever the mutation does to the rest.
fn small(text: &str, results: &Path) -> String {
    let mut out: Vec<String> = text
        .lines()
        .map(|l| {
            let t = l.trim_start();
            if t.starts_with("samples =") {
                "samples = 1".to_string()
            } else if t.starts_with("output =") {
                String::new()
            } else {
                l.to_string()
            }
        })
        .collect();
    out.insert(0, format!("output = \"{}\"", results.display()));
    out.join("\n")
}

fn run_boxed(args: &[&str]) -> (Option<i32>, String) {
    run_boxed_in(Path::new("."), args, TIME_BOX)
}

/// `study args…` in the folder `cwd`: (exit code, stderr); a run longer
/// than `limit` is killed and counts as a hang (the test fails).
/// The command a test's command line names: `bench …` is the benchmark
/// binary's (the harness has a binary of its own), anything else `study`'s.
pub(crate) fn command_for<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Command {
    match args.split_first() {
        Some((first, rest)) if first.as_ref() == "bench" => {
            let mut c = Command::new(env!("CARGO_BIN_EXE_autobal-bench"));
            c.args(rest);
            c
        }
        _ => {
            let mut c = Command::new(env!("CARGO_BIN_EXE_study"));
            c.args(args);
            c
        }
    }
}

pub(crate) fn run_boxed_in<S: AsRef<std::ffi::OsStr> + std::fmt::Debug>(
    cwd: &Path,
    args: &[S],
    limit: Duration,
) -> (Option<i32>, String) {
    let mut child = command_for(args)
        .current_dir(cwd)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            return (status.code(), err);
        }
        if start.elapsed() > limit {
            child.kill().unwrap();
            panic!("study {args:?} did not finish within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn mutated_studies_and_scenes_never_crash_or_hang() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(20261125);
    let mut failures = Vec::new();
    for (verb, dir) in [("simulate", "scenes"), ("run", "studies")] {
        for file in shipped(dir) {
            let text = std::fs::read_to_string(&file).unwrap();
            for _ in 0..MUTATIONS {
                let tmp = tempfile::tempdir().unwrap();
                let mut mutated = mutate(&text, &mut rng);
                if verb == "run" {
                    mutated = small(&mutated, &tmp.path().join("results"));
                }
                let path = tmp.path().join("mutated.toml");
                std::fs::write(&path, &mutated).unwrap();
                let (code, err) = run_boxed(
                    &[verb, path.to_str().unwrap(), "--quiet"][..if verb == "run" { 3 } else { 2 }],
                );
                if !matches!(code, Some(0..=2)) || err.contains("panicked") {
                    failures.push(format!(
                        "{}: exit {code:?}: {err}\n{mutated}",
                        file.display()
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n---\n"));
}
