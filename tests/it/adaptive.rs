//! Adaptive sampling: batches until a precision, deterministic, and the same
//! rows as the fixed-sample study it stopped at.

use crate::fixtures::SI_SCENE;
use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::results::io::read_parquet;
use autobal::study::results::runs_file::read_summary_columns;
use autobal::study::run::adaptive::precision;
use autobal::study::run::{NoProgress, RunOptions, Shard, run_study};
use polars::prelude::*;
use std::path::Path;
use std::process::Command;

/// Two ball designs on the main job's rotor; `sampling` is the whole
/// `[sampling]` table's body.
fn study(output: &Path, sampling: &str) -> String {
    format!(
        "name = \"adaptive\"\nseed = 5\noutput = \"{}\"\n{SI_SCENE}
[designs]
kind = \"ball\"
n = 3
rho = \"optimal\"
race_radius = 0.05
drag = [10.0, 50.0]
[sampling]
unbalance = {{ distribution = \"uniform\", min = 0.2, max = 0.8, relative_to = \"capacity\" }}
racing = false
{sampling}
[metrics]
t_end_revs = 400
",
        output.display()
    )
}

fn plan(text: &str) -> StudyPlan {
    StudyFile::parse(text, "adaptive.toml")
        .unwrap()
        .plan(text, "adaptive.toml")
        .unwrap()
}

/// (design, sample) → (outcome, settling time, residual) of a runs file, sorted.
fn rows(dir: &Path) -> DataFrame {
    read_parquet(&dir.join("runs.parquet"))
        .unwrap()
        .select([
            "design_id",
            "sample_id",
            "outcome",
            "settling_revs",
            "residual_rel",
            "unbalance",
        ])
        .unwrap()
        .sort(["design_id", "sample_id"], SortMultipleOptions::default())
        .unwrap()
}

const LOOSE: &str = "samples = 200\nbatch = 10\nstop_when = { median_halfwidth_rel = 0.2 }";

#[test]
fn stops_at_the_first_batch_that_reaches_the_precision() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(&study(dir.path(), LOOSE));
    let out = run_study(&p, &RunOptions::default(), &NoProgress).unwrap();
    let adaptive = out
        .adaptive
        .clone()
        .expect("an adaptive study says where it stopped");
    assert!(adaptive.precision.reached, "{adaptive:?}");
    let s = adaptive.samples_per_design;
    assert!(s < 200 && s.is_multiple_of(10), "{adaptive:?}");
    assert_eq!(adaptive.batches as u32, s / 10);
    // Every design ran exactly the samples 0..s, and nothing beyond.
    assert_eq!(out.runs, 2 * u64::from(s));
    let runs: Vec<Option<u64>> = out
        .summary
        .as_ref()
        .unwrap()
        .column("runs")
        .unwrap()
        .u64()
        .unwrap()
        .iter()
        .collect();
    assert_eq!(runs, vec![Some(u64::from(s)); 2]);
    // The decision is the precision of the runs so far: reached at s, not
    // at any earlier batch.
    let stop = p.file.sampling.stop_when.as_ref().unwrap();
    let all = read_summary_columns(&out.dir.join("runs.parquet")).unwrap();
    let upto = |end: u32| {
        let mask = all.column("sample_id").unwrap().u32().unwrap().lt(end);
        precision(&p, stop, &all.filter(&mask).unwrap()).unwrap()
    };
    assert_eq!(upto(s), adaptive.precision);
    for end in (10..s).step_by(10) {
        assert!(!upto(end).reached, "already reached at {end} samples");
    }
}

#[test]
fn gives_the_rows_and_summary_of_the_fixed_study_it_stopped_at_for_any_thread_count() {
    let (a, b, fixed) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    let run = |dir: &Path, threads, sampling: &str| {
        let opts = RunOptions {
            threads: Some(threads),
            ..RunOptions::default()
        };
        run_study(&plan(&study(dir, sampling)), &opts, &NoProgress).unwrap()
    };
    let one = run(a.path(), 1, LOOSE);
    let two = run(b.path(), 2, LOOSE);
    assert_eq!(one.adaptive, two.adaptive);
    assert!(rows(&one.dir).equals_missing(&rows(&two.dir)));
    let s = one.adaptive.as_ref().unwrap().samples_per_design;
    let same = run(fixed.path(), 2, &format!("samples = {s}"));
    assert!(same.adaptive.is_none());
    assert!(rows(&one.dir).equals_missing(&rows(&same.dir)));
    assert!(
        one.summary
            .as_ref()
            .unwrap()
            .equals_missing(same.summary.as_ref().unwrap())
    );
}

#[test]
fn an_unreachable_precision_runs_to_the_cap_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(&study(
        dir.path(),
        "samples = 30\nbatch = 10\nstop_when = { median_halfwidth_rel = 0.001, win_share_halfwidth = 0.001 }",
    ));
    let out = run_study(&p, &RunOptions::default(), &NoProgress).unwrap();
    let adaptive = out.adaptive.unwrap();
    assert!(!adaptive.precision.reached);
    assert_eq!((adaptive.batches, adaptive.samples_per_design), (3, 30));
    assert_eq!(out.runs, 60);
    let keys: Vec<&str> = adaptive.precision.worst.iter().map(|w| w.0).collect();
    assert_eq!(keys, ["median_halfwidth_rel", "win_share_halfwidth"]);
    assert!(adaptive.precision.worst.iter().all(|(_, v, t)| v > t));
}

#[test]
fn a_sharded_adaptive_study_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(&study(dir.path(), LOOSE));
    let opts = RunOptions {
        shard: Some(Shard { index: 1, count: 2 }),
        ..RunOptions::default()
    };
    let err = run_study(&p, &opts, &NoProgress).unwrap_err();
    assert!(err.is_user_error());
    assert!(err.to_string().contains("stop_when"), "{err}");
}

#[test]
fn the_cli_prints_where_it_stopped_and_refuses_a_bad_precision() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("adaptive.toml");
    std::fs::write(&file, study(&dir.path().join("out"), LOOSE)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", "--quiet"])
        .arg(&file)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("adaptive sampling: precision reached after"),
        "{stdout}"
    );
    for (bad, key) in [
        (
            "samples = 50\nstop_when = { median_halfwidth_rel = 1.5 }",
            "sampling.stop_when.median_halfwidth_rel",
        ),
        ("samples = 50\nstop_when = {}", "sampling.stop_when"),
        (
            "samples = 50\nbatch = 0\nstop_when = { win_share_halfwidth = 0.05 }",
            "sampling.batch",
        ),
    ] {
        let out_dir = dir.path().join("bad");
        std::fs::write(&file, study(&out_dir, bad)).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["run", "--quiet"])
            .arg(&file)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(key), "{key}: {stderr}");
        assert!(!out_dir.exists());
    }
}
