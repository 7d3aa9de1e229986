//! Random hostile command lines on every verb (issue 33): each verb's
//! options are read from its own `--help`, so a new option is fuzzed
//! without editing this file. Whatever the values, `study` answers with
//! exit code 0, 1 or 2 — never a panic, a signal or a hang — and a refusal
//! (exit 2) leaves the working folder exactly as it was, with no temporary
//! file anywhere. Seeded, so a failure reproduces. Every path flag, read
//! from the command definition, also meets the paths a hostile user gives
//! (issue 46): a refusal names the flag.

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
    let help = crate::fuzz_input::command_for(&words)
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

/// Every path flag of every verb, as (verb words, flag), read from the
/// command definition itself (the fish completion script clap writes marks
/// a path with `-r -F`): a path flag added tomorrow is fuzzed without
/// editing this file.
fn path_flags() -> Vec<(Vec<String>, String)> {
    let script = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["completions", "fish"])
        .output()
        .unwrap();
    let script = String::from_utf8_lossy(&script.stdout).to_string();
    let mut out = Vec::new();
    for line in script.lines().filter(|l| l.ends_with(" -r -F")) {
        let Some(condition) = line.split("-n \"").nth(1).and_then(|c| c.split('"').next()) else {
            continue;
        };
        let Some(flag) = line.split(" -l ").nth(1).and_then(|f| f.split(' ').next()) else {
            continue;
        };
        let word_after = |mark: &str| {
            condition
                .split(mark)
                .nth(1)
                .map(|w| w.split([';', ' ']).next().unwrap_or("").to_string())
        };
        let Some(verb) = word_after("__fish_study_using_subcommand ") else {
            continue;
        };
        let mut words = vec![verb];
        words.extend(word_after("__fish_seen_subcommand_from "));
        out.push((words, format!("--{flag}")));
    }
    // The benchmark binary writes no completions; its path flags by name.
    for flag in ["--lean-inputs", "--lean-study"] {
        out.push((vec!["bench".to_string()], flag.to_string()));
    }
    out
}

/// A command line of `verb` that does its job when the path flag gets a
/// good value (so that a refusal can only be about the flag), and the
/// extension such a value has.
fn path_base(verb: &[String], flag: &str) -> Option<(Vec<&'static str>, &'static str)> {
    let words: Vec<&str> = verb.iter().map(String::as_str).collect();
    Some(match (words.as_slice(), flag) {
        (["merge"], _) => (
            vec![
                "merge",
                "results/corpus/shard-1-of-2",
                "results/corpus/shard-2-of-2",
            ],
            "d",
        ),
        (["simulate"], _) => (vec!["simulate", "scene.toml"], "csv"),
        (["compare"], _) => (vec!["compare", "results/corpus", "--designs", "0,1"], "svg"),
        (["calibrate"], _) => (
            vec![
                "calibrate",
                "rig.toml",
                "--draws",
                "4",
                "--restarts",
                "1",
                "--budget",
                "4",
            ],
            "d",
        ),
        (["claims"], _) => (vec!["claims", "corpus.toml"], "md"),
        (["check"], _) => (vec!["check", "corpus.toml"], "parquet"),
        (["baseline"], _) => (vec!["baseline", "corpus.toml"], "d"),
        (["plot", "run"], _) => (vec!["plot", "run", "scene.toml"], "svg"),
        (["plot", "study"], _) => (vec!["plot", "study", "results/corpus"], "d"),
        (["plot", "design"], _) => (vec!["plot", "design", "--n", "2"], "svg"),
        (["plot", "tradeoff"], _) => (vec!["plot", "tradeoff", "tradeoff.parquet"], "svg"),
        (["plot", "map"], _) => (vec!["plot", "map", "map.parquet"], "svg"),
        (["report"], _) => (vec!["report", "results/corpus"], "html"),
        (["sweep"], _) => (
            vec!["sweep", "scene.toml", "--omega", "1..4", "--points", "2"],
            "parquet",
        ),
        (["stepped"], _) => (
            vec![
                "stepped",
                "scene.toml",
                "--rpm",
                "10..20",
                "--step-rpm",
                "10",
                "--dwell",
                "2",
                "--up-only",
            ],
            "parquet",
        ),
        (["map"], _) => (
            vec![
                "map",
                "scene.toml",
                "--omega",
                "1..4",
                "--unbalance",
                "0.001..0.002",
                "--points",
                "2x2",
            ],
            "parquet",
        ),
        (["bench"], "--lean-study") => (
            vec!["bench", "--lean-inputs", "lean.csv", "--samples", "1"],
            "toml",
        ),
        (["bench"], _) => (vec!["bench", "--samples", "1"], "csv"),
        _ => return None,
    })
}

/// The hostile values of a path flag whose good values end in `.ext`:
/// a folder, a trailing `/`, a trailing `/.`, a read-only folder, a
/// symbolic link to a file and a missing folder.
fn hostile_paths(ext: &str) -> [String; 6] {
    [
        "a_folder".into(),
        format!("new.{ext}/"),
        format!("new.{ext}/."),
        format!("ro/new.{ext}"),
        format!("link.{ext}"),
        format!("missing/new.{ext}"),
    ]
}

/// Put the fixtures of [`hostile_paths`] back as they were, and remove
/// whatever an accepted command added beside them.
#[cfg(unix)]
fn reset_path_fixtures(dir: &Path, keep: &[std::ffi::OsString]) {
    use std::os::unix::fs::PermissionsExt;
    let ro = dir.join("ro");
    if ro.exists() {
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if keep.contains(&e.file_name()) {
            continue;
        }
        let p = e.path();
        if e.file_type().unwrap().is_dir() {
            std::fs::remove_dir_all(&p).unwrap();
        } else {
            std::fs::remove_file(&p).unwrap();
        }
    }
    for d in ["a_folder", "ro"] {
        std::fs::create_dir(dir.join(d)).unwrap();
    }
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    for ext in ["d", "csv", "svg", "md", "parquet", "html", "toml"] {
        let target = format!("target.{ext}");
        std::fs::write(dir.join(&target), b"keep").unwrap();
        std::os::unix::fs::symlink(&target, dir.join(format!("link.{ext}"))).unwrap();
    }
}

/// Seconds the path-flag fuzz may spend (CI's budget for it).
const PATH_FUZZ_BUDGET: Duration = Duration::from_secs(50);

#[cfg(unix)]
#[test]
fn every_path_flag_of_every_verb_refuses_folders_links_and_missing_or_read_only_folders_naming_the_flag()
 {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Two designs, so that `compare --designs 0,1` has two to compare.
    let study = crate::bad_input::study(Path::new("results")).replace("n = 3\n", "n = [3, 4]\n");
    std::fs::write(dir.join("corpus.toml"), &study).unwrap();
    std::fs::write(dir.join("scene.toml"), crate::bad_input::scene()).unwrap();
    std::fs::write(
        dir.join("rig.toml"),
        "name = \"fuzz\"\nscene = \"scene.toml\"\n[unknowns]\n\"rotor.bx\" = { distribution = \"uniform\", min = 0.05, max = 0.2 }\n[protocol]\nkind = \"run\"\n[[case]]\nname = \"one\"\n[[point]]\ncase = \"one\"\nquantity = \"residual\"\nvalue = 1e-3\nsd = 1e-4\n",
    )
    .unwrap();
    for setup in [
        vec!["run", "corpus.toml", "--quiet"],
        vec!["run", "corpus.toml", "--quiet", "--shard", "1/2"],
        vec!["run", "corpus.toml", "--quiet", "--shard", "2/2"],
        vec!["baseline", "corpus.toml"],
        vec![
            "map",
            "scene.toml",
            "--omega",
            "1..4",
            "--unbalance",
            "0.001..0.002",
            "--points",
            "2x2",
            "--out",
            "map.parquet",
        ],
    ] {
        let (code, err) = run_boxed(
            dir,
            &setup.iter().map(|s| s.to_string()).collect::<Vec<_>>(),
        );
        assert_eq!(code, Some(0), "{setup:?}: {err}");
    }
    let mut table = polars::prelude::df!(
        "fidelity" => ["full", "full"],
        "rtol" => [1e-3, 1e-6],
        "settling_error_revs" => [0.5, 0.01],
        "rhs_calls" => [100u64, 1000],
        "wall_time_s" => [0.01, 0.1],
    )
    .unwrap();
    autobal::study::results::io::write_parquet(
        &dir.join("tradeoff.parquet"),
        &mut table,
        &autobal::study::results::io::Provenance::new("tradeoff fixture", 0, "all"),
    )
    .unwrap();
    let keep: Vec<std::ffi::OsString> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    let flags = path_flags();
    assert!(
        flags.len() >= 15,
        "only {} path flags read: {flags:?}",
        flags.len()
    );
    // Breadth first: every flag meets its first hostile value before any
    // meets its second, so that the time box never leaves a flag untried.
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(20261127);
    let mut cases: Vec<(usize, Vec<String>, String)> = Vec::new();
    for (verb, flag) in &flags {
        let (base, ext) = path_base(verb, flag).unwrap_or_else(|| {
            panic!("{verb:?} {flag}: no command line in path_base; add one for the new verb")
        });
        let mut values = hostile_paths(ext).to_vec();
        for i in (1..values.len()).rev() {
            values.swap(i, rng.random_range(0..=i));
        }
        for (round, value) in values.into_iter().enumerate() {
            let mut args: Vec<String> = base.iter().map(|s| s.to_string()).collect();
            args.push(flag.clone());
            args.push(value);
            cases.push((round, args, flag.clone()));
        }
    }
    cases.sort_by_key(|(round, _, _)| *round);
    let start = std::time::Instant::now();
    let mut failures = Vec::new();
    let (mut tried, mut refused) = (0, 0);
    for (round, args, flag) in cases {
        if start.elapsed() > PATH_FUZZ_BUDGET && round > 0 {
            break;
        }
        reset_path_fixtures(dir, &keep);
        let before = snapshot(dir);
        let (code, err) = run_boxed(dir, &args);
        let after = snapshot(dir);
        tried += 1;
        match code {
            Some(0 | 1) => {}
            Some(2) => {
                refused += 1;
                if !err.contains(&flag) {
                    failures.push(format!("{args:?}: refused without naming {flag}: {err}"));
                }
                if after != before {
                    failures.push(format!("{args:?}: exit 2 but the folder changed: {err}"));
                }
            }
            other => failures.push(format!("{args:?}: exit {other:?}: {err}")),
        }
        if err.contains("panicked") {
            failures.push(format!("{args:?}: {err}"));
        }
        if let Some((p, _)) = after
            .iter()
            .find(|(p, _)| p.to_string_lossy().contains(".tmp-") || p.ends_with(".lock"))
        {
            failures.push(format!("{args:?}: left {} behind", p.display()));
        }
    }
    reset_path_fixtures(dir, &keep);
    assert!(
        tried >= flags.len(),
        "only {tried} command lines in the time box"
    );
    assert!(refused >= flags.len(), "only {refused} refusals of {tried}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
