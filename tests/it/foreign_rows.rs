//! Results folders are changed only by the runs that own them. Runs copied
//! in from another study or seed are never adopted: `--resume`,
//! `study merge` and `study compare` check each table's recorded
//! provenance against the study beside it and refuse a mismatch naming the
//! file, leaving every folder as it was; a folder made read-only is not
//! overwritten.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn study_bin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .output()
        .unwrap()
}

/// `study ARGS`, which must succeed.
fn study_ok(args: &[&str]) {
    let out = study_bin(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The corpus study under `results`, with `seed`, written to `file`.
fn study_file(dir: &Path, results: &Path, seed: u64, file: &str) -> PathBuf {
    let text = crate::bad_input::study(results).replace("seed = 5", &format!("seed = {seed}"));
    let path = dir.join(file);
    std::fs::write(&path, text).unwrap();
    path
}

fn refused(out: &Output, names: &Path, why: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&names.display().to_string()) && err.contains(why),
        "{err}"
    );
}

/// A finished study of seed 6 whose runs.parquet is replaced by the same
/// study's under seed 5 (another study text): `--resume` and `compare`
/// refuse it by its recorded hash.
#[test]
fn a_table_of_another_seed_is_neither_resumed_nor_compared() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let five = study_file(tmp.path(), &a, 5, "five.toml");
    let six = study_file(tmp.path(), &b, 6, "six.toml");
    for path in [&five, &six] {
        study_ok(&["run", path.to_str().unwrap(), "--quiet"]);
    }
    let folder = b.join("corpus");
    let runs = folder.join("runs.parquet");
    std::fs::copy(a.join("corpus/runs.parquet"), &runs).unwrap();
    std::fs::remove_file(folder.join("summary.parquet")).unwrap();
    let before = crate::bad_input::tree_snapshot(&folder);
    let out = study_bin(&["run", six.to_str().unwrap(), "--quiet", "--resume"]);
    refused(&out, &runs, "written by another study file");
    assert_eq!(
        crate::bad_input::tree_snapshot(&folder),
        before,
        "a refused resume changed the folder"
    );
    let out = study_bin(&[
        "compare",
        a.join("corpus").to_str().unwrap(),
        folder.to_str().unwrap(),
    ]);
    refused(&out, &runs, "written by another study file");
}

/// A shard folder whose runs.parquet came from the same shard of another
/// seed is refused by `study merge`, naming the table.
#[test]
fn a_shard_of_another_seed_is_not_merged() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let five = study_file(tmp.path(), &a, 5, "five.toml");
    let six = study_file(tmp.path(), &b, 6, "six.toml");
    for k in ["1/2", "2/2"] {
        study_ok(&["run", five.to_str().unwrap(), "--quiet", "--shard", k]);
    }
    study_ok(&["run", six.to_str().unwrap(), "--quiet", "--shard", "1/2"]);
    let shards = a.join("corpus");
    let first = shards.join("shard-1-of-2");
    let runs = first.join("runs.parquet");
    std::fs::copy(b.join("corpus/shard-1-of-2/runs.parquet"), &runs).unwrap();
    let before = crate::bad_input::tree_snapshot(&shards);
    let out = study_bin(&[
        "merge",
        first.to_str().unwrap(),
        shards.join("shard-2-of-2").to_str().unwrap(),
    ]);
    refused(&out, &runs, "written by another study file");
    assert_eq!(
        crate::bad_input::tree_snapshot(&shards),
        before,
        "a refused merge changed the folders"
    );
}

/// `--resume` over a folder with runs but no plan.sha256 cannot tell which
/// build made them: refused, the folder as it was (before: resumed).
#[test]
fn a_resume_without_the_plan_id_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("r");
    let path = study_file(tmp.path(), &results, 5, "s.toml");
    study_ok(&["run", path.to_str().unwrap(), "--quiet"]);
    let folder = results.join("corpus");
    std::fs::remove_file(folder.join("plan.sha256")).unwrap();
    std::fs::remove_file(folder.join("summary.parquet")).unwrap();
    let before = crate::bad_input::tree_snapshot(&folder);
    let out = study_bin(&["run", path.to_str().unwrap(), "--quiet", "--resume"]);
    refused(&out, &folder, "plan.sha256 is missing or unreadable");
    assert_eq!(crate::bad_input::tree_snapshot(&folder), before);
}

/// A results folder made read-only is not overwritten, even by a process
/// the system would let write it (root): refused before any work, exit 2,
/// the folder as it was.
#[test]
fn a_read_only_results_folder_is_not_overwritten() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("r");
    let path = study_file(tmp.path(), &results, 5, "s.toml");
    study_ok(&["run", path.to_str().unwrap(), "--quiet"]);
    let folder = results.join("corpus");
    let before = crate::bad_input::tree_snapshot(&folder);
    let mode = |m: u32| std::fs::set_permissions(&folder, std::fs::Permissions::from_mode(m));
    mode(0o555).unwrap();
    let out = study_bin(&["run", path.to_str().unwrap(), "--quiet", "--overwrite"]);
    mode(0o755).unwrap();
    refused(&out, &folder, "read-only");
    assert_eq!(
        crate::bad_input::tree_snapshot(&folder),
        before,
        "a read-only folder was rewritten"
    );
}
