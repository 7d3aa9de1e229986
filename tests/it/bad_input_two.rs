//! The bad-input corpus, round two (issue 46): a rotor on two supports with
//! a couple, fixed-length arrays, planes beyond any machine, names that
//! would become odd folders, speed flags, and every suggestion an error
//! makes. Each case is refused with exit code 2, a message naming the key
//! or flag, and no output folder (not even an empty parent).

use autobal::study::plan::criterion::Criterion;
use std::path::Path;
use std::process::Command;

/// A small two-plane study with a couple that follows the static part.
pub(crate) fn study(results: &Path) -> String {
    format!(
        r#"name = "two"
output = "{}"
[scene.rotor]
{}
planes = [-1.0, 1.0]
[scene.speed]
mode = "constant"
omega = 6.3
[designs]
kind = "ball"
n = 2
rho = 0.1
race_radius = 1.0
density = 10.0
drag = 0.01
[sampling]
samples = 2
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.6, relative_to = "capacity" }}
[sampling.couple]
follows_static = 0.5
[metrics]
t_end_revs = 20
hold_revs = 10
"#,
        results.display(),
        crate::couple_unbalance::LONG_ROTOR
    )
}

/// (what to replace, with what, a text the message must contain).
const CASES: &[(&str, &str, &str)] = &[
    // Fixed-length arrays: a third element once ran silently.
    (
        "follows_static = 0.5",
        "follows_static = 0.5\nat = [-1.0, 1.0, 2.0]",
        "sampling.couple.at",
    ),
    (
        "follows_static = 0.5",
        "follows_static = 0.5\nat = [-1.0]",
        "sampling.couple.at",
    ),
    (
        "[metrics]",
        "[optimize]\nobjective = \"capacity\"\nrho_bounds = [0.05, 0.2, 0.3]\n[metrics]",
        "optimize.rho_bounds",
    ),
    (
        "[metrics]",
        "[optimize]\nobjective = \"settling_mean\"\nfree = [\"rho\", \"drag\"]\ndrag_bounds = [0.01, 0.1, 1.0]\n[metrics]",
        "optimize.drag_bounds",
    ),
    (
        "[metrics]",
        "[optimize]\nobjective = \"capacity\"\nrho_bounds = []\n[metrics]",
        "optimize.rho_bounds",
    ),
    // Coincident planes: the couple has no moment, as with `at = [z, z]`.
    (
        "planes = [-1.0, 1.0]",
        "planes = [1.0, 1.0]",
        "scene.rotor.planes",
    ),
    // Planes beyond any machine, and planes × weights.
    (
        "planes = [-1.0, 1.0]",
        "planes = [-1.0, 1.0, -0.5, -0.4, -0.3, -0.2, -0.1, 0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]",
        "scene.rotor.planes",
    ),
    // Names that become folders and labels.
    ("name = \"two\"", "name = \"   \"", "name"),
    ("name = \"two\"", "name = \"\"", "name"),
    ("name = \"two\"", "name = \"a\\nb\"", "name"),
    ("name = \"two\"", "name = \"tab\\there\"", "name"),
    ("name = \"two\"", "name = \" two\"", "name"),
];

fn run(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

#[test]
fn every_bad_two_plane_study_is_refused_naming_the_key_with_nothing_written() {
    let mut failures = Vec::new();
    for (from, to, needle) in CASES {
        let tmp = tempfile::tempdir().unwrap();
        // A nested output: a refusal must not leave even its parents.
        let results = tmp.path().join("results").join("nested");
        let base = study(&results);
        assert!(base.contains(from), "fixture lacks {from:?}");
        let path = tmp.path().join("case.toml");
        std::fs::write(&path, base.replacen(from, to, 1)).unwrap();
        let (code, err) = run(&["run", path.to_str().unwrap(), "--quiet"]);
        let wrote = tmp.path().join("results").exists();
        if code != Some(2) || !err.contains(needle) || wrote {
            failures.push(format!(
                "{to:?}: exit {code:?}, wrote {wrote}, expected {needle:?} in: {err}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_fixture_itself_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("ok.toml");
    std::fs::write(&path, study(&tmp.path().join("results"))).unwrap();
    let (code, err) = run(&["run", path.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn a_name_too_long_for_a_folder_leaves_nothing_behind() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results").join("a").join("b");
    let text = study(&results).replacen(
        "name = \"two\"",
        &format!("name = \"{}\"", "x".repeat(300)),
        1,
    );
    let path = tmp.path().join("long.toml");
    std::fs::write(&path, text).unwrap();
    let (code, err) = run(&["run", path.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("name = "), "{err}");
    assert!(
        !tmp.path().join("results").exists(),
        "a refusal left folders"
    );
}

/// Every `e.g.` an error of `--rank-by` / `rank_by` prints parses as it
/// stands: `settled_by:30min` once suggested `30mins`, itself refused.
#[test]
fn every_suggestion_a_criterion_error_makes_is_accepted() {
    let inputs = [
        "settled_by:",
        "settled_by",
        "p_residual_below",
        "settled_by:30",
        "settled_by:30min",
        "settled_by:0.5 sec",
        "settled_by:2h",
        "settled_by:abc",
        "settled_by:-1min",
        "p_residual_below:",
        "p_residual_below:2e-5",
        "p_residual_below:20um",
        "p_residual_below:1e-3mm",
    ];
    let mut checked = 0;
    for input in inputs {
        let err = Criterion::parse(input).expect_err(input);
        let Some((_, examples)) = err.split_once("e.g. ") else {
            continue;
        };
        for example in examples.split([',', ' ']).filter(|w| w.contains(':')) {
            checked += 1;
            assert!(
                Criterion::parse(example).is_ok(),
                "{input:?} suggests {example:?}, which is refused: {err}"
            );
        }
    }
    assert!(checked >= 10, "only {checked} suggestions checked");
}

/// A speed flag's value outside the spin rates a scene may name is refused
/// naming the flag the user typed, not the scene key it becomes.
#[test]
fn a_speed_flag_out_of_range_names_the_flag() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/two_support_long.toml");
    for (args, flag) in [
        (vec!["sweep", scene, "--omega", "1e-300..2e-300"], "--omega"),
        (vec!["sweep", scene, "--omega", "1..1e300"], "--omega"),
        (
            vec![
                "map",
                scene,
                "--omega",
                "1e-300..2e-300",
                "--unbalance",
                "0.1..0.2",
                "--points",
                "2x2",
            ],
            "--omega",
        ),
        (
            vec![
                "stepped",
                scene,
                "--rpm",
                "1e-300..2e-300",
                "--step-rpm",
                "1",
                "--dwell",
                "1",
            ],
            "--rpm",
        ),
    ] {
        let (code, err) = run(&args);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(
            err.contains(flag) && !err.contains("speed.omega"),
            "{args:?}: {err}"
        );
    }
}

/// A scene's planes and weights are capped as a study's are, before the
/// system is built (120 000 planes once ran for ever).
#[test]
fn a_scene_with_planes_or_weights_beyond_the_limits_is_refused() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/two_support_long.toml"
    ))
    .unwrap();
    let planes: Vec<String> = (0..120_000).map(|i| format!("{}.0", i % 7)).collect();
    let many_cargo = "[[cargo]]\nmass = 0.01\ntrack_radius = 1.0\n".repeat(600);
    for (from, to, needle) in [
        (
            "planes = [-1.0, 1.0]".to_string(),
            format!("planes = [{}]", planes.join(", ")),
            "rotor.planes",
        ),
        (
            "[speed]".to_string(),
            format!("{many_cargo}[speed]"),
            "cargo",
        ),
    ] {
        assert!(text.contains(&from));
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("scene.toml");
        std::fs::write(&path, text.replacen(&from, &to, 1)).unwrap();
        let (code, err) = crate::fuzz_input::run_boxed_in(
            tmp.path(),
            &["simulate", path.to_str().unwrap()],
            std::time::Duration::from_secs(60),
        );
        assert_eq!(code, Some(2), "{needle}: {err}");
        assert!(err.contains(needle), "{needle}: {err}");
    }
}

/// A speed in rpm runs as its rad/s twin and `simulate` echoes both units;
/// both keys for one speed, or neither, are refused naming them.
#[test]
fn a_speed_is_given_once_in_rad_per_second_or_in_rpm() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/two_support_long.toml"
    ))
    .unwrap();
    assert!(text.contains("\nomega = 6.32\n"));
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("scene.toml");
    let simulate = |body: String| {
        std::fs::write(&path, body).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["simulate", path.to_str().unwrap()])
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).to_string(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (code, out, err) = simulate(text.replacen("\nomega = 6.32\n", "\nrpm = 60\n", 1));
    assert_eq!(code, Some(0), "{err}");
    assert!(
        out.lines()
            .next()
            .unwrap()
            .contains("ω = 6.283 rad/s (60 rpm)"),
        "{out}"
    );
    for (to, needles) in [
        (
            "\nomega = 6.32\nrpm = 60\n",
            &["speed.omega", "speed.rpm"][..],
        ),
        ("\n", &["omega", "rpm"][..]),
        ("\nrpm = 1e300\n", &["speed.rpm = 1e300"][..]),
        ("\nrpm = nan\n", &["speed.rpm"][..]),
    ] {
        let (code, _, err) = simulate(text.replacen("\nomega = 6.32\n", to, 1));
        assert_eq!(code, Some(2), "{to:?}: {err}");
        assert!(needles.iter().all(|n| err.contains(n)), "{to:?}: {err}");
    }
    // A motor's synchronous speed has its rpm twin too.
    let motor = text.replacen(
        "mode = \"constant\"\nomega = 6.32",
        "mode = \"motor\"\nstall_torque = 1.0\nrpm_sync = 60\nomega_sync = 6.3",
        1,
    );
    assert_ne!(motor, text);
    let (code, _, err) = simulate(motor);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("speed.omega_sync") && err.contains("speed.rpm_sync"),
        "{err}"
    );
}

/// Three planes of 200 weights: each balancer within its own limit, 600
/// weights in all beyond the 512 any scene may hold.
#[test]
fn planes_times_weights_beyond_the_limit_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let text = study(&tmp.path().join("results"))
        .replacen("planes = [-1.0, 1.0]", "planes = [-1.0, 0.0, 1.0]", 1)
        .replacen("n = 2", "n = 200", 1)
        .replacen("rho = 0.1", "rho = 0.01", 1)
        .replacen(
            "follows_static = 0.5",
            "follows_static = 0.5\nat = [-1.0, 1.0]",
            1,
        );
    let path = tmp.path().join("case.toml");
    std::fs::write(&path, text).unwrap();
    let (code, err) = run(&["run", path.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("scene.rotor.planes") && err.contains("3 planes × 200"),
        "{err}"
    );
    assert!(!tmp.path().join("results").exists());
}
