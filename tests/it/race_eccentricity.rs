//! Race eccentricity (issue 19, item 2): the weights centre the race on the
//! axis, leaving the rotor whirling at exactly r = e_r (docs/model.md, "Race
//! eccentricity"), whatever their mass; both formulations agree.

use crate::fixtures::{assert_same_run, scene_metrics};
use autobal::scene_file::SceneFile;

/// The dimensionless three-ball scene (ω = 4 ω_n, e = 0.01, capacity 3 M e)
/// with its race centre `offset` off the axis at `angle_deg`, run to the end.
fn scene(offset: f64, angle_deg: f64, cargo_mass: f64, extra: &str) -> String {
    let mut text = std::fs::read_to_string("scenes/three_balls.toml").expect("shipped scene");
    text = text.replace("mass = 0.01\n", &format!("mass = {cargo_mass}\n"));
    text = text.replace(
        "t_end_revs = 1000",
        "t_end_revs = 600\nstop_when_settled = false",
    );
    text.push_str(&format!(
        "\n[effects.race_eccentricity]\noffset = {offset}\nangle_deg = {angle_deg}\n{extra}"
    ));
    text
}

fn run(text: &str) -> autobal::simulation::RunResult {
    let file = SceneFile::parse(text, "race.toml").expect("valid scene");
    file.simulation("race.toml")
        .expect("simulation")
        .run(true)
        .expect("runs")
}

/// Final rotor displacement in the frame turning with the rotor, (|w|, arg w).
fn final_whirl(text: &str) -> (f64, f64) {
    let series = run(text).series.expect("recorded");
    let k = series.t.len() - 1;
    let a = 4.0 * series.t[k];
    let (x, y) = (series.x[k], series.y[k]);
    let (u, v) = (x * a.cos() + y * a.sin(), -x * a.sin() + y * a.cos());
    (u.hypot(v), v.atan2(u))
}

#[test]
fn the_weights_centre_the_race_and_the_rotor_whirls_at_the_offset() {
    for (offset, angle) in [(1e-4, 0.0), (2e-4, 0.0), (1e-4, 130.0), (5e-4, -60.0)] {
        for mass in [0.01, 0.02] {
            let (r, arg) = final_whirl(&scene(offset, angle, mass, ""));
            assert!(
                (r / offset - 1.0).abs() < 1e-3,
                "e_r {offset}, m {mass}: r/e_r = {}",
                r / offset
            );
            // w = −e_r e^{iθ}: the rotor sits opposite the race centre.
            let expected = (angle + 180.0f64).to_radians();
            let miss = (arg - expected)
                .sin()
                .abs()
                .max(((arg - expected).cos() - 1.0).abs());
            assert!(miss < 1e-3, "e_r {offset}, θ {angle}: arg w = {arg}");
        }
    }
}

#[test]
fn both_formulations_agree_with_an_off_centre_race() {
    let rotating = final_whirl(&scene(
        2e-4,
        45.0,
        0.01,
        "\n[solver]\nfidelity = \"rotating\"\n",
    ));
    let full = final_whirl(&scene(
        2e-4,
        45.0,
        0.01,
        "\n[solver]\nfidelity = \"full\"\nrtol = 1e-9\n",
    ));
    assert!(
        (rotating.0 / full.0 - 1.0).abs() < 1e-4,
        "{rotating:?} vs {full:?}"
    );
    assert!(
        (rotating.1 - full.1).sin().abs() < 1e-4,
        "{rotating:?} vs {full:?}"
    );
}

#[test]
fn a_zero_offset_is_the_scene_without_the_effect() {
    let base = std::fs::read_to_string("scenes/three_balls.toml").expect("scene");
    let with_table = format!("{base}\n[effects.race_eccentricity]\noffset = 0.0\nangle_deg = 30\n");
    assert_same_run(&scene_metrics(&with_table), &scene_metrics(&base));
}

#[test]
fn a_motor_driven_rotor_is_refused_naming_the_field() {
    let text = scene(1e-4, 0.0, 0.01, "").replace(
        "mode = \"constant\"\nomega = 4.0",
        "mode = \"motor\"\nstall_torque = 1.0\nomega_sync = 4.0",
    );
    let err = SceneFile::parse(&text, "m.toml")
        .and_then(|f| f.simulation("m.toml").map(|_| ()))
        .expect_err("refused");
    let message = err.to_string();
    assert!(
        message.contains("effects.race_eccentricity.offset"),
        "{message}"
    );
    assert!(message.contains("prescribed speed"), "{message}");
}

#[test]
fn the_locked_start_carries_the_weights_mass_at_the_offset() {
    // Weights held by a drag a million times the rotor's damping: they barely
    // move in the first revolutions, so a start that is the locked system's
    // steady state keeps r constant; one that leaves out the weights' mass
    // carried at e_r starts a transient of the size of m_Σ e_r against U.
    let text = scene(5e-3, 40.0, 0.02, "")
        .replace("drag = 0.01", "drag = 1.0e5")
        .replace("t_end_revs = 600", "t_end_revs = 3\nhold_revs = 1");
    let series = run(&text).series.expect("recorded");
    let r0 = series.r[0];
    let wander = series
        .r
        .iter()
        .map(|r| (r - r0).abs() / r0)
        .fold(0.0, f64::max);
    assert!(
        wander < 2e-4,
        "r wanders by {wander:.2e} of r(0) = {r0:.4e}"
    );
}
