//! One output policy for every verb that writes (issue 33): an existing
//! result is replaced only with `--overwrite`, a folder of another study or
//! verb is never written into, a refusal comes before any work and leaves
//! nothing behind, every message names the flag and the path, and temporary
//! files of a killed writer are removed by the next writer.

use crate::bad_input::{scene, study};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn study_cmd(args: &[&str]) -> Output {
    crate::fuzz_input::command_for(args).output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).to_string()
}

/// Every entry below `dir` (files and folders), sorted, as paths relative to it.
fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            out.push(p.strip_prefix(dir).unwrap().to_path_buf());
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    out.sort();
    out
}

/// A refused command: exit 2, the needles in the message, and `dir`
/// exactly as it was.
fn assert_refused(args: &[&str], needles: &[&str], dir: &Path) {
    let before = listing(dir);
    let out = study_cmd(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    for needle in needles {
        assert!(
            err.contains(needle),
            "{args:?}: expected {needle:?} in: {err}"
        );
    }
    assert_eq!(listing(dir), before, "{args:?} changed the folder");
}

/// A dead process's id, for a temporary file its writer left behind.
fn dead_pid() -> u32 {
    let mut child = Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

#[test]
fn single_file_outputs_refuse_existing_files_folders_and_missing_folders_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let scene_path = dir.join("scene.toml");
    std::fs::write(&scene_path, scene()).unwrap();
    let study_path = dir.join("study.toml");
    std::fs::write(&study_path, study(&dir.join("results"))).unwrap();
    let existing = dir.join("old.parquet");
    std::fs::write(&existing, b"earlier results").unwrap();
    let folder = dir.join("a_folder");
    std::fs::create_dir(&folder).unwrap();
    let (sc, st) = (scene_path.to_str().unwrap(), study_path.to_str().unwrap());
    let (ex, fo) = (existing.to_str().unwrap(), folder.to_str().unwrap());
    let missing = dir.join("no/such/folder/x.parquet");
    let mi = missing.to_str().unwrap();
    let sweep = |out: &str| -> Vec<String> {
        [
            "sweep", sc, "--omega", "1..8", "--points", "3", "--out", out,
        ]
        .map(String::from)
        .to_vec()
    };
    let map = |out: &str| -> Vec<String> {
        [
            "map",
            sc,
            "--omega",
            "1..8",
            "--unbalance",
            "0.001..0.002",
            "--points",
            "2x2",
            "--out",
            out,
        ]
        .map(String::from)
        .to_vec()
    };
    let simulate =
        |out: &str| -> Vec<String> { ["simulate", sc, "--series", out].map(String::from).to_vec() };
    let claims =
        |out: &str| -> Vec<String> { ["claims", st, "--report", out].map(String::from).to_vec() };
    let lean = |out: &str| -> Vec<String> {
        ["bench", "--lean-inputs", out, "--samples", "1"]
            .map(String::from)
            .to_vec()
    };
    type Verb<'a> = (&'a str, &'a dyn Fn(&str) -> Vec<String>);
    let verbs: [Verb; 5] = [
        ("--out", &sweep),
        ("--out", &map),
        ("--series", &simulate),
        ("--report", &claims),
        ("--lean-inputs", &lean),
    ];
    for (flag, verb) in verbs {
        let args = |out: &str| verb(out);
        let call = args(ex);
        let call: Vec<&str> = call.iter().map(String::as_str).collect();
        assert_refused(&call, &[flag, ex, "--overwrite"], dir);
        assert_eq!(std::fs::read(&existing).unwrap(), b"earlier results");
        let call = args(fo);
        let call: Vec<&str> = call.iter().map(String::as_str).collect();
        assert_refused(&call, &[flag, fo, "names a folder"], dir);
        let call = args(mi);
        let call: Vec<&str> = call.iter().map(String::as_str).collect();
        assert_refused(&call, &[flag, "does not exist"], dir);
    }
    assert!(!dir.join("results").exists());
}

#[test]
fn overwrite_replaces_a_single_file_and_a_dead_writers_temporary_is_removed() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let scene_path = dir.join("scene.toml");
    std::fs::write(&scene_path, scene()).unwrap();
    let out = dir.join("sweep.parquet");
    std::fs::write(&out, b"earlier results").unwrap();
    let stale = dir.join(format!("sweep.parquet.tmp-{}", dead_pid()));
    std::fs::write(&stale, b"half a file").unwrap();
    let args = [
        "sweep",
        scene_path.to_str().unwrap(),
        "--omega",
        "1..8",
        "--points",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--overwrite",
    ];
    let done = study_cmd(&args);
    assert!(done.status.success(), "{}", stderr(&done));
    assert_ne!(std::fs::read(&out).unwrap(), b"earlier results");
    assert!(
        autobal::study::results::io::read_parquet(&out)
            .unwrap()
            .height()
            == 2
    );
    assert!(
        !stale.exists(),
        "the killed writer's temporary is still there"
    );
}

/// The study text of the bad-input corpus in `dir`; returns its path and
/// its output folder.
fn corpus_study(dir: &Path, extra: &str) -> (PathBuf, PathBuf) {
    let path = dir.join("corpus.toml");
    // Two designs, so that `compare --designs 0,1` has two to compare.
    let text = study(&dir.join("results")).replace("n = 3\n", "n = [3, 4]\n");
    std::fs::write(&path, text + extra).unwrap();
    (path, dir.join("results/corpus"))
}

#[test]
fn tradeoff_and_optimize_write_into_their_studys_folder_only_by_the_policy() {
    let tmp = tempfile::tempdir().unwrap();
    let optimize_table = "[optimize]\nobjective = \"capacity\"\nfree = [\"rho\"]\n";
    let (path, folder) = corpus_study(tmp.path(), optimize_table);
    let p = path.to_str().unwrap();
    std::fs::create_dir_all(&folder).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    // Earlier results of the same study: refused without --overwrite.
    std::fs::write(folder.join("study.toml"), &text).unwrap();
    std::fs::write(folder.join("tradeoff.parquet"), b"earlier").unwrap();
    std::fs::write(folder.join("optimum.parquet"), b"earlier").unwrap();
    assert_refused(
        &["tradeoff", p, "--runs", "1"],
        &["tradeoff.parquet", "--overwrite"],
        tmp.path(),
    );
    assert_refused(
        &["optimize", p],
        &["optimum.parquet", "--overwrite"],
        tmp.path(),
    );
    // Another study's folder, a check's scratch folder, a baseline: never.
    std::fs::remove_file(folder.join("tradeoff.parquet")).unwrap();
    std::fs::remove_file(folder.join("optimum.parquet")).unwrap();
    std::fs::write(folder.join("study.toml"), "name = \"another\"\n").unwrap();
    for args in [
        vec!["tradeoff", p, "--runs", "1", "--overwrite"],
        vec!["optimize", p, "--overwrite"],
    ] {
        assert_refused(&args, &["another study file"], tmp.path());
    }
    std::fs::write(folder.join("study.toml"), &text).unwrap();
    for (mark, what) in [
        (
            autobal::study::run::study_folder::SCRATCH_MARK,
            "scratch folder",
        ),
        (
            autobal::study::run::study_folder::BASELINE_MANIFEST,
            "baseline folder",
        ),
    ] {
        std::fs::write(folder.join(mark), b"").unwrap();
        assert_refused(&["tradeoff", p, "--overwrite"], &[what], tmp.path());
        assert_refused(&["optimize", p, "--overwrite"], &[what], tmp.path());
        std::fs::remove_file(folder.join(mark)).unwrap();
    }
    // A refused [optimize] table makes no folder at all.
    let bare = tempfile::tempdir().unwrap();
    let (path, folder) = corpus_study(bare.path(), "");
    assert_refused(
        &["optimize", path.to_str().unwrap()],
        &["no [optimize] table"],
        bare.path(),
    );
    assert!(!folder.exists());
    // The capacity objective is analytic: optimize runs, then needs --overwrite.
    let (path, folder) = corpus_study(bare.path(), optimize_table);
    let p = path.to_str().unwrap();
    let first = study_cmd(&["optimize", p]);
    assert!(first.status.success(), "{}", stderr(&first));
    assert!(folder.join("optimum.parquet").exists());
    assert!(!folder.join(".lock").exists());
    assert_refused(&["optimize", p], &["--overwrite"], bare.path());
    let again = study_cmd(&["optimize", p, "--overwrite"]);
    assert!(again.status.success(), "{}", stderr(&again));
}

#[test]
fn a_run_removes_temporaries_left_by_a_killed_final_write_and_refuses_stop_when_with_shard_unwritten()
 {
    let tmp = tempfile::tempdir().unwrap();
    let (path, folder) = corpus_study(tmp.path(), "");
    let p = path.to_str().unwrap();
    let first = study_cmd(&["run", p, "--quiet"]);
    assert!(first.status.success(), "{}", stderr(&first));
    let pid = dead_pid();
    let leftovers = [
        folder.join(format!("runs.parquet.tmp-{pid}")),
        folder.join(format!("summary.parquet.tmp-{pid}")),
    ];
    for f in &leftovers {
        std::fs::write(f, b"half a file").unwrap();
    }
    let resumed = study_cmd(&["run", p, "--quiet", "--resume"]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    for f in &leftovers {
        assert!(!f.exists(), "{} left behind", f.display());
    }
    // Adaptive sampling with a shard: refused before the folder is made.
    let adaptive = tempfile::tempdir().unwrap();
    let text = study(&adaptive.path().join("results")).replace(
        "samples = 2\n",
        "samples = 20\nbatch = 10\nstop_when = { median_halfwidth_rel = 0.2 }\n",
    );
    let path = adaptive.path().join("adaptive.toml");
    std::fs::write(&path, text).unwrap();
    assert_refused(
        &["run", path.to_str().unwrap(), "--shard", "1/2"],
        &["stop_when", "--shard"],
        adaptive.path(),
    );
    assert!(!adaptive.path().join("results").exists());
}

#[test]
fn a_corrupt_runs_file_is_reported_with_its_path() {
    let tmp = tempfile::tempdir().unwrap();
    let (path, folder) = corpus_study(tmp.path(), "");
    let p = path.to_str().unwrap();
    assert!(study_cmd(&["run", p, "--quiet"]).status.success());
    let baseline = tmp.path().join("baseline");
    let made = study_cmd(&["baseline", p, "--out", baseline.to_str().unwrap()]);
    assert!(made.status.success(), "{}", stderr(&made));
    let runs = folder.join("runs.parquet");
    std::fs::write(&runs, b"not parquet at all").unwrap();
    let figures = tmp.path().join("figs");
    let report = tmp.path().join("report.html");
    // A damaged results file is the user's input: exit 2, named once.
    for args in [
        vec!["run", p, "--quiet", "--resume"],
        vec![
            "check",
            p,
            "--baseline",
            baseline.to_str().unwrap(),
            "--runs",
            runs.to_str().unwrap(),
        ],
        vec!["compare", folder.to_str().unwrap(), "--designs", "0,1"],
        vec![
            "plot",
            "study",
            folder.to_str().unwrap(),
            "--out",
            figures.to_str().unwrap(),
        ],
        vec![
            "report",
            folder.to_str().unwrap(),
            "--out",
            report.to_str().unwrap(),
        ],
    ] {
        let out = study_cmd(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(
            err.matches(runs.to_str().unwrap()).count(),
            1,
            "{args:?}: {err}"
        );
        assert!(
            !err.contains("out of specification") || err.contains("Parquet"),
            "{err}"
        );
    }
}

#[test]
fn plot_study_refuses_a_missing_figure_before_making_its_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let (path, folder) = corpus_study(tmp.path(), "");
    assert!(
        study_cmd(&["run", path.to_str().unwrap(), "--quiet"])
            .status
            .success()
    );
    let figs = tmp.path().join("figs");
    assert_refused(
        &[
            "plot",
            "study",
            folder.to_str().unwrap(),
            "--only",
            "passage",
            "--out",
            figs.to_str().unwrap(),
        ],
        &["stall torque"],
        tmp.path(),
    );
    assert!(!figs.exists());
}

#[test]
fn simultaneous_starts_get_the_lock_message_never_an_io_error() {
    let tmp = tempfile::tempdir().unwrap();
    let (path, folder) = corpus_study(tmp.path(), "");
    let p = path.to_str().unwrap();
    let children: Vec<_> = (0..12)
        .map(|_| {
            Command::new(env!("CARGO_BIN_EXE_study"))
                .args(["run", p, "--quiet", "--resume"])
                .stderr(std::process::Stdio::piped())
                .stdout(std::process::Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut finished = 0;
    for child in children {
        let out = child.wait_with_output().unwrap();
        let err = stderr(&out);
        match out.status.code() {
            Some(0) => finished += 1,
            Some(2) => assert!(err.contains("in use by another study run"), "{err}"),
            other => panic!("exit {other:?}: {err}"),
        }
    }
    assert!(finished >= 1);
    assert!(folder.join("runs.parquet").exists());
    assert!(!folder.join(".lock").exists());
    assert!(
        !listing(&folder)
            .iter()
            .any(|p| p.to_string_lossy().contains(".write-probe")),
        "a probe file left behind"
    );
}

#[test]
fn claims_rewrites_only_the_variant_folders_it_marked() {
    let tmp = tempfile::tempdir().unwrap();
    let text = format!(
        "{}\n[designs]\nkind = \"ball\"\nn = [2]\nrho = \"optimal\"\nrace_radius = 0.05\ndrag = 10.0\n[sampling]\nsamples = 1\nunbalance = {{ distribution = \"fixed\", value = 0.5, relative_to = \"capacity\" }}\n[metrics]\nt_end_revs = 60\n",
        format!("name = \"claims\"\noutput = \"{}\"\n", tmp.path().display())
            + crate::fixtures::SI_SCENE
    );
    let plan = autobal::study::plan::config::StudyFile::parse(&text, "claims.toml")
        .unwrap()
        .plan(&text, "claims.toml")
        .unwrap();
    let foreign = tmp.path().join("claims/fastest_equal_mass");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("runs.parquet"), b"someone else's results").unwrap();
    let before = listing(tmp.path());
    let err = autobal::claims::run_claims(&plan, &autobal::study::run::NoProgress).unwrap_err();
    assert!(err.is_user_error(), "{err}");
    assert!(err.to_string().contains("fastest_equal_mass"), "{err}");
    assert_eq!(
        listing(tmp.path()),
        before,
        "a variant ran before the refusal"
    );
    std::fs::remove_dir_all(&foreign).unwrap();
    autobal::claims::run_claims(&plan, &autobal::study::run::NoProgress).unwrap();
    let marked = tmp
        .path()
        .join("claims/fastest_equal_mass")
        .join(autobal::study::run::study_folder::CLAIMS_MARK);
    assert!(marked.exists());
    // Its own folders are recomputed.
    autobal::claims::run_claims(&plan, &autobal::study::run::NoProgress).unwrap();
}

#[cfg(unix)]
#[test]
fn a_trailing_dot_a_link_a_read_only_folder_or_a_file_as_folder_is_refused_before_any_work() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("scene.toml"), scene()).unwrap();
    std::fs::write(dir.join("corpus.toml"), study(Path::new("results"))).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", "corpus.toml", "--quiet"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", stderr(&run));
    std::fs::write(dir.join("kept.txt"), b"keep").unwrap();
    std::os::unix::fs::symlink("kept.txt", dir.join("link.out")).unwrap();
    std::fs::create_dir(dir.join("ro")).unwrap();
    std::fs::set_permissions(dir.join("ro"), std::fs::Permissions::from_mode(0o555)).unwrap();
    let base: &[(&str, &[&str])] = &[
        (
            "--out",
            &["sweep", "scene.toml", "--omega", "1..4", "--points", "2"],
        ),
        (
            "--out",
            &[
                "map",
                "scene.toml",
                "--omega",
                "1..4",
                "--unbalance",
                "0.001..0.002",
                "--points",
                "2x2",
            ],
        ),
        ("--series", &["simulate", "scene.toml"]),
        ("--report", &["claims", "corpus.toml"]),
        ("--out", &["report", "results/corpus"]),
        ("--out", &["plot", "design"]),
        ("--plot", &["compare", "results/corpus", "--designs", "0,1"]),
    ];
    for (flag, verb) in base {
        let figure = verb[0] == "plot" || *flag == "--plot";
        let ext = if figure { "svg" } else { "out" };
        let mut cases = vec![
            (format!("r.{ext}/."), "names a folder"),
            (format!("ro/r.{ext}"), "read-only"),
            (format!("kept.txt/r.{ext}"), "is a file, not a folder"),
        ];
        // A figure is redrawn in place; results are replaced only when asked.
        if !figure {
            cases.push(("link.out".into(), "symbolic link"));
        }
        for (value, reason) in cases {
            let mut args: Vec<String> = verb.iter().map(|s| s.to_string()).collect();
            args.extend([flag.to_string(), value.clone()]);
            let before = listing(dir);
            let out = Command::new(env!("CARGO_BIN_EXE_study"))
                .args(&args)
                .current_dir(dir)
                .output()
                .unwrap();
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
            assert!(
                err.contains(&format!("{flag} {value}")) && err.contains(reason),
                "{args:?}: expected {flag} {value} and {reason:?} in: {err}"
            );
            assert_eq!(listing(dir), before, "{args:?} changed the folder");
        }
    }
    assert_eq!(std::fs::read(dir.join("kept.txt")).unwrap(), b"keep");
    // Folders asked for (plot study's --out) get the same care.
    for (value, reason) in [
        ("kept.txt", "is a file"),
        ("ro/figs", "read-only"),
        ("new/.", "does not exist"),
    ] {
        let before = listing(dir);
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["plot", "study", "results/corpus", "--out", value])
            .current_dir(dir)
            .output()
            .unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{value}: {err}");
        assert!(
            err.contains(&format!("--out {value}")) && err.contains(reason),
            "{err}"
        );
        assert_eq!(listing(dir), before);
    }
    std::fs::set_permissions(dir.join("ro"), std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn a_results_table_of_the_wrong_kind_is_refused_naming_the_file_and_the_missing_columns() {
    let tmp = tempfile::tempdir().unwrap();
    let (path, folder) = corpus_study(tmp.path(), "");
    let p = path.to_str().unwrap();
    assert!(study_cmd(&["run", p, "--quiet"]).status.success());
    assert!(study_cmd(&["baseline", p]).status.success());
    let summary = folder.join("summary.parquet");
    let s = summary.to_str().unwrap();
    let summary_keep = tmp.path().join("summary.keep");
    std::fs::copy(&summary, &summary_keep).unwrap();
    // The summary given where the runs are asked for.
    let out = study_cmd(&["check", p, "--runs", s]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("--runs {s}"))
            && err.contains("\"outcome\"")
            && err.contains("summary.parquet"),
        "{err}"
    );
    assert_eq!(err.matches(s).count(), 1, "{err}");
    // The summary in the runs' place, and the runs in the summary's.
    let runs = folder.join("runs.parquet");
    let keep = tmp.path().join("runs.keep");
    std::fs::copy(&runs, &keep).unwrap();
    std::fs::copy(&summary, &runs).unwrap();
    let f = folder.to_str().unwrap();
    let figs = tmp.path().join("figs");
    for args in [
        vec!["compare", f, "--designs", "0,1"],
        vec!["plot", "study", f, "--out", figs.to_str().unwrap()],
        vec!["run", p, "--quiet", "--resume"],
    ] {
        let out = study_cmd(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(runs.to_str().unwrap()) && err.contains("\"outcome\""),
            "{args:?}: {err}"
        );
    }
    std::fs::copy(&keep, &summary).unwrap();
    std::fs::copy(&keep, &runs).unwrap();
    let out = study_cmd(&["plot", "study", f, "--out", figs.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(s) && err.contains("\"rank_by\""), "{err}");
    assert!(!figs.exists());
    // A shard whose runs are a summary: merge names it.
    for k in ["1/2", "2/2"] {
        assert!(
            study_cmd(&["run", p, "--quiet", "--shard", k])
                .status
                .success()
        );
    }
    let shard = folder.join("shard-1-of-2");
    std::fs::copy(&summary_keep, shard.join("runs.parquet")).unwrap();
    let merged = tmp.path().join("merged");
    let out = study_cmd(&[
        "merge",
        shard.to_str().unwrap(),
        folder.join("shard-2-of-2").to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(shard.join("runs.parquet").to_str().unwrap()) && err.contains("\"outcome\""),
        "{err}"
    );
}
