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

/// A reading window holds whole revolutions at the dwell's end: its peak is
/// the largest sample recorded in it, its samples are in time order inside
/// the dwell, a one-revolution window is the default reading, and the dwell
/// itself (the state at its end) does not depend on how it is read.
#[test]
fn a_reading_window_is_the_recorded_samples_at_the_dwells_end() {
    use autobal::simulation::stepped::SweepSeries;
    let sim = three_balls();
    let omega = 4.0;
    let rev = 2.0 * std::f64::consts::PI / omega;
    let speeds = [(Direction::Up, omega), (Direction::Up, omega * 1.5)];
    let dwell = 12.0 * rev;
    let mut series = SweepSeries::default();
    let read = sim
        .stepped_sweep_windowed(&speeds, dwell, Some(3.0 * rev), Some(&mut series))
        .expect("runs");
    // One revolution at the faster speed: less than one at the slower, and
    // a window holds at least one whole revolution.
    let fast_rev = 2.0 * std::f64::consts::PI / (omega * 1.5);
    let last_rev = sim
        .stepped_sweep_windowed(&speeds, dwell, Some(fast_rev), None)
        .expect("runs");
    assert_eq!(last_rev, sim.stepped_sweep(&speeds, dwell).expect("runs"));
    for (step, p) in read.iter().enumerate() {
        let rows: Vec<usize> = (0..series.t.len())
            .filter(|&i| series.step[i] as usize == step)
            .collect();
        let w_rev = 2.0 * std::f64::consts::PI / p.omega;
        let t0 = step as f64 * dwell;
        let (first, last) = (series.t[rows[0]], series.t[*rows.last().unwrap()]);
        let revs = (3.0 * rev / w_rev - 1e-9).ceil();
        let begins = t0 + dwell - revs * w_rev;
        assert!(
            first > begins && first < begins + 0.1 * w_rev,
            "{first} vs {begins}"
        );
        assert!(
            (last - (t0 + dwell)).abs() < 1e-9,
            "{last} vs {}",
            t0 + dwell
        );
        assert!(rows.windows(2).all(|w| series.t[w[1]] > series.t[w[0]]));
        let peak = rows.iter().map(|&i| series.whirl[i]).fold(0.0, f64::max);
        assert_eq!(peak, p.whirl_peak);
        // The three-revolution peak holds the last revolution's.
        assert!(p.whirl_peak >= last_rev[step].whirl_peak);
        for (x, y) in p.angles_deg.iter().zip(&last_rev[step].angles_deg) {
            assert!((x - y).abs() < 1e-6, "{x} vs {y}");
        }
    }
}

/// `study stepped ARGS` from the repository's root.
fn stepped(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("stepped")
        .args(args)
        .output()
        .unwrap()
}

/// `study stepped` warns where a scene makes the protocol matter or its
/// weights unlike solid balls, writes the recording with --series, and
/// refuses flags that cannot take effect, naming them.
#[test]
fn the_stepped_verb_warns_records_and_refuses_by_flag() {
    let study = stepped;
    let dir = tempfile::tempdir().unwrap();
    let series = dir.path().join("series.parquet");
    let out = study(&[
        "scenes/three_balls.toml",
        "--rpm",
        "38..40",
        "--step-rpm",
        "1",
        "--dwell",
        "5",
        "--window",
        "2",
        "--series",
        series.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("[[cargo]] weights are point masses"), "{err}");
    let df = autobal::study::results::io::read_parquet(&series).unwrap();
    assert_eq!(
        df.get_column_names()
            .iter()
            .map(|c| c.as_str())
            .collect::<Vec<_>>(),
        ["step", "direction", "rpm", "t", "whirl"]
    );
    let out = study(&[
        "scenes/bristol_uncertain.toml",
        "--rpm",
        "4000..4100",
        "--step-rpm",
        "100",
        "--dwell",
        "0.1",
        "--draws",
        "1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("with rolling resistance"), "{err}");
    for (flags, named) in [
        (&["--window", "6"][..], "--window"),
        (&["--threads", "2"][..], "--threads"),
    ] {
        let mut args = vec![
            "scenes/three_balls.toml",
            "--rpm",
            "38..40",
            "--step-rpm",
            "1",
            "--dwell",
            "5",
        ];
        args.extend(flags);
        let out = study(&args);
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).contains(named));
    }
    let out = study(&[
        "scenes/bristol_uncertain.toml",
        "--rpm",
        "4000..4100",
        "--step-rpm",
        "100",
        "--dwell",
        "0.1",
        "--series",
        dir.path().join("s2.parquet").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--series"));
    assert!(!dir.path().join("s2.parquet").exists());
}

/// A sweep that could never end (a day's dwell at millions of rpm: 10¹⁰
/// revolutions) and an output file named for another format are refused
/// before any dwell, exit 2, naming the flag and writing nothing.
#[test]
fn an_endless_sweep_and_a_csv_name_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let study = |args: &[&str]| stepped(&[&["scenes/three_balls.toml"], args].concat());
    let endless = study(&["--rpm", "8e6..9e6", "--step-rpm", "1e5", "--dwell", "86400"]);
    let err = String::from_utf8_lossy(&endless.stderr);
    assert_eq!(endless.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--dwell 86400") && err.contains("revolutions"),
        "{err}"
    );
    for flag in ["--out", "--series"] {
        let csv = dir.path().join("steps.csv");
        let out = study(&[
            "--rpm",
            "38..40",
            "--step-rpm",
            "1",
            "--dwell",
            "5",
            flag,
            csv.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag}: {err}");
        assert!(
            err.contains(flag) && err.contains(".parquet"),
            "{flag}: {err}"
        );
        assert!(!csv.exists(), "{flag}: wrote {}", csv.display());
    }
}
