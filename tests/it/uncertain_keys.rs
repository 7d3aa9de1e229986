//! Uncertain scene keys (`[uncertain]`): drawn per sample from streams of
//! their own, written into the run's scene, recorded as `scene.<key>`
//! columns, and refused up front where they cannot take effect.

use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::results::record::{RunRecord, to_dataframe};
use autobal::study::run::{run_one, sample_simulation};
use autobal::uncertain::{apply, read};
use polars::prelude::*;
use std::process::Command;

/// The main job's rotor with three balls, short runs, and `extra` appended
/// (an `[uncertain]` table, an effect).
fn study(samples: u32, extra: &str) -> String {
    format!(
        r#"
name = "uq"
seed = 5
output = "unused"
[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
inertia = 0.05
[scene.speed]
mode = "constant"
omega = 300.0
[designs]
kind = "ball"
n = [2, 3]
rho = 0.25
race_radius = 0.05
drag = 10.0
[sampling]
samples = {samples}
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.9, relative_to = "capacity" }}
[metrics]
t_end_revs = 200
hold_revs = 20
{extra}
"#
    )
}

fn plan(text: &str) -> StudyPlan {
    StudyFile::parse(text, "uq.toml")
        .unwrap()
        .plan(text, "uq.toml")
        .unwrap()
}

fn refusal(text: &str) -> String {
    match StudyFile::parse(text, "uq.toml")
        .and_then(|f| f.plan(text, "uq.toml"))
        .map(|_| ())
    {
        Ok(()) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn runs(plan: &StudyPlan) -> Vec<RunRecord> {
    (0..plan.total_runs()).map(|id| run_one(plan, id)).collect()
}

/// Every column of the runs but wall time, as bits.
fn columns(runs: &[RunRecord]) -> DataFrame {
    to_dataframe(runs).unwrap().drop("wall_time_s").unwrap()
}

/// Every shipped study's scene survives the round trip the uncertain keys
/// take (serialize, set nothing, read back) exactly: a key written into the
/// scene changes that key and nothing else.
#[test]
fn every_shipped_scene_reads_back_exactly() {
    for path in crate::fixtures::shipped_studies() {
        let plan = crate::fixtures::shipped_plan(&path, 1, |_| {});
        for design in &plan.designs {
            let scene = plan.scene(design, 0.3 * design.capacity, 1.1);
            assert_eq!(
                apply(&scene, &[]).as_ref(),
                Ok(&scene),
                "{}",
                path.display()
            );
        }
    }
}

/// The rotor's inertia at constant speed enters no equation of motion:
/// drawing it leaves the outcome and settling time of every run bit for
/// bit, and the residual and final state within rounding (1e-9 relative;
/// it moves them in the 12th digit on some runs, through the solver's
/// arithmetic rather than the physics).
#[test]
fn a_dummy_key_changes_no_other_column() {
    let without = runs(&plan(&study(6, "")));
    let with = runs(&plan(&study(
        6,
        "[uncertain]\n\"rotor.inertia\" = { distribution = \"uniform\", min = 0.01, max = 0.5 }",
    )));
    let (a, b) = (columns(&without), columns(&with));
    assert_eq!(b.width(), a.width() + 1);
    let drawn = b.column("scene.rotor.inertia").unwrap().f64().unwrap();
    assert!(drawn.iter().flatten().all(|x| (0.01..=0.5).contains(&x)));
    assert!(drawn.n_unique().unwrap() > 1);
    for name in [
        "outcome",
        "settled",
        "settling_revs",
        "unbalance",
        "initial_angles_deg",
    ] {
        assert!(
            a.column(name)
                .unwrap()
                .equals_missing(b.column(name).unwrap()),
            "{name}"
        );
    }
    for (x, y) in without.iter().zip(&with) {
        let (p, q) = (x.metrics.residual_abs, y.metrics.residual_abs);
        assert!((p - q).abs() <= 1e-9 * p.abs(), "{p} vs {q}");
        assert!((x.metrics.t_final - y.metrics.t_final).abs() <= 1e-9 * x.metrics.t_final);
    }
}

/// Adding a key that changes the physics leaves every other draw (unbalance,
/// direction, start angles, another key's values) bit-identical, and the
/// drawn value is what the run's scene holds.
#[test]
fn adding_a_key_leaves_the_other_draws_alone_and_reaches_the_scene() {
    let k = "\"rotor.kx\" = { distribution = \"normal\", mean = 1e5, sd = 1e4 }";
    let c = "\"rotor.bx\" = { distribution = \"log_uniform\", min = 50, max = 200 }";
    let one = plan(&study(6, &format!("[uncertain]\n{k}")));
    let two = plan(&study(6, &format!("[uncertain]\n{k}\n{c}")));
    let (a, b) = (columns(&runs(&one)), columns(&runs(&two)));
    for name in [
        "unbalance",
        "direction_deg",
        "initial_angles_deg",
        "scene.rotor.kx",
    ] {
        assert!(
            a.column(name)
                .unwrap()
                .equals_missing(b.column(name).unwrap()),
            "{name}"
        );
    }
    assert!(
        !a.column("settling_revs")
            .unwrap()
            .equals_missing(b.column("settling_revs").unwrap()),
        "the damping drawn changes the settling"
    );
    for (design, sample) in [(0, 0), (1, 3)] {
        let (s, sim) = sample_simulation(&two, &two.designs[design], sample);
        for v in &s.uncertain {
            assert_eq!(
                read(&sim.scene, &v.key).unwrap().to_bits(),
                v.value.to_bits()
            );
        }
        assert_eq!(s.uncertain.len(), 2);
    }
}

/// Each refusal names the uncertain key and says why.
#[test]
fn keys_that_cannot_take_effect_are_refused_naming_them() {
    let cases = [
        (
            "\"rotor.kz\" = { distribution = \"uniform\", min = 1, max = 2 }",
            "sets no `kz`",
        ),
        (
            "\"start.x\" = { distribution = \"uniform\", min = 1, max = 2 }",
            "lies under",
        ),
        (
            "\"rotor.kx\" = { distribution = \"uniform\", min = -1e5, max = 1e5 }",
            "lowest value",
        ),
        (
            "\"rotor.kx\" = { distribution = \"log_uniform\", min = 0, max = 1e5 }",
            "must be positive",
        ),
        (
            "\"rotor.kx\" = { distribution = \"normal\", mean = 1e5, sd = 0 }",
            "sd",
        ),
        (
            "\"rotor.kx\" = { distribution = \"uniform\", min = 2e5, max = 1e5 }",
            "must be above",
        ),
        // The study draws the rotor's unbalance itself in every run.
        (
            "\"rotor.eccentricity\" = { distribution = \"uniform\", min = 1e-5, max = 2e-5 }",
            "sets this key itself",
        ),
        (
            "\"speed.omega\" = { distribution = \"uniform\", min = 0, max = 300 }",
            "lowest value",
        ),
    ];
    for (line, why) in cases {
        let message = refusal(&study(2, &format!("[uncertain]\n{line}")));
        let key = line.split(" = ").next().unwrap();
        assert!(
            message.contains(&format!("uncertain.{key}")),
            "{line}: {message}"
        );
        assert!(message.contains(why), "{line}: {message}");
    }
}

/// From the command line: exit 2, the key named, nothing written.
#[test]
fn the_cli_refuses_a_bad_key_with_exit_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("results");
    let text = study(
        2,
        "[uncertain]\n\"rotor.kz\" = { distribution = \"uniform\", min = 1, max = 2 }",
    )
    .replace(
        "output = \"unused\"",
        &format!("output = \"{}\"", out.display()),
    );
    let file = dir.path().join("uq.toml");
    std::fs::write(&file, text).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", file.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("uncertain.\"rotor.kz\""), "{stderr}");
    assert!(!out.exists());
}

/// A scene file's `[uncertain]` keys: `study simulate --draws N` runs each
/// draw, `--json` gives every draw's values within their distributions, and
/// `--draws` on a scene without such keys is refused with exit 2.
#[test]
fn simulate_draws_the_scene_files_keys() {
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let run = |file: &str, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_study"))
            .arg("simulate")
            .arg(scene.join(file))
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run("three_balls.toml", &["--draws", "2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no [uncertain] keys"));
    let out = run("bristol_uncertain.toml", &["--draws", "3", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let draws: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let draws = draws.as_array().unwrap();
    assert_eq!(draws.len(), 3);
    for d in draws {
        let mu = d["values"]["effects.rolling_resistance.coefficient"]
            .as_f64()
            .unwrap();
        let angle = d["values"]["effects.race_eccentricity.angle_deg"]
            .as_f64()
            .unwrap();
        assert!(
            (3e-4..=3e-3).contains(&mu) && (0.0..=360.0).contains(&angle),
            "{d}"
        );
        assert!(d["metrics"]["residual_rel"].as_f64().unwrap() > 0.0, "{d}");
    }
    assert_ne!(draws[0]["values"], draws[1]["values"]);
}
