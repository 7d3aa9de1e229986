//! "Settled" means settled at the operating point. A slow run-up (0 → 4 rad/s
//! over 2000 s on a rotor whose natural frequency is 1 rad/s) keeps the whirl
//! radius below δ·A_ref (A_ref taken at the final speed) while the speed is
//! still low; before settling was judged only at the operating speed, such a
//! run was reported settled at t = 0 (evenly spaced balls) or at 1388 s
//! (clustered balls), before the ramp had ended.

use autobal::metrics::Outcome;
use autobal::scene_file::SceneFile;

const RAMP: f64 = 2000.0;

fn runup(angles: &str, t_end_revs: f64) -> String {
    crate::fixtures::point_weights_scene(3)
        + &format!(
            r#"
[speed]
mode = "ramp"
omega_start = 0.0
omega_end = 4.0
duration = {RAMP}

[start]
angles_deg = {angles}

[metrics]
t_end_revs = {t_end_revs}
"#
        )
}

#[test]
fn a_slow_run_up_is_not_settled_before_the_ramp_ends() {
    // One revolution at 4 rad/s is π/2 s: the ramp plus a 50-revolution hold
    // needs 1324 revolutions; 1500 leaves room to settle after it.
    for angles in ["[0, 120, 240]", "[0, 10, 20]"] {
        let text = runup(angles, 1500.0);
        let sim = SceneFile::parse(&text, "runup.toml")
            .and_then(|f| f.simulation("runup.toml"))
            .expect("valid scene");
        let m = sim.run(false).expect("runs").metrics;
        match m.outcome {
            Outcome::Settled => {
                let t = m.settling_time.expect("settled runs have a time");
                assert!(t >= RAMP, "{angles}: settled at t = {t} during the ramp");
            }
            Outcome::Censored => {
                assert!(m.settling_time.is_none());
                let censored_at = m.censoring_revs.expect("censoring time");
                assert!(censored_at * std::f64::consts::FRAC_PI_2 >= RAMP);
            }
            other => panic!("{angles}: {other:?}: {}", m.reason),
        }
    }
}

#[test]
fn a_run_too_short_for_the_ramp_and_the_hold_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("runup.toml");
    std::fs::write(&path, runup("[0, 120, 240]", 1300.0)).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("simulate")
        .arg(&path)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("metrics.t_end_revs"), "{err}");
    assert!(err.contains("t_end_revs ≥ 1324"), "{err}");
}

#[test]
fn a_run_that_ends_without_a_complete_hold_is_censored_not_settled() {
    // A constant-speed run too short for the weights to settle: it ends
    // censored, with no settling time, whatever r does in its last moments.
    let text = runup("[0, 10, 20]", 1500.0).replace(
        "mode = \"ramp\"\nomega_start = 0.0\nomega_end = 4.0\nduration = 2000",
        "mode = \"constant\"\nomega = 4.0",
    );
    let text = text.replace("t_end_revs = 1500", "t_end_revs = 60");
    let sim = SceneFile::parse(&text, "short.toml")
        .and_then(|f| f.simulation("short.toml"))
        .expect("valid scene");
    let m = sim.run(false).expect("runs").metrics;
    assert_eq!(m.outcome, Outcome::Censored, "{}", m.reason);
    assert!(!m.settled && m.settling_revs.is_none());
    // Known only to exceed the end less the hold window: 60 − 50 revolutions.
    let censored_at = m.censoring_revs.expect("censoring time");
    assert!((censored_at - 10.0).abs() < 1e-9, "{censored_at}");
}
