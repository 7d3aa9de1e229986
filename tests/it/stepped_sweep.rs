//! Stepped speed sweeps (`study stepped`): the state and the spin angle are
//! carried from one dwell to the next, so two dwells at one speed are one
//! dwell twice as long, and a refused dwell names its flag.

use autobal::scene_file::SceneFile;
use autobal::simulation::Simulation;
use autobal::simulation::stepped::{Direction, stepped_speeds};

fn three_balls() -> Simulation {
    let text = std::fs::read_to_string("scenes/three_balls.toml")
        .expect("shipped scene")
        .replace("[metrics]", "[solver]\nrtol = 1e-10\n[metrics]");
    SceneFile::parse(&text, "three_balls.toml")
        .expect("valid")
        .simulation("three_balls.toml")
        .expect("simulation")
}

#[test]
fn two_dwells_at_one_speed_are_one_dwell_twice_as_long() {
    // The weights are still moving after 10 revolutions: a state or a spin
    // angle dropped at the step (φ restarted at 0 turns the unbalance by
    // ω·dwell) would move where they end by degrees.
    let sim = three_balls();
    let omega = 4.0;
    let rev = 2.0 * std::f64::consts::PI / omega;
    let split = sim
        .stepped_sweep(
            &[(Direction::Up, omega), (Direction::Up, omega)],
            10.3 * rev,
        )
        .expect("runs");
    let whole = sim
        .stepped_sweep(&[(Direction::Up, omega)], 20.6 * rev)
        .expect("runs");
    let (a, b) = (&split[1], &whole[0]);
    for (x, y) in a.angles_deg.iter().zip(&b.angles_deg) {
        assert!(
            (x - y).abs() < 1e-5,
            "angles {:?} vs {:?}",
            a.angles_deg,
            b.angles_deg
        );
    }
    assert!(
        (a.whirl_peak / b.whirl_peak - 1.0).abs() < 1e-5,
        "whirl {} vs {}",
        a.whirl_peak,
        b.whirl_peak
    );
    // And the weights did move between the two dwells' ends.
    let moved = split[0]
        .angles_deg
        .iter()
        .zip(&split[1].angles_deg)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(moved > 1.0, "the weights moved only {moved}°");
}

#[test]
fn the_speeds_go_up_to_the_top_and_back_without_repeating_it() {
    let s = stepped_speeds(1.0, 2.0, 0.3, true);
    let up: Vec<f64> = s
        .iter()
        .filter(|p| p.0 == Direction::Up)
        .map(|p| p.1)
        .collect();
    let down: Vec<f64> = s
        .iter()
        .filter(|p| p.0 == Direction::Down)
        .map(|p| p.1)
        .collect();
    assert_eq!(up.len(), 5, "{up:?}");
    assert!((up[3] - 1.9).abs() < 1e-12 && up[4] == 2.0, "{up:?}");
    assert_eq!(down.len(), 4, "{down:?}");
    assert!(
        down.iter()
            .zip(up.iter().rev().skip(1))
            .all(|(d, u)| d == u)
    );
    assert_eq!(stepped_speeds(1.0, 2.0, 0.5, false).len(), 3);
}

#[test]
fn a_dwell_shorter_than_a_revolution_is_refused_naming_the_flag() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["stepped", "scenes/three_balls.toml", "--rpm", "30..40"])
        .args(["--step-rpm", "5", "--dwell", "1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--dwell 1") && err.contains("one revolution"),
        "{err}"
    );
}
