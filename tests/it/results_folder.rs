//! A results folder belongs to one plan and one writer: a rerun never
//! deletes results unless asked (--overwrite), --resume refuses a folder
//! whose plan is unknown or different, and a second writer is turned away
//! with the holder's name. Each case exits 2 and leaves the results as they
//! were.

use autobal::study::run::lock::FolderLock;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn study_text(results: &Path) -> String {
    format!(
        r#"name = "folder"
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
t_end_revs = 60
"#,
        results.display()
    )
}

/// A study file in a fresh folder; returns (tempdir, study path, results folder).
fn setup() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let path = tmp.path().join("folder.toml");
    std::fs::write(&path, study_text(&results)).unwrap();
    let folder = results.join("folder");
    (tmp, path, folder)
}

fn study(path: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--quiet"])
        .args(extra)
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).to_string()
}

#[test]
fn a_rerun_needs_overwrite_and_leaves_the_results_otherwise() {
    let (_tmp, path, folder) = setup();
    assert!(study(&path, &[]).status.success());
    let runs = std::fs::read(folder.join("runs.parquet")).unwrap();
    assert!(!folder.join(".lock").exists(), "lock file left behind");
    let again = study(&path, &[]);
    assert_eq!(again.status.code(), Some(2));
    assert!(
        stderr(&again).contains("already holds results"),
        "{}",
        stderr(&again)
    );
    assert_eq!(std::fs::read(folder.join("runs.parquet")).unwrap(), runs);
    let replaced = study(&path, &["--overwrite"]);
    assert!(replaced.status.success(), "{}", stderr(&replaced));
}

#[test]
fn resume_refuses_results_without_a_plan_and_keeps_them() {
    let (_tmp, path, folder) = setup();
    assert!(study(&path, &[]).status.success());
    std::fs::remove_file(folder.join("study.toml")).unwrap();
    let runs = std::fs::read(folder.join("runs.parquet")).unwrap();
    let out = study(&path, &["--resume"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("no study.toml"), "{}", stderr(&out));
    assert_eq!(std::fs::read(folder.join("runs.parquet")).unwrap(), runs);
}

#[test]
fn resume_refuses_runs_of_another_build() {
    let (_tmp, path, folder) = setup();
    assert!(study(&path, &[]).status.success());
    std::fs::write(folder.join("plan.sha256"), "0123456789abcdef").unwrap();
    let out = study(&path, &["--resume"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("another autobal build"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn a_second_writer_is_turned_away_with_the_holders_name() {
    let (_tmp, path, folder) = setup();
    std::fs::create_dir_all(&folder).unwrap();
    let held = FolderLock::acquire(&folder).expect("first writer");
    let out = study(&path, &["--resume"]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("in use by another study run"), "{err}");
    assert!(
        err.contains(&format!("pid {}", std::process::id())),
        "{err}"
    );
    drop(held);
    assert!(!folder.join(".lock").exists());
    // Released: the run goes ahead.
    assert!(study(&path, &["--resume"]).status.success());
}

#[test]
fn the_folders_copy_of_the_study_leaves_out_the_schema_line_and_still_resumes_and_merges() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let path = tmp.path().join("folder.toml");
    let text = format!(
        "#:schema ../schema/study.schema.json\n{}",
        study_text(&results)
    );
    std::fs::write(&path, &text).unwrap();
    assert!(study(&path, &[]).status.success());
    let folder = results.join("folder");
    let copy = std::fs::read_to_string(folder.join("study.toml")).unwrap();
    // The line's path is relative to the study file's folder: from the
    // results folder it resolves nowhere, and editors flag it.
    assert!(!copy.contains("#:schema"), "{copy}");
    assert_eq!(copy, study_text(&results));
    let resumed = study(&path, &["--resume"]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    // Shards and their merge record the study file's own hash, as one run does.
    for k in 1..=2 {
        let shard = study(&path, &["--shard", &format!("{k}/2")]);
        assert!(shard.status.success(), "{}", stderr(&shard));
    }
    let merged_dir = tmp.path().join("merged");
    let merged = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["merge", "--out", merged_dir.to_str().unwrap()])
        .arg(folder.join("shard-1-of-2"))
        .arg(folder.join("shard-2-of-2"))
        .output()
        .unwrap();
    assert!(merged.status.success(), "{}", stderr(&merged));
    let sha = |p: &Path| {
        autobal::study::results::io::read_metadata(p)
            .unwrap()
            .into_iter()
            .find(|(k, _)| k == "study_sha256")
            .unwrap()
            .1
    };
    let whole = sha(&folder.join("runs.parquet"));
    // The recorded hash is that of the stored study.toml, byte for byte:
    // `sha256sum results/folder/study.toml` finds it.
    let stored = std::fs::read(folder.join("study.toml")).unwrap();
    assert_eq!(whole, hex_sha256(&stored));
    assert_eq!(sha(&folder.join("summary.parquet")), whole);
    assert_eq!(sha(&merged_dir.join("runs.parquet")), whole);
    assert_eq!(sha(&merged_dir.join("summary.parquet")), whole);
}

/// SHA-256 of bytes as `sha256sum` prints it.
fn hex_sha256(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[test]
fn resume_after_the_study_changed_advises_overwrite_and_that_advice_works() {
    let (_tmp, path, folder) = setup();
    assert!(study(&path, &[]).status.success());
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("samples = 2", "samples = 3")).unwrap();
    let before = std::fs::read(folder.join("runs.parquet")).unwrap();
    let resumed = study(&path, &["--resume"]);
    let err = stderr(&resumed);
    assert_eq!(resumed.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--overwrite") && err.contains("replace the earlier runs"),
        "{err}"
    );
    assert!(
        !err.contains("without --resume"),
        "the circle is back: {err}"
    );
    assert_eq!(std::fs::read(folder.join("runs.parquet")).unwrap(), before);
    // Following the advice runs the changed study.
    let replaced = study(&path, &["--overwrite"]);
    assert!(replaced.status.success(), "{}", stderr(&replaced));
    let runs = autobal::study::results::io::read_parquet(&folder.join("runs.parquet")).unwrap();
    assert_eq!(runs.height(), 3);
}

#[test]
fn resume_of_a_complete_study_says_so_and_prints_its_ranking_without_a_rate() {
    let (_tmp, path, _folder) = setup();
    assert!(study(&path, &[]).status.success());
    let again = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--resume"])
        .args(["--progress-every", "1000"])
        .output()
        .unwrap();
    let err = stderr(&again);
    assert!(again.status.success(), "{err}");
    assert!(err.contains("already complete"), "{err}");
    for meaningless in ["0 runs", "runs/s", "s/run", "settled 0.0 %"] {
        assert!(!err.contains(meaningless), "{meaningless}: {err}");
    }
    let out = String::from_utf8_lossy(&again.stdout);
    assert!(out.contains("recommendation"), "no ranking: {out}");
}

/// A study of 2 runs in 4 shards: two shards hold no run. Each is a valid
/// shard all the same (exit 0, an empty runs table), and their merge is the
/// unsharded run's table (before: those shards failed with "no data" and
/// the merge could not be made).
#[test]
fn an_empty_shard_is_a_shard_and_merges() {
    let (tmp, path, folder) = setup();
    assert!(study(&path, &[]).status.success());
    let shards: Vec<PathBuf> = (1..=4)
        .map(|k| {
            let out = study(&path, &["--shard", &format!("{k}/4")]);
            assert!(out.status.success(), "shard {k}/4: {}", stderr(&out));
            folder.join(format!("shard-{k}-of-4"))
        })
        .collect();
    // Every column but the wall time, which no two runs share.
    let rows = |p: &Path| {
        autobal::study::results::io::read_parquet(p)
            .unwrap()
            .drop("wall_time_s")
            .unwrap()
    };
    assert_eq!(rows(&shards[3].join("runs.parquet")).height(), 0);
    let merged_dir = tmp.path().join("merged");
    let merged = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["merge", "--out", merged_dir.to_str().unwrap()])
        .args(&shards)
        .output()
        .unwrap();
    assert!(merged.status.success(), "{}", stderr(&merged));
    let whole = rows(&folder.join("runs.parquet"));
    let joined = rows(&merged_dir.join("runs.parquet"));
    assert_eq!(whole.height(), 2);
    assert!(
        whole.equals_missing(&joined),
        "the merge differs from one run"
    );
}
