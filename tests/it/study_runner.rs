//! The study runner: determinism, sharding, resume, statistics, bad input.

use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::results::io::read_parquet;
use autobal::study::results::record::deterministic_columns;
use autobal::study::run::{NoProgress, RunOptions, Shard, run_study};
use polars::prelude::*;
use std::path::Path;
use std::process::Command;

/// A small, fast study: two ball designs, dimensionless-ish rotor.
fn small_study(output: &Path, samples: u32, extra: &str) -> String {
    format!(
        r#"
name = "small"
seed = 7
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
samples = {samples}
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.8, relative_to = "capacity" }}

[metrics]
t_end_revs = 800
{extra}
"#,
        output.display()
    )
}

fn plan(text: &str) -> StudyPlan {
    StudyFile::parse(text, "small.toml")
        .unwrap()
        .plan(text, "small.toml")
        .unwrap()
}

/// The deterministic columns of a Parquet file (wall time left out).
fn stable(path: &Path) -> DataFrame {
    let df = read_parquet(path).unwrap();
    let cols = deterministic_columns(&df);
    df.select(cols).unwrap()
}

#[test]
fn results_are_identical_for_one_and_two_threads() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let run = |dir: &Path, threads| {
        let p = plan(&small_study(dir, 12, ""));
        let opts = RunOptions {
            threads: Some(threads),
            ..RunOptions::default()
        };
        run_study(&p, &opts, &NoProgress).unwrap().dir
    };
    let (da, db) = (run(a.path(), 1), run(b.path(), 2));
    assert!(stable(&da.join("runs.parquet")).equals_missing(&stable(&db.join("runs.parquet"))));
    assert!(
        read_parquet(&da.join("summary.parquet"))
            .unwrap()
            .equals_missing(&read_parquet(&db.join("summary.parquet")).unwrap())
    );
}

#[test]
fn sharded_and_merged_equals_whole() {
    let whole = tempfile::tempdir().unwrap();
    let sharded = tempfile::tempdir().unwrap();
    let p = plan(&small_study(whole.path(), 10, ""));
    let dir = run_study(&p, &RunOptions::default(), &NoProgress)
        .unwrap()
        .dir;
    let p = plan(&small_study(sharded.path(), 10, ""));
    let mut dirs = Vec::new();
    for k in 1..=3 {
        let opts = RunOptions {
            shard: Some(Shard { index: k, count: 3 }),
            ..RunOptions::default()
        };
        let out = run_study(&p, &opts, &NoProgress).unwrap();
        assert!(out.summary.is_none());
        assert!(
            out.load_runs()
                .unwrap()
                .iter()
                .all(|r| r.run_id % 3 == u64::from(k - 1))
        );
        dirs.push(out.dir);
    }
    // Shards are disjoint and together hold every run.
    let merged = autobal::study::run::merge::merge(&dirs, None, false).unwrap();
    // A second merge into the same folder needs to say it replaces the first.
    let again = autobal::study::run::merge::merge(&dirs, None, false).unwrap_err();
    assert!(
        again.to_string().contains("already holds results"),
        "{again}"
    );
    autobal::study::run::merge::merge(&dirs, None, true).unwrap();
    assert_eq!(merged.runs, 20);
    assert_eq!(merged.load_runs().unwrap().len(), 20);
    assert!(
        stable(&dir.join("runs.parquet")).equals_missing(&stable(&merged.dir.join("runs.parquet")))
    );
    assert!(
        read_parquet(&dir.join("summary.parquet"))
            .unwrap()
            .equals_missing(&read_parquet(&merged.dir.join("summary.parquet")).unwrap())
    );
    // Merging an incomplete set fails and names what is missing.
    let err =
        autobal::study::run::merge::merge(&dirs[..2], Some(&sharded.path().join("partial")), false)
            .unwrap_err();
    assert!(err.to_string().contains("missing"), "{err}");
}

/// Wait until a run has saved at least one chunk of finished runs.
fn wait_for_a_chunk(chunks: &Path) {
    let start = std::time::Instant::now();
    while !std::fs::read_dir(chunks).is_ok_and(|d| {
        d.filter_map(Result::ok)
            .any(|e| e.file_name().to_string_lossy().ends_with(".arrow"))
    }) {
        assert!(start.elapsed().as_secs() < 60, "no chunk appeared");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

#[test]
fn resume_after_a_kill_ends_with_the_same_files() {
    let whole = tempfile::tempdir().unwrap();
    let killed = tempfile::tempdir().unwrap();
    let text = small_study(killed.path(), 150, "");
    let study = killed.path().join("small.toml");
    std::fs::write(&study, &text).unwrap();
    let out = killed.path().join("small");
    let mut child = Command::new(env!("CARGO_BIN_EXE_study"))
        .args([
            "run",
            study.to_str().unwrap(),
            "--quiet",
            "--chunk-runs",
            "5",
            "--threads",
            "1",
        ])
        .spawn()
        .unwrap();
    // Kill once at least one chunk of finished runs is on disk.
    wait_for_a_chunk(&out.join("chunks"));
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !out.join("runs.parquet").exists(),
        "the run must have been interrupted"
    );
    let status = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", study.to_str().unwrap(), "--quiet", "--resume"])
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let p = plan(&small_study(whole.path(), 150, ""));
    let dir = run_study(&p, &RunOptions::default(), &NoProgress)
        .unwrap()
        .dir;
    assert!(stable(&dir.join("runs.parquet")).equals_missing(&stable(&out.join("runs.parquet"))));
    assert!(!out.join("chunks").exists());
}

#[test]
fn ctrl_c_saves_the_finished_runs_leaves_no_temporary_file_and_resume_completes() {
    let whole = tempfile::tempdir().unwrap();
    let stopped = tempfile::tempdir().unwrap();
    let text = small_study(stopped.path(), 150, "");
    let study = stopped.path().join("small.toml");
    std::fs::write(&study, &text).unwrap();
    let out = stopped.path().join("small");
    // Not quiet: the batch log's closing line must not claim "finished".
    let child = Command::new(env!("CARGO_BIN_EXE_study"))
        .args([
            "run",
            study.to_str().unwrap(),
            "--progress-every",
            "1000",
            "--chunk-runs",
            "5",
            "--threads",
            "1",
        ])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let chunks = out.join("chunks");
    wait_for_a_chunk(&chunks);
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let ended = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&ended.stderr);
    assert_eq!(ended.status.code(), Some(130), "{err}");
    assert!(
        err.contains("interrupted after ")
            && err.contains(" of 300 runs")
            && err.contains("--resume"),
        "{err}"
    );
    assert!(
        !err.contains("finished"),
        "an interrupted study said finished: {err}"
    );
    assert_eq!(
        err.lines().filter(|l| l.contains("interrupted")).count(),
        1,
        "{err}"
    );
    assert!(!out.join("runs.parquet").exists());
    // Nothing temporary is left: no lock, no half-written file.
    let mut leftovers = Vec::new();
    for dir in [&out, &chunks] {
        for entry in std::fs::read_dir(dir).unwrap().filter_map(Result::ok) {
            let name = entry.file_name().to_string_lossy().to_string();
            if name == ".lock" || name.contains(".tmp-") {
                leftovers.push(name);
            }
        }
    }
    assert!(leftovers.is_empty(), "{leftovers:?}");
    let resumed = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", study.to_str().unwrap(), "--quiet", "--resume"])
        .output()
        .unwrap();
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    let p = plan(&small_study(whole.path(), 150, ""));
    let dir = run_study(&p, &RunOptions::default(), &NoProgress)
        .unwrap()
        .dir;
    assert!(stable(&dir.join("runs.parquet")).equals_missing(&stable(&out.join("runs.parquet"))));
}

#[test]
fn a_killed_and_resumed_shard_merges_into_the_whole() {
    let whole = tempfile::tempdir().unwrap();
    let sharded = tempfile::tempdir().unwrap();
    let text = small_study(sharded.path(), 150, "");
    let study = sharded.path().join("small.toml");
    std::fs::write(&study, &text).unwrap();
    let shard_dir = |k: u32| sharded.path().join("small").join(format!("shard-{k}-of-2"));
    // Shard 1 is killed once it has saved a chunk, then resumed.
    let mut child = Command::new(env!("CARGO_BIN_EXE_study"))
        .args([
            "run",
            study.to_str().unwrap(),
            "--quiet",
            "--shard",
            "1/2",
            "--chunk-runs",
            "5",
            "--threads",
            "1",
        ])
        .spawn()
        .unwrap();
    wait_for_a_chunk(&shard_dir(1).join("chunks"));
    child.kill().unwrap();
    child.wait().unwrap();
    for args in [vec!["--shard", "1/2", "--resume"], vec!["--shard", "2/2"]] {
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["run", study.to_str().unwrap(), "--quiet"])
            .args(&args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let merged =
        autobal::study::run::merge::merge(&[shard_dir(1), shard_dir(2)], None, false).unwrap();
    let p = plan(&small_study(whole.path(), 150, ""));
    let dir = run_study(&p, &RunOptions::default(), &NoProgress)
        .unwrap()
        .dir;
    assert!(
        stable(&dir.join("runs.parquet")).equals_missing(&stable(&merged.dir.join("runs.parquet")))
    );
}

#[test]
fn resume_refuses_a_changed_study() {
    let tmp = tempfile::tempdir().unwrap();
    let study = tmp.path().join("small.toml");
    std::fs::write(&study, small_study(tmp.path(), 2, "")).unwrap();
    let ok = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", study.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    assert!(ok.status.success());
    std::fs::write(&study, small_study(tmp.path(), 3, "")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", study.to_str().unwrap(), "--quiet", "--resume"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("study file changed"));
}

#[test]
fn golden_study_makes_physical_sense() {
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(&small_study(tmp.path(), 24, ""));
    let out = run_study(&p, &RunOptions::default(), &NoProgress).unwrap();
    let summary = out.summary.unwrap();
    let frac: Vec<f64> = summary
        .column("settled_fraction")
        .unwrap()
        .f64()
        .unwrap()
        .no_null_iter()
        .collect();
    let median: Vec<f64> = summary
        .column("settling_revs_median_km")
        .unwrap()
        .f64()
        .unwrap()
        .iter()
        .map(Option::unwrap)
        .collect();
    // Three times above resonance every run settles …
    assert!(frac.iter().all(|f| *f == 1.0), "{frac:?}");
    // … and in the overdamped regime more drag is slower (β = 50 vs 10).
    assert!(median[1] > median[0] * 1.3, "{median:?}");
    // Summary columns the README promises.
    for c in [
        "settled_fraction_lo",
        "settling_revs_median_km_lo",
        "settling_revs_rmst",
        "settling_revs_rmst_hi",
        "vs_best_verdict",
        "vs_best_p_holm",
        "residual_rel_p95",
        "diverged",
    ] {
        assert!(summary.column(c).is_ok(), "{c}");
    }
}

#[test]
fn provenance_is_stored_in_the_parquet_metadata() {
    let tmp = tempfile::tempdir().unwrap();
    let text = small_study(tmp.path(), 2, "");
    let out = run_study(&plan(&text), &RunOptions::default(), &NoProgress).unwrap();
    let meta = autobal::study::results::io::read_metadata(&out.dir.join("runs.parquet")).unwrap();
    let get = |k: &str| {
        meta.iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.clone())
            .unwrap()
    };
    // The study text is stored once, beside the files, not in each of them.
    assert!(meta.iter().all(|(key, _)| key != "study_toml"));
    assert_eq!(
        std::fs::read_to_string(out.dir.join("study.toml")).unwrap(),
        text
    );
    assert_eq!(get("seed"), "7");
    assert_eq!(get("shard"), "all");
    assert_eq!(
        get("study_sha256"),
        autobal::study::results::io::sha256_hex(&text)
    );
    assert_eq!(get("autobal_version"), env!("CARGO_PKG_VERSION"));
    // The build that ran, as `study --version` says it.
    assert_eq!(get("build"), autobal::build_info::VERSION_LINE);
    assert_eq!(get("git_commit"), autobal::build_info::commit_label());
}

/// Runs spanning several row-group windows of `runs.parquet` (32 768 run ids
/// each) give the same table whole, sharded and merged, or with small chunks.
#[test]
fn runs_spanning_several_windows_are_the_same_however_split() {
    let extra = "[solver]\nfidelity = \"analytic\"\n";
    let whole = tempfile::tempdir().unwrap();
    // Every run, to span the windows: no race.
    let every = |dir: &Path| {
        small_study(dir, 20_000, extra).replace("[sampling]\n", "[sampling]\nracing = false\n")
    };
    let p = plan(&every(whole.path()));
    let out = run_study(&p, &RunOptions::default(), &NoProgress).unwrap();
    assert_eq!(out.runs, 40_000);
    let reference = stable(&out.dir.join("runs.parquet"));
    let ids: Vec<u64> = reference
        .column("run_id")
        .unwrap()
        .u64()
        .unwrap()
        .into_no_null_iter()
        .collect();
    assert!(ids.iter().copied().eq(0..40_000));

    let small_chunks = tempfile::tempdir().unwrap();
    let p = plan(&every(small_chunks.path()));
    let opts = RunOptions {
        chunk_runs: 97,
        threads: Some(2),
        ..RunOptions::default()
    };
    let out = run_study(&p, &opts, &NoProgress).unwrap();
    assert!(reference.equals_missing(&stable(&out.dir.join("runs.parquet"))));

    let sharded = tempfile::tempdir().unwrap();
    let p = plan(&every(sharded.path()));
    let dirs: Vec<_> = (1..=3)
        .map(|k| {
            let opts = RunOptions {
                shard: Some(Shard { index: k, count: 3 }),
                ..RunOptions::default()
            };
            run_study(&p, &opts, &NoProgress).unwrap().dir
        })
        .collect();
    let merged = autobal::study::run::merge::merge(&dirs, None, false).unwrap();
    assert!(reference.equals_missing(&stable(&merged.dir.join("runs.parquet"))));
}

/// In a batch log (stderr not a terminal) `study run` says every few
/// seconds how far it is, and says nothing with `--quiet`.
#[test]
fn a_batch_log_shows_progress_lines_and_quiet_silences_them() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("small.toml");
    std::fs::write(&file, small_study(tmp.path(), 6, "")).unwrap();
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_study"))
            .arg("run")
            .arg(&file)
            .args(["--overwrite", "--threads", "1"])
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run(&["--progress-every", "0.000001"]);
    assert!(out.status.success());
    let log = String::from_utf8_lossy(&out.stderr);
    let line = log
        .lines()
        .find(|l| l.starts_with("progress: "))
        .unwrap_or_else(|| panic!("no progress line in {log}"));
    for part in ["/12 runs", "runs/s", "ETA", "settled", "failures 0"] {
        assert!(line.contains(part), "{part}: {line}");
    }
    assert!(
        log.lines().any(|l| l.starts_with("finished: 12 runs in ")),
        "{log}"
    );
    let quiet = run(&["--quiet", "--progress-every", "0.000001"]);
    let log = String::from_utf8_lossy(&quiet.stderr);
    assert!(
        !log.contains("progress:") && !log.contains("finished:"),
        "{log}"
    );
    let bad = run(&["--progress-every", "0"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--progress-every"));
}
