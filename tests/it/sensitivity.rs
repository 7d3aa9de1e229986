//! `study sensitivity`: Sobol indices of a study's measures over its
//! sampled inputs, by pick-freeze runs of the study's own streams.

use autobal::study::config::{StudyFile, StudyPlan};
use autobal::study::run::run_one;
use autobal::study::sensitivity::{
    Measure, SensitivityRow, SensitivitySettings, estimate, inputs, run_pick_freeze,
};
use autobal::study::stream::Sequence;

/// Two- and three-ball designs on the main job's rotor, with the rotor's
/// inertia (unused at constant speed) and its damping uncertain.
fn plan(sequence: &str) -> StudyPlan {
    let text = format!(
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
    );
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

/// The study's inputs, in order: its own streams, then its uncertain keys.
#[test]
fn the_inputs_are_the_studys_streams_and_keys() {
    let names: Vec<String> = inputs(&plan("sobol")).into_iter().map(|i| i.name).collect();
    assert_eq!(
        names,
        [
            "unbalance (size, direction)",
            "start angles",
            "rotor.bx",
            "rotor.inertia"
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
