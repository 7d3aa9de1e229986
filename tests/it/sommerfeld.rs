//! The Sommerfeld effect: a motor of limited torque running a rotor up from
//! rest is held where its torque meets the load of the whirl (docs/model.md,
//! "The Sommerfeld effect"). Checked against the steady torque balance,
//! computed independently of the simulation by `model::sommerfeld`:
//!
//! - a rotor without a balancer (a weight of 1e-9 kg stands in for none)
//!   is held just below its critical speed where M_s (1 − Ω/ω_sync) =
//!   b Ω A(U, Ω)² (the classical result: Sommerfeld 1902, Kononenko 1969),
//!   and passes when the motor exceeds the load's peak;
//! - three pendulum-like weights lump together and whirl near ω_n while the
//!   rotor turns much faster, held where the motor's torque meets their
//!   drag Σ β l² (Ω − ω_b): the 191 rad/s of `studies/runup.toml`'s rotor at
//!   M_s = 8 N·m.

use autobal::metrics::RunMetrics;
use autobal::model::sommerfeld::{LumpedWeights, PlaneWhirl};
use autobal::scene_file::SceneFile;

const OMEGA_SYNC: f64 = 300.0;

/// `studies/runup.toml`'s rotor (10 kg, 1e5 N/m, 100 N·s/m, ω_n ≈ 100 rad/s)
/// with eccentricity `e`, the given cargo tables and a motor of stall
/// torque `stall`, run up from rest for 3000 revolutions at 300 rad/s.
fn run_up(e: f64, cargo: &str, stall: f64) -> RunMetrics {
    let text = format!(
        r#"[rotor]
mass = 10.0
eccentricity = {e}
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
inertia = 0.05
{cargo}
[speed]
mode = "motor"
stall_torque = {stall}
omega_sync = {OMEGA_SYNC}
omega_start = 0.0

[start]
mode = "runup"
angles_deg = {angles}

[metrics]
t_end_revs = 3000
stop_when_settled = false
"#,
        angles = if cargo.matches("[[cargo]]").count() == 3 {
            "[100, 170, 240]"
        } else {
            "[0]"
        },
    );
    SceneFile::parse(&text, "sommerfeld.toml")
        .and_then(|f| f.simulation("sommerfeld.toml"))
        .expect("valid scene")
        .run(false)
        .expect("runs")
        .metrics
}

const NO_BALANCER: &str =
    "[[cargo]]\nmass = 1.0e-9\ntrack_radius = 0.01\ndrag = 1.0e-6\nkappa = 1.0\n";

fn pendulums() -> String {
    "[[cargo]]\nmass = 0.2\ntrack_radius = 0.032\ndrag = 10.0\nkappa = 1.4\n".repeat(3)
}

#[test]
fn a_rotor_without_a_balancer_is_held_where_the_motor_meets_the_whirl_load() {
    let (e, u) = (0.002, 0.02);
    let rotor = PlaneWhirl {
        mass: 10.0,
        stiffness: 1.0e5,
        damping: 100.0,
    };
    let nothing = LumpedWeights {
        unbalance: 0.0,
        drag: 0.0,
    };
    for stall in [3.0, 5.0] {
        let predicted = nothing
            .held(&rotor, u, stall, OMEGA_SYNC)
            .expect("held below resonance");
        let m = run_up(e, NO_BALANCER, stall);
        let spin = m.final_spin_rate.expect("integrated");
        assert!(m.operating_time.is_none(), "M_s = {stall}: passed");
        assert!(
            (spin / predicted.spin - 1.0).abs() < 1e-3,
            "M_s = {stall}: simulated {spin}, torque balance {}",
            predicted.spin
        );
        assert!(predicted.spin < rotor.natural_frequency());
    }
    // Above the load's peak U² ω_n³ / b = 4 N·m at ω_n, with a margin.
    assert!(nothing.held(&rotor, u, 8.0, OMEGA_SYNC).is_none());
    let m = run_up(e, NO_BALANCER, 8.0);
    assert!(m.operating_time.is_some(), "M_s = 8 did not pass");
}

#[test]
fn pendulums_that_run_together_hold_the_rotor_far_above_its_critical_speed() {
    let (e, u) = (0.0006, 0.006);
    // The weights move with the shaft: M_Σ = M + 3 m.
    let rotor = PlaneWhirl {
        mass: 10.6,
        stiffness: 1.0e5,
        damping: 100.0,
    };
    let lump = LumpedWeights {
        unbalance: 3.0 * 0.2 * 0.032,
        drag: 3.0 * 10.0 * 0.032 * 0.032,
    };
    for stall in [4.0, 8.0] {
        let held = lump
            .held(&rotor, u, stall, OMEGA_SYNC)
            .expect("held by the lump");
        let m = run_up(e, &pendulums(), stall);
        let spin = m.final_spin_rate.expect("integrated");
        assert!(m.operating_time.is_none(), "M_s = {stall}: passed");
        assert!(
            (spin / held.spin - 1.0).abs() < 0.01,
            "M_s = {stall}: simulated {spin}, torque balance {}",
            held.spin
        );
        // Far above the critical speed, with the weights whirling near it.
        assert!(held.spin > 1.5 * rotor.natural_frequency());
        assert!((held.weights / rotor.natural_frequency() - 1.0).abs() < 0.05);
        // They run as one lump: equal angles relative to the rotor.
        let a = &m.final_rel_angles_deg;
        assert!(a.iter().all(|x| (x - a[0]).abs() < 1.0), "{a:?}");
    }
    // A motor strong enough to drag the rotor past the lump's peak load.
    assert!(lump.held(&rotor, u, 14.0, OMEGA_SYNC).is_none());
    let m = run_up(e, &pendulums(), 14.0);
    assert!(m.operating_time.is_some(), "M_s = 14 did not pass");
}

/// A study of the motor rotor with `[designs] stall_torque = <list>` and
/// the given speed mode.
fn torque_study(list: &str, speed: &str) -> String {
    format!(
        r#"[scene]
start = "runup"
[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[scene.speed]
{speed}
[designs]
kind = ["ball", "pendulum"]
n = 3
rho = "optimal"
race_radius = 0.05
drag = 10.0
stall_torque = {list}
[sampling]
samples = 1
unbalance = {{ distribution = "fixed", value = 0.5, relative_to = "capacity" }}
[metrics]
t_end_revs = 100
"#
    )
}

const MOTOR: &str = "mode = \"motor\"\nstall_torque = 20.0\nomega_sync = 300.0";

#[test]
fn a_stall_torque_list_is_one_more_design_axis_applied_to_the_motor() {
    use autobal::model::speed::SpeedLaw;
    use autobal::study::plan::config::StudyFile;
    let text = torque_study("[2.0, 8.0, 12.0]", MOTOR);
    let plan = StudyFile::parse(&text, "s.toml")
        .and_then(|f| f.plan(&text, "s.toml"))
        .expect("valid");
    assert_eq!(plan.designs.len(), 6);
    let torques: Vec<f64> = plan
        .designs
        .iter()
        .map(|d| match plan.scene(d, 0.01, 0.0).speed {
            SpeedLaw::Motor { stall_torque, .. } => stall_torque,
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(torques, [2.0, 8.0, 12.0, 2.0, 8.0, 12.0]);
}

#[test]
fn a_bad_stall_torque_list_is_refused_naming_the_key() {
    let cases = [
        (torque_study("[]", MOTOR), "needs at least one value"),
        (torque_study("[4.0, -1.0]", MOTOR), "positive"),
        (torque_study("[0.0]", MOTOR), "positive"),
        (
            torque_study("[4.0]", "mode = \"constant\"\nomega = 300.0"),
            "needs a motor",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (text, why) in cases {
        let path = dir.path().join("s.toml");
        std::fs::write(&path, text).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
            .arg("run")
            .arg(&path)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("designs.stall_torque"), "{err}");
        assert!(err.contains(why), "{err}");
    }
}

#[test]
fn study_run_prints_the_stall_torque_and_the_passage_table() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    let text = format!(
        "output = {:?}\n{}",
        dir.path().display().to_string(),
        torque_study("[4.0, 12.0]", MOTOR)
    );
    std::fs::write(&path, text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("run")
        .arg(&path)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("M_s (N·m)"), "{stdout}");
    assert!(stdout.contains("reached operating speed"), "{stdout}");
    // 100 revolutions at 300 rad/s are 2.1 s: too short for 4 N·m to get there.
    assert!(stdout.contains("0/1"), "{stdout}");
}

/// The pendulum design of `studies/sommerfeld.toml` at the given stall torque.
fn shipped_pendulums(
    torque: f64,
    tolerances: &str,
) -> (autobal::study::plan::config::StudyPlan, u32) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/studies/sommerfeld.toml");
    let text = std::fs::read_to_string(path).unwrap() + tolerances;
    let plan = autobal::study::plan::config::StudyFile::parse(&text, path)
        .unwrap()
        .plan(&text, path)
        .unwrap();
    let id = plan
        .designs
        .iter()
        .find(|d| d.spec.kind.name() == "pendulum" && d.stall_torque == Some(torque))
        .unwrap()
        .id;
    (plan, id)
}

#[test]
fn identical_pendulums_that_meet_end_merged_instead_of_reporting_the_pair_as_physics() {
    use autobal::metrics::Outcome;
    use autobal::study::run::run_design_sample;
    let (plan, id) = shipped_pendulums(12.0, "");
    let design = plan.designs[id as usize].clone();
    let run = run_design_sample(&plan, &design, 9, 9);
    assert_eq!(
        run.metrics.outcome,
        Outcome::Merged,
        "{}",
        run.metrics.reason
    );
    assert!(
        run.metrics.reason.contains("coincided"),
        "{}",
        run.metrics.reason
    );
    assert!(!run.metrics.settled);
    // The same run with the weights' masses spread by 1e-6: no pair is
    // identical, nothing merges, and the run balances.
    let (plan, id) = shipped_pendulums(
        12.0,
        "\n[sampling.tolerances]\nmass = { sigma = 1e-6, relative = true }\n",
    );
    let design = plan.designs[id as usize].clone();
    let run = run_design_sample(&plan, &design, 9, 9);
    assert_ne!(
        run.metrics.outcome,
        Outcome::Merged,
        "{}",
        run.metrics.reason
    );
    assert!(run.metrics.residual_rel < 0.05, "{}", run.metrics.reason);
}
