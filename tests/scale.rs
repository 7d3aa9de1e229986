//! A plan of a million runs streams to disk with bounded memory.
//!
//! Its own test binary, so that the process's peak resident memory
//! (VmHWM) is this study's and no other test's.

use autobal::study::plan::config::StudyFile;
use autobal::study::run::{NoProgress, RunOptions, run_study};
use polars::prelude::*;
use std::fs::File;

/// Peak resident memory of this process so far, in bytes (Linux).
fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[test]
fn a_million_runs_stream_to_disk_with_bounded_memory() {
    let out = tempfile::tempdir().unwrap();
    // 20 designs × 50 000 samples at the closed-form fidelity: the runner's
    // own cost per run, not the physics, is what is measured.
    let text = format!(
        r#"
name = "million"
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
n = 3
rho = ["optimal", 0.25, 0.30, 0.35]
race_radius = 0.05
drag = [2.0, 5.0, 10.0, 20.0, 50.0]

[sampling]
samples = 50000
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.9, relative_to = "capacity" }}
# Every run: the runner's streaming is measured, not a race.
racing = false

[solver]
fidelity = "analytic"
"#,
        out.path().display()
    );
    let plan = StudyFile::parse(&text, "million.toml")
        .and_then(|f| f.plan(&text, "million.toml"))
        .unwrap();
    assert_eq!(plan.total_runs(), 1_000_000);
    let before = peak_resident_bytes();
    let output = run_study(&plan, &RunOptions::default(), &NoProgress).unwrap();
    let after = peak_resident_bytes();

    // Every run once, in run order, in row groups of a bounded size.
    assert_eq!(output.runs, 1_000_000);
    let path = output.dir.join("runs.parquet");
    let ids = ParquetReader::new(File::open(&path).unwrap())
        .with_columns(Some(vec!["run_id".into()]))
        .finish()
        .unwrap();
    let ids = ids.column("run_id").unwrap().u64().unwrap();
    assert!(ids.into_no_null_iter().eq(0..1_000_000u64));
    let groups = ParquetReader::new(File::open(&path).unwrap())
        .get_metadata()
        .unwrap()
        .row_groups
        .len();
    assert_eq!(groups, 1_000_000usize.div_ceil(32_768));
    let summary = output.summary.unwrap();
    let runs = summary.column("runs").unwrap().u64().unwrap();
    assert!(runs.into_no_null_iter().all(|r| r == 50_000));
    assert!(!output.dir.join("chunks").exists());

    // The memory bound of docs/running-at-scale.md: about 80 bytes a run
    // beyond a fixed part. Keeping every run in memory, as the runner once
    // did, cost about 2.4 kB a run; 400 bytes leaves room for allocator
    // slack and still fails that.
    if let (Some(before), Some(after)) = (before, after) {
        let per_run = after.saturating_sub(before) as f64 / 1e6;
        assert!(per_run < 400.0, "{per_run:.0} bytes per run");
        eprintln!("peak resident grew by {per_run:.0} bytes per run");
    }
}
