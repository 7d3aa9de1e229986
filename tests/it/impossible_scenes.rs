//! What a scene or study cannot mean is refused before any run, naming the
//! key (exit 2, nothing written): a weight larger than its track radius,
//! unbalances beyond a thousand times what the weights can cancel (before,
//! a 1.5 m ball on a 1 m track ran and exited 0, and 1e300 times the
//! capacity exited 1 after every run had failed).

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
