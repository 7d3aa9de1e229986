//! The cause of a design's unsettled runs, by counterfactual re-runs
//! (issue 70): on the bench grinder (studies/bench_grinder.toml) the floor
//! checks name the dead band of rolling resistance, but re-running the runs
//! that did not settle without each effect shows the race eccentricity is
//! what stops them, and rolling resistance is not.

use autobal::study::results::io::read_parquet;
use polars::prelude::DataFrame;
use std::path::Path;
use std::process::{Command, Output};

/// The bench grinder's study file, written into `dir` with its output
/// there and `extra` lines appended to its `[summary]` table.
fn grinder(dir: &Path, extra: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/bench_grinder.toml"),
    )
    .unwrap();
    let path = dir.join("study.toml");
    std::fs::write(
        &path,
        format!("output = \"{}\"\n{text}{extra}", dir.display()),
    )
    .unwrap();
    path
}

fn run(study: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("run")
        .arg(study)
        .args(["--quiet", "--wide", "--overwrite"])
        .args(args)
        .output()
        .unwrap()
}

/// Column `name` of `df` as strings (null: "").
fn strings(df: &DataFrame, name: &str) -> Vec<String> {
    df.column(name)
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|s| s.unwrap_or_default().to_string())
        .collect()
}

/// Re-runs (settled, all) of one counterfactual in causes.parquet.
fn tally(causes: &DataFrame, key: &str) -> (usize, usize) {
    let keys = strings(causes, "counterfactual");
    let settled = causes.column("settled").unwrap().bool().unwrap();
    let mine: Vec<usize> = (0..keys.len()).filter(|&i| keys[i] == key).collect();
    let hits = mine
        .iter()
        .filter(|&&i| settled.get(i) == Some(true))
        .count();
    (hits, mine.len())
}

/// The cause named is the race eccentricity, with the counts the re-runs
/// left in causes.parquet, and rolling resistance, whose dead band the
/// floor checks name, is not: removing it settles none.
#[test]
fn the_grinder_fails_to_settle_because_of_its_race_not_its_rolling_resistance() {
    let tmp = tempfile::tempdir().unwrap();
    let out = run(&grinder(tmp.path(), ""), &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    // Before the experiment the verdict named the dead band here.
    assert!(
        stdout.contains("cause: why") && stdout.contains("race eccentricity — removing it settles"),
        "{stdout}"
    );
    let folder = tmp.path().join("bench_grinder");
    let runs = read_parquet(&folder.join("runs.parquet")).unwrap();
    let unsettled = strings(&runs, "outcome")
        .iter()
        .filter(|o| *o == "censored" || *o == "not_settled")
        .count();
    assert!(
        unsettled >= 4,
        "too few unsettled runs to test: {unsettled}"
    );
    let causes = read_parquet(&folder.join("causes.parquet")).unwrap();
    let (race, race_n) = tally(&causes, "race_eccentricity");
    let (rolling, rolling_n) = tally(&causes, "rolling_resistance");
    // Every unsettled run was re-run without each of the two.
    assert_eq!((race_n, rolling_n), (unsettled, unsettled));
    assert!(2 * race >= race_n, "race eccentricity {race} of {race_n}");
    assert!(
        2 * rolling < rolling_n,
        "rolling resistance {rolling} of {rolling_n}"
    );
    let named = format!("race eccentricity — removing it settles {race} of {race_n}");
    assert!(stdout.contains(&named), "{stdout}");
    assert!(
        stdout.contains(&format!("rolling resistance {rolling} of {rolling_n}")),
        "{stdout}"
    );
    assert!(
        !stdout.contains("rolling resistance — removing it"),
        "{stdout}"
    );
    let summary = read_parquet(&folder.join("summary.parquet")).unwrap();
    assert_eq!(strings(&summary, "cause_tested_key"), ["race_eccentricity"]);
    // The report shows the counts.
    let page = tmp.path().join("report.html");
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("report")
        .arg(&folder)
        .arg("--out")
        .arg(&page)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(&page).unwrap();
    let row =
        format!("<tr><td>race eccentricity</td><td>{race_n}</td><td>{race}</td><td>0</td></tr>");
    assert!(
        html.contains("id=\"causes-table\"") && html.contains(&row),
        "{html}"
    );
}

/// The re-runs are the seed's, not the schedule's: one thread and two
/// write the same causes.parquet.
#[test]
fn the_re_runs_do_not_depend_on_the_thread_count() {
    let tmp = tempfile::tempdir().unwrap();
    let study = grinder(tmp.path(), "");
    let table = |threads: &str| {
        let out = run(&study, &["--threads", threads]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        read_parquet(&tmp.path().join("bench_grinder/causes.parquet")).unwrap()
    };
    let one = table("1");
    let two = table("2");
    assert!(one.height() > 0);
    assert!(one.equals_missing(&two), "{one}\n{two}");
}

/// `counterfactual_runs` bounds the samples re-run (the first by sample
/// id), 0 turns the experiment off and removes an earlier causes.parquet,
/// and a value beyond the bound is refused naming the key.
#[test]
fn the_experiment_is_bounded_and_can_be_turned_off() {
    let tmp = tempfile::tempdir().unwrap();
    let set = |n: &str| {
        grinder(
            tmp.path(),
            &format!("\n[summary]\ncounterfactual_runs = {n}\n"),
        )
    };
    let causes = tmp.path().join("bench_grinder/causes.parquet");
    let out = run(&set("3"), &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("(the first 3 of them re-run"), "{stdout}");
    let table = read_parquet(&causes).unwrap();
    let mut samples: Vec<u32> = table
        .column("sample_id")
        .unwrap()
        .u32()
        .unwrap()
        .iter()
        .flatten()
        .collect();
    samples.dedup();
    assert_eq!(samples.len(), 3);

    let out = run(&set("0"), &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        !causes.exists(),
        "an earlier causes.parquet was left behind"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!stdout.contains("re-run with each effect"), "{stdout}");

    let out = run(&set("5000"), &[]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("summary.counterfactual_runs"), "{stderr}");
}

/// Each counterfactual applies where its effect is on, and after it is
/// removed no longer does, the others untouched; removing the couple keeps
/// the rotor's static unbalance and leaves no moment about its centre of mass.
#[test]
fn each_counterfactual_removes_its_effect_and_only_it() {
    use autobal::model::rotor::RotorModel;
    use autobal::scene_file::SceneFile;
    use autobal::simulation::counterfactual::Counterfactual;
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two_support_long.toml"),
    )
    .unwrap();
    let text = format!(
        "{text}\n[effects.race_eccentricity]\noffset = 1e-6\n\n[effects.rolling_resistance]\ncoefficient = 1e-4\n\n[effects.gravity]\naxis_inclination_deg = 0.0\n"
    );
    let file = SceneFile::parse(&text, "s.toml").unwrap_or_else(|e| panic!("{e}"));
    let run = file.simulation("s.toml").unwrap();
    let static_part = |r: &RotorModel| {
        let RotorModel::TwoSupport(r) = r else {
            panic!("two supports")
        };
        let mut s = (
            r.static_unbalance * r.static_angle.cos(),
            r.static_unbalance * r.static_angle.sin(),
        );
        for u in &r.unbalances {
            s = (s.0 + u.s * u.angle.cos(), s.1 + u.s * u.angle.sin());
        }
        s
    };
    for c in Counterfactual::ALL {
        let expected = c != Counterfactual::SpeedHeld;
        assert_eq!(c.applies(&run), expected, "{c:?}");
        let mut without = run.clone();
        c.remove(&mut without);
        assert!(
            !c.applies(&without),
            "{c:?} still applies after its removal"
        );
        for other in Counterfactual::ALL.into_iter().filter(|&o| o != c) {
            assert_eq!(
                other.applies(&without),
                other.applies(&run),
                "{c:?} touched {other:?}"
            );
        }
        if c == Counterfactual::Couple {
            let (a, b) = (
                static_part(&run.scene.rotor),
                static_part(&without.scene.rotor),
            );
            assert!(
                (a.0 - b.0).abs() < 1e-15 && (a.1 - b.1).abs() < 1e-15,
                "{a:?} {b:?}"
            );
        }
    }
}

/// With rolling resistance's coefficient uncertain, each run's dead band is
/// its own drawn μ_s·l: the runs that did not settle are classed against
/// it (`unsettled_floor`), not against the nominal μ's.
#[test]
fn an_uncertain_friction_is_classed_per_run_by_its_drawn_dead_band() {
    let tmp = tempfile::tempdir().unwrap();
    let study = grinder(
        tmp.path(),
        "\n[summary]\ncounterfactual_runs = 0\n\n[uncertain]\n\"effects.rolling_resistance.coefficient\" = { distribution = \"log_uniform\", min = 1e-5, max = 2e-4 }\n",
    );
    // Only the dead band may reach the bands: the race is made true, and
    // the balls stick where they stop (no creep).
    let text = std::fs::read_to_string(&study)
        .unwrap()
        .replace("offset = 1e-6", "offset = 0.0")
        .replace("slip_rate = 1e-3", "");
    std::fs::write(&study, text).unwrap();
    let out = run(&study, &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let folder = tmp.path().join("bench_grinder");
    let runs = read_parquet(&folder.join("runs.parquet")).unwrap();
    let outcome = strings(&runs, "outcome");
    let mu = runs
        .column("scene.effects.rolling_resistance.coefficient")
        .unwrap()
        .f64()
        .unwrap()
        .clone();
    let a_refs = runs.column("plane_a_ref").unwrap().list().unwrap().clone();
    // Track radius 31.5 mm, static ratio 1, δ = 0.05: count per plane.
    let (track, delta, nominal) = (0.0315, 0.05, 5e-5);
    let reached = |plane: usize, own: bool| {
        (0..runs.height())
            .filter(|&i| outcome[i] == "censored" || outcome[i] == "not_settled")
            .filter(|&i| {
                let a = a_refs.get_as_series(i).unwrap();
                let a = a.f64().unwrap().get(plane).unwrap();
                let mu = if own { mu.get(i).unwrap() } else { nominal };
                mu * track >= delta * a
            })
            .count()
    };
    let own = reached(0, true).max(reached(1, true));
    let unsettled = outcome
        .iter()
        .filter(|o| *o == "censored" || *o == "not_settled")
        .count();
    let summary = read_parquet(&folder.join("summary.parquet")).unwrap();
    let floor = strings(&summary, "unsettled_floor").remove(0);
    assert!(own > 0 && 2 * own >= unsettled, "own {own} of {unsettled}");
    assert!(
        floor.starts_with(&format!(
            "{own} of the {unsettled} runs that did not settle"
        )) && floor.contains("each run's own, from its drawn μ"),
        "{floor} (own {own}, nominal {})",
        reached(0, false)
    );
}
