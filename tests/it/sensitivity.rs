//! `study sensitivity`: Sobol indices of a study's measures over its
//! sampled inputs, by pick-freeze runs of the study's own streams.

use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::plan::stream::Sequence;
use autobal::study::run::run_one;
use autobal::study::sensitivity::{
    InputKind, Measure, SensitivityRow, SensitivitySettings, estimate, inputs, run_pick_freeze,
};

/// Two- and three-ball designs on the main job's rotor, with the rotor's
/// inertia (unused at constant speed) and its damping uncertain.
fn text(sequence: &str) -> String {
    format!(
        r#"
name = "sens"
seed = 5
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
samples = 64
sequence = "{sequence}"
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.9, relative_to = "capacity" }}
[metrics]
t_end_revs = 300
hold_revs = 20
[uncertain]
"rotor.inertia" = {{ distribution = "uniform", min = 0.01, max = 0.5 }}
"rotor.bx" = {{ distribution = "log_uniform", min = 30, max = 300 }}
"#
    )
}

fn plan(sequence: &str) -> StudyPlan {
    let text = text(sequence);
    StudyFile::parse(&text, "sens.toml")
        .unwrap()
        .plan(&text, "sens.toml")
        .unwrap()
}

fn settings(threads: usize) -> SensitivitySettings {
    SensitivitySettings {
        rows: 64,
        sequence: Sequence::Sobol,
        threads: Some(threads),
    }
}

fn index<'a>(
    rows: &'a [SensitivityRow],
    design: u32,
    m: Measure,
    input: &str,
) -> &'a SensitivityRow {
    rows.iter()
        .find(|r| r.design_id == design && r.measure == m && r.input == input)
        .unwrap()
}

/// The study's inputs, in order: its own streams (sampled operating
/// conditions), then its uncertain keys (the machine unknowns).
#[test]
fn the_inputs_are_the_studys_streams_and_keys() {
    let found: Vec<(String, InputKind)> = inputs(&plan("sobol"))
        .into_iter()
        .map(|i| (i.name, i.kind))
        .collect();
    let condition = InputKind::OperatingCondition;
    let unknown = InputKind::MachineUnknown;
    assert_eq!(
        found,
        [
            ("unbalance (size, direction)".to_string(), condition),
            ("start angles".to_string(), condition),
            ("rotor.bx".to_string(), unknown),
            ("rotor.inertia".to_string(), unknown)
        ]
    );
}

/// Matrix A is the study itself: its runs are `study run`'s, bit for bit;
/// the indices do not depend on the thread count; the rotor's inertia,
/// which no equation uses at constant speed, gets a total index below 0.02
/// with an interval reaching down to 0, and a first-order interval
/// covering 0, on every measure that varies; the unbalance, which sets
/// the settling, has a clearly larger total index.
#[test]
fn a_dummy_input_gets_no_index_and_the_unbalance_does() {
    let p = plan("sobol");
    let one = run_pick_freeze(&p, &settings(1), &|_| {});
    let two = run_pick_freeze(&p, &settings(2), &|_| {});
    let rows = 64u64;
    for sample in [0, 5, 63] {
        let own = run_one(&p, sample);
        assert_eq!(one[sample as usize].metrics, own.metrics);
    }
    let first = estimate(&p, &settings(1), &one);
    assert_eq!(first, estimate(&p, &settings(2), &two));
    assert_eq!(one.len() as u64, 2 * rows * 6);
    for design in [0, 1] {
        for m in [Measure::RestrictedSettling, Measure::Residual] {
            let dummy = index(&first, design, m, "rotor.inertia");
            let i = dummy.index.as_ref().expect("the measure varies");
            assert!(i.total < 0.02 && i.total_ci.0 < 1e-6, "{m:?} {i:?}");
            assert!(i.first_ci.0 <= 0.0 && 0.0 <= i.first_ci.1, "{m:?} {i:?}");
        }
        let unbalance = index(
            &first,
            design,
            Measure::RestrictedSettling,
            "unbalance (size, direction)",
        );
        let u = unbalance.index.as_ref().unwrap();
        assert!(u.total_ci.0 > 0.3, "{u:?}");
    }
}

/// A study whose #1 loses where an uncertain key is low says so: design 0
/// settles in 10 rev where the damping is in its lowest third and in 200
/// rev elsewhere, design 1 in 60 rev everywhere; #1 overall is design 1,
/// best in two of the three thirds, and design 0 wins the lowest.
#[test]
fn robustness_names_the_third_where_the_decision_turns() {
    use autobal::decide::robustness::robustness;
    use autobal::metrics::Outcome;
    use autobal::uncertain::UncertainValue;
    let p = plan("random");
    let mut runs = Vec::new();
    for design in 0..2u32 {
        for sample in 0..60u32 {
            let bx = 30.0 + 270.0 * (f64::from(sample) + 0.5) / 60.0;
            let revs = match (design, bx < 120.0) {
                (0, true) => 10.0,
                (0, false) => 200.0,
                _ => 60.0,
            };
            let id = u64::from(design * 60 + sample);
            let mut r = crate::study_summary::record(id, Outcome::Settled, Some(revs), 0.01);
            r.design_id = design;
            r.sample_id = sample;
            r.metrics.censoring_revs = Some(280.0);
            r.uncertain = ["rotor.bx", "rotor.inertia"]
                .map(|key| UncertainValue {
                    key: key.into(),
                    value: if key == "rotor.bx" { bx } else { 0.1 },
                })
                .to_vec();
            runs.push(r);
        }
    }
    let df = autobal::study::results::record::to_dataframe(&runs).unwrap();
    let r = robustness(&p, &df, 1).unwrap().unwrap();
    let bx: Vec<_> = r.parts.iter().filter(|p| p.key == "rotor.bx").collect();
    assert_eq!(bx.iter().map(|p| p.winner).collect::<Vec<_>>(), [0, 1, 1]);
    assert_eq!(bx[0].winner_value, Some(10.0));
    assert_eq!(bx[0].crown_value, Some(60.0));
    assert!(bx[0].range.1 < 120.0 && bx[1].range.0 >= 120.0, "{bx:?}");
    // A key that did not vary cuts nothing and is not counted.
    assert!(r.parts.iter().all(|p| p.key == "rotor.bx"));
    // Design 0's 10 rev against #1's 60 on all 20 paired samples: a finding
    // at any α, Holm-adjusted over the three thirds' tests.
    let turns = r.turns();
    assert_eq!(turns.len(), 1);
    assert_eq!((turns[0].0.part, turns[0].1.design), (0, 0));
    assert!(turns[0].1.p_holm < 1e-4 && r.third_tests() == 3, "{r:?}");
    // The damping explains design 1's settling not at all (it is constant).
    assert!(
        r.explained
            .iter()
            .all(|e| e.share == 0.0 && e.p_value == 1.0)
    );
    assert!(r.credited().is_none());
}

/// From the command line: the cost first, sensitivity.parquet written into
/// the study's folder (never replaced without --overwrite), rows that are
/// not a power of two and unknown designs refused with exit 2.
#[test]
fn the_cli_writes_the_indices_and_refuses_bad_flags() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let study = text("sobol").replace(
        "seed = 5",
        &format!("seed = 5\noutput = \"{}\"", dir.path().display()),
    );
    let file = dir.path().join("sens.toml");
    std::fs::write(&file, study).unwrap();
    let study = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_study"))
            .arg("sensitivity")
            .arg(&file)
            .args(args)
            .output()
            .unwrap()
    };
    for bad in [&["--rows", "12"][..], &["--designs", "7"][..]] {
        let out = study(bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(bad[0]),
            "{bad:?}"
        );
    }
    assert!(!dir.path().join("sens").exists());
    let out = study(&["--rows", "8", "--designs", "1"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("cost: N·(k + 2) = 8·(4 + 2) = 48 runs per design"),
        "{stderr}"
    );
    let written = dir.path().join("sens/sensitivity.parquet");
    let df = autobal::study::results::io::read_parquet(&written).unwrap();
    assert_eq!(df.height(), 3 * 4);
    let (input, kind) = (
        df.column("input").unwrap().str().unwrap().clone(),
        df.column("input_kind").unwrap().str().unwrap().clone(),
    );
    let kinds: Vec<(String, String)> = (0..df.height())
        .map(|i| {
            let text = |c: &polars::prelude::StringChunked| c.get(i).unwrap().to_string();
            (text(&input), text(&kind))
        })
        .collect();
    for (input, kind) in &kinds {
        let unknown = input.starts_with("rotor.");
        assert_eq!(kind == "machine_unknown", unknown, "{input}: {kind}");
        assert!(unknown || kind == "operating_condition", "{input}: {kind}");
    }
    assert_eq!(
        study(&["--rows", "8", "--designs", "1"]).status.code(),
        Some(2)
    );
}

/// The headline of `study sensitivity` names the largest total index among
/// the uncertain keys, the machine unknowns, and reports the unbalance and
/// the start apart as sampled operating conditions, however large their
/// index; `study report` on the same folder, which then has
/// sensitivity.parquet, words it the same way.
#[test]
fn the_headline_names_a_machine_unknown_and_the_conditions_apart() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let study = text("sobol")
        .replace(
            "seed = 5",
            &format!("seed = 5\noutput = \"{}\"", dir.path().display()),
        )
        .replace("samples = 64", "samples = 16");
    let file = dir.path().join("sens.toml");
    std::fs::write(&file, study).unwrap();
    let cli = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {stderr}");
        String::from_utf8(out.stdout).unwrap()
    };
    let file = file.to_str().unwrap();
    cli(&["run", file, "--quiet"]);
    let text = cli(&["sensitivity", file, "--rows", "8"]);
    // Design 1's headline, with its wrapped continuation lines.
    let from = text
        .find("largest total index on design 1")
        .expect("headline");
    let line = text[from..]
        .lines()
        .enumerate()
        .take_while(|(i, l)| *i == 0 || l.starts_with(' '))
        .map(|(_, l)| l.trim())
        .collect::<Vec<_>>()
        .join(" ");
    assert!(
        line.starts_with("largest total index on design 1's settling time among the machine unknowns ([uncertain] keys): rotor."),
        "{text}"
    );
    let apart = "operating conditions (sampled, not machine unknowns): ";
    let after = &line[line.find(apart).expect(apart) + apart.len()..];
    assert!(
        after.contains("unbalance (size, direction) S_T = ")
            && after.contains("start angles S_T = "),
        "{line}"
    );
    assert!(!after.contains("rotor."), "{line}");
    let folder = dir.path().join("sens");
    let page = dir.path().join("report.html");
    cli(&[
        "report",
        folder.to_str().unwrap(),
        "--out",
        page.to_str().unwrap(),
    ]);
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains("of the uncertain keys, rotor.")
            && html.contains("has the largest total index on #1")
            && html.contains(apart),
        "the report's robustness findings"
    );
}
