//! `study calibrate` on a synthetic rig: data the model generates at a
//! known truth with noise; the fit must find the truth inside its
//! intervals, the intervals must cover it in at least 90 % of 20
//! repetitions on fresh noise and be narrower than the priors, the results
//! must not depend on the thread count, and bad rig files are refused.

use polars::prelude::*;
use std::path::Path;
use std::process::{Command, Output};

const RIG: &str = "rigs/synthetic_three_balls.toml";
const TRUTH: &str = "effects.rolling_resistance.coefficient=3e-5,balancer.drag=10";
const KEYS: [(&str, f64); 2] = [
    ("balancer.drag", 10.0),
    ("effects.rolling_resistance.coefficient", 3e-5),
];

fn calibrate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("calibrate")
        .args(args)
        .output()
        .unwrap()
}

fn frame(dir: &Path, name: &str) -> DataFrame {
    let file = std::fs::File::open(dir.join(name)).unwrap();
    ParquetReader::new(file).finish().unwrap()
}

fn column(df: &DataFrame, name: &str) -> Vec<f64> {
    df.column(name)
        .unwrap()
        .f64()
        .unwrap()
        .iter()
        .map(|v| v.unwrap())
        .collect()
}

/// The truth lies inside each unknown's 95 % interval, the drag's interval
/// is a small part of its prior (the points pin it), and over 20
/// repetitions on fresh noise each interval covers the truth at least 18
/// times. A cheap setting (32 + 32 draws, 2 restarts) to keep CI short.
#[test]
fn synthetic_rig_is_recovered_and_its_intervals_cover_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let out = calibrate(&[
        RIG,
        "--synthetic",
        TRUTH,
        "--repeats",
        "20",
        "--draws",
        "32",
        "--restarts",
        "2",
        "--budget",
        "40",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let est = frame(&out_dir, "calibration.parquet");
    let keys: Vec<String> = est
        .column("key")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|k| k.unwrap().to_string())
        .collect();
    let (lo, hi) = (column(&est, "p025"), column(&est, "p975"));
    let (pmin, pmax) = (column(&est, "prior_min"), column(&est, "prior_max"));
    for (j, (key, truth)) in KEYS.iter().enumerate() {
        assert_eq!(keys[j], *key);
        assert!(
            lo[j] <= *truth && *truth <= hi[j],
            "{key}: {truth} outside [{}, {}]\n{stdout}",
            lo[j],
            hi[j]
        );
    }
    // Drag: a log-uniform prior over a factor 25; the interval a factor < 3.
    let share = (hi[0] / lo[0]).ln() / (pmax[0] / pmin[0]).ln();
    assert!(
        share < 0.35,
        "drag interval is {share:.2} of the prior\n{stdout}"
    );
    let cov = frame(&out_dir, "coverage.parquet");
    assert_eq!(cov.height(), 20);
    for (key, _) in KEYS {
        let covered = cov
            .column(&format!("covered.{key}"))
            .unwrap()
            .bool()
            .unwrap()
            .iter()
            .filter(|c| c.unwrap())
            .count();
        assert!(covered >= 18, "{key}: covered {covered} of 20\n{stdout}");
    }
    assert!(
        stdout.contains("Synthetic check, 20 repetitions"),
        "{stdout}"
    );
}

/// The shipped rig file holds exactly the data `--synthetic` generates at
/// its stated truth (its header's claim), and the results are bit-identical
/// on one thread and on all.
#[test]
fn shipped_synthetic_data_is_the_tools_own_and_threads_do_not_matter() {
    let dir = tempfile::tempdir().unwrap();
    let cheap = ["--draws", "8", "--restarts", "1", "--budget", "12"];
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let mut from_file = vec![RIG, "--threads", "1", "--out", a.to_str().unwrap()];
    from_file.extend(cheap);
    let mut synthetic = vec![RIG, "--synthetic", TRUTH, "--out", b.to_str().unwrap()];
    synthetic.extend(cheap);
    for args in [from_file, synthetic] {
        let out = calibrate(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    for name in ["calibration.parquet", "points.parquet", "draws.parquet"] {
        assert!(
            frame(&a, name).equals_missing(&frame(&b, name)),
            "{name} differs"
        );
    }
}

/// Bad rig files and flags exit 2 naming the key, and write nothing.
#[test]
fn bad_rig_files_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(RIG)).unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/synthetic_rig.toml");
    let text = text.replace(
        "scene = \"../scenes/synthetic_rig.toml\"",
        &format!("scene = {:?}", scene.display().to_string()),
    );
    let cases: [(&str, String, &str); 5] = [
        (
            "unknown not in the scene",
            text.replace("\"balancer.drag\" =", "\"balancer.dreg\" ="),
            "unknowns.\"balancer.dreg\"",
        ),
        (
            "a reading without uncertainty",
            text.replacen("sd = 0.2", "sd = 0.0", 1),
            "point[0].sd",
        ),
        (
            "a stepped quantity under a run protocol",
            text.replacen("quantity = \"settling_time\"", "quantity = \"ratio\"", 1),
            "point[0].quantity",
        ),
        (
            "a point of no case",
            text.replacen("case = \"e = 0.15 mm\"", "case = \"e = 9 mm\"", 1),
            "point[0].case",
        ),
        (
            "a prior end the scene refuses",
            text.replace("min = 2.0, max = 50.0", "min = -1.0, max = 50.0"),
            "unknowns.\"balancer.drag\"",
        ),
    ];
    for (what, body, key) in cases {
        let rig = dir.path().join("rig.toml");
        std::fs::write(&rig, body).unwrap();
        let out_dir = dir.path().join("never");
        let out = calibrate(&[rig.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{what}: {err}");
        assert!(err.contains(key), "{what}: {err}");
        assert!(!out_dir.exists(), "{what}: wrote {}", out_dir.display());
    }
    let out = calibrate(&[RIG, "--repeats", "3"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--synthetic"));
    let out = calibrate(&[RIG, "--synthetic", "balancer.drag=10"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("effects.rolling_resistance.coefficient")
    );
}

/// Every shipped rig file reads, and its scene accepts every key it sets:
/// a rig whose calibration takes an hour and a half must not fail on a
/// typo after the first draws.
#[test]
fn every_shipped_rig_file_builds_its_problem() {
    use autobal::calibrate::problem::RigProblem;
    use autobal::calibrate::rig_file::RigFile;
    use autobal::scene_file::SceneFile;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut rigs: Vec<_> = std::fs::read_dir(root.join("rigs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    rigs.sort();
    assert!(rigs.len() >= 3, "{rigs:?}");
    for path in rigs {
        let rig = RigFile::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let scene_path = rig.scene_path(&path);
        let scene = SceneFile::read(&scene_path)
            .unwrap_or_else(|e| panic!("{}: {e}", scene_path.display()));
        RigProblem::new(rig, scene, &scene_path.display().to_string())
            .unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    }
}

/// A ball offset is read from the light spot: a point on a case without
/// a static unbalance (Bristol's 0 washers, a pure couple) is refused
/// before any run, naming the point.
#[test]
fn a_ball_offset_without_a_light_spot_is_refused() {
    use autobal::calibrate::problem::RigProblem;
    use autobal::calibrate::rig_file::RigFile;
    use autobal::scene_file::SceneFile;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("rigs/bristol_fig12_angles.toml")).unwrap();
    let scene_path = root.join("scenes/bristol_uncertain.toml");
    let text = text.replace(
        "scene = \"../scenes/bristol_uncertain.toml\"",
        &format!("scene = {:?}", scene_path.display().to_string()),
    );
    let last = text.rfind("case = \"2 washers\"").unwrap();
    let moved = format!(
        "{}case = \"0 washers\"{}",
        &text[..last],
        &text[last + "case = \"2 washers\"".len()..]
    );
    let dir = tempfile::tempdir().unwrap();
    for (body, refused) in [(text, false), (moved, true)] {
        let path = dir.path().join("rig.toml");
        std::fs::write(&path, body).unwrap();
        let rig = RigFile::read(&path).unwrap();
        let offset_point = rig.points.len() - 1;
        let scene = SceneFile::read(&scene_path).unwrap();
        let made = RigProblem::new(rig, scene, "bristol_uncertain.toml");
        match made {
            Ok(_) => assert!(!refused, "a ball offset on a pure couple was accepted"),
            Err(e) => {
                assert!(refused, "{e:?}");
                let shown = format!("{e:?} {e}");
                assert!(
                    shown.contains(&format!("point[{offset_point}].quantity"))
                        && shown.contains("light spot"),
                    "{shown}"
                );
            }
        }
    }
}
