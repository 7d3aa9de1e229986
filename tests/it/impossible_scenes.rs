//! What a scene, a study or a study folder cannot mean is refused before
//! any run, naming the key or the entry (exit 2, nothing written): a weight
//! larger than its track radius, unbalances beyond a thousand times what
//! the weights can cancel (before, a 1.5 m ball on a 1 m track ran and
//! exited 0, and 1e300 times the capacity exited 1 after every run had
//! failed), a folder whose entries are of the wrong kind.

use crate::fixtures::simulate_text;
use std::process::Command;

#[test]
fn a_weight_larger_than_its_track_radius_is_refused() {
    let scene = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/three_balls.toml"),
    )
    .unwrap()
    .replacen("kappa = 1.4\n", "kappa = 1.4\nradius = 1.5\n", 1);
    let out = simulate_text(&scene);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cargo[0].radius") && err.contains("cargo[0].track_radius"),
        "{err}"
    );
}

/// Run `study run` on a study (`base` of its results folder) with `from`
/// replaced by `to`.
fn run_with(
    base: fn(&std::path::Path) -> String,
    from: &str,
    to: &str,
) -> (Option<i32>, String, bool) {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let base = base(&results);
    assert!(base.contains(from), "fixture lacks {from:?}");
    let text = base.replacen(from, to, 1);
    let path = tmp.path().join("s.toml");
    std::fs::write(&path, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).to_string(),
        results.exists(),
    )
}

#[test]
fn unbalances_far_beyond_the_capacity_are_refused_naming_the_key() {
    let unbalance = "unbalance = { distribution = \"uniform\", min = 0.2, max = 0.8, relative_to = \"capacity\" }";
    let (code, err, wrote) = run_with(
        crate::bad_input::study,
        unbalance,
        "unbalance = { distribution = \"uniform\", min = 0.2, max = 1e300, relative_to = \"capacity\" }\nrequire_balanceable = false",
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("sampling.unbalance.max") && err.contains("times the capacity"),
        "{err}"
    );
    assert!(!wrote, "a refusal wrote results");
    // A couple 1e300 times the static part, on the two-plane study.
    let (code, err, wrote) = run_with(
        crate::bad_input_two::study,
        "follows_static = 0.5",
        "follows_static = 1e300",
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("sampling.couple.follows_static") && err.contains("times the capacity"),
        "{err}"
    );
    assert!(!wrote, "a refusal wrote results");
    // Twice the capacity is still a question a study may ask.
    let (code, err, _) = run_with(
        crate::bad_input::study,
        unbalance,
        "unbalance = { distribution = \"fixed\", value = 2.0, relative_to = \"capacity\" }\nrequire_balanceable = false",
    );
    assert_eq!(code, Some(0), "{err}");
}

/// A study folder whose `chunks` is a file, or whose `study.toml` is a
/// folder: `--resume` exits 2 naming the entry and leaves the folder as it
/// was (before: exit 1 with a bare "os error 17" or "21").
#[test]
fn a_misshapen_study_folder_is_refused_naming_the_entry() {
    for (entry, make_dir) in [("chunks", false), ("study.toml", true)] {
        let tmp = tempfile::tempdir().unwrap();
        let results = tmp.path().join("results");
        let path = tmp.path().join("s.toml");
        std::fs::write(&path, crate::bad_input::study(&results)).unwrap();
        let folder = results.join("corpus");
        std::fs::create_dir_all(&folder).unwrap();
        if make_dir {
            std::fs::create_dir(folder.join(entry)).unwrap();
        } else {
            std::fs::write(folder.join(entry), b"not a folder").unwrap();
        }
        let before = crate::bad_input::tree_snapshot(&folder);
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["run", path.to_str().unwrap(), "--quiet", "--resume"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{entry}: {err}");
        assert!(
            err.contains(&folder.join(entry).display().to_string())
                && err.contains("nothing was changed"),
            "{entry}: {err}"
        );
        assert_eq!(
            crate::bad_input::tree_snapshot(&folder),
            before,
            "{entry}: the folder changed"
        );
    }
}

/// `--resume` over a truncated runs.parquet is refused and leaves the
/// folder byte for byte as it was (before: exit 2, but a new `chunks/`).
#[test]
fn a_refused_resume_over_a_damaged_table_leaves_the_folder_as_it_was() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let path = tmp.path().join("s.toml");
    std::fs::write(&path, crate::bad_input::study(&results)).unwrap();
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["run", path.to_str().unwrap(), "--quiet"])
            .args(extra)
            .output()
            .unwrap()
    };
    assert!(run(&[]).status.success());
    let folder = results.join("corpus");
    let runs = folder.join("runs.parquet");
    let bytes = std::fs::read(&runs).unwrap();
    std::fs::write(&runs, &bytes[..bytes.len() / 2]).unwrap();
    let before = crate::bad_input::tree_snapshot(&folder);
    let out = run(&["--resume"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("runs.parquet"), "{err}");
    assert_eq!(
        crate::bad_input::tree_snapshot(&folder),
        before,
        "the refusal changed the folder"
    );
}
