//! `autobal-bench` through the command line: structure of its JSON output and
//! its option checks. The measurements themselves are unit-tested in the
//! binary (`src/bin/autobal-bench/bench/`). Wall-clock figures are never asserted
//! (the machine is shared and noisy).

use autobal::integrate::Method;
use std::process::Command;

/// The benchmark's cargo counts and tolerances (`src/bin/autobal-bench/bench/`,
/// whose unit tests check the report against its own constants).
const CARGO_COUNTS: usize = 7;
const RTOLS: usize = 2;

fn bench(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_autobal-bench"))
        .args(args)
        .output()
        .expect("autobal-bench runs")
}

#[test]
fn bench_quick_json() {
    let out = bench(&["--quick", "--json", "--revolutions", "5"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["config"]["revolutions"], 5.0);
    assert_eq!(v["rhs"]["points"].as_array().unwrap().len(), CARGO_COUNTS);
    let solves = v["solves"].as_array().unwrap();
    assert_eq!(solves.len(), Method::ALL.len() * RTOLS);
    assert_eq!(solves[0]["method"], "dp5");
    for key in [
        "median_ms",
        "us_per_revolution",
        "stats",
        "counted_rhs_calls",
    ] {
        assert!(solves[0].get(key).is_some(), "missing {key}");
    }
}

#[test]
fn bench_rejects_bad_options_and_documents_itself() {
    let out = bench(&["--repeats", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--repeats"));
    let help = bench(&["--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.contains("Examples:"), "{text}");
    // It says what it is, not what the designer's binary is.
    assert!(text.starts_with("Time autobal's ODE core"), "{text}");
}

#[test]
fn bench_peer_cases_and_thread_scaling_json() {
    let out = bench(&["--peer-cases", "--quick", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["y0", "scale", "t_end", "rhs_samples", "reference", "cases"] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["cases"][0]["method"], "dp5");

    let out = bench(&["--thread-scaling", "--quick", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["identical_results"], true);
    assert_eq!(v["timings"].as_array().unwrap().len(), 2);

    let both = bench(&["--peer-cases", "--thread-scaling"]);
    assert_eq!(both.status.code(), Some(2));
}

#[test]
fn bench_lean_inputs_writes_one_row_per_run() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("runs.csv");
    let out = bench(&["--lean-inputs", path.to_str().unwrap(), "--samples", "1"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    // The main job's 20 designs, one sample each, under one header.
    assert_eq!(lines.len(), 1 + 20);
    assert!(lines[0].starts_with("run_id,design_id,sample_id,n,omega,"));
    let columns = lines[0].split(',').count();
    assert!(lines.iter().all(|l| l.split(',').count() == columns));

    // --samples means nothing on its own.
    let alone = bench(&["--samples", "3"]);
    assert_eq!(alone.status.code(), Some(2));
}

#[test]
fn racing_looks_replay_the_race_the_study_makes() {
    // The main job at 200 samples per design (4 000 runs, 20 looks of 10):
    // the replay makes the race the raced study makes, looks until it ends,
    // and never more runs than every sample.
    let out = bench(&[
        "--racing-looks",
        "--samples",
        "200",
        "--repeats",
        "1",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["runs_every_sample"], 4000);
    let looks = v["looks"].as_array().unwrap();
    assert!(
        !looks.is_empty() && looks.len() <= 19,
        "{} looks",
        looks.len()
    );
    let left: u64 = looks.iter().map(|l| l["left"].as_u64().unwrap()).sum();
    let raced = v["runs_raced"].as_u64().unwrap();
    assert!(
        raced <= 4000 && (left == 0) == (raced == 4000),
        "{left} left, {raced} runs"
    );
    assert!(v["max_ms"].as_f64().unwrap() >= v["median_ms"].as_f64().unwrap());
}

#[test]
fn the_designers_binary_lists_no_benchmark() {
    let help = Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("--help")
        .output()
        .expect("study runs");
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.contains("run") && text.contains("simulate"), "{text}");
    assert!(
        !text.lines().any(|l| l.trim_start().starts_with("bench")),
        "{text}"
    );
    let refused = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["bench", "--quick"])
        .output()
        .expect("study runs");
    assert_eq!(refused.status.code(), Some(2));
}
