//! `study tradeoff`: every setting measured on the same runs against the reference.

use crate::fixtures::SI_SCENE;
use autobal::simulation::Fidelity;
use autobal::study::config::StudyFile;
use autobal::tradeoff::{measure, recommend, rows_frame, settings, spread_runs, summarize};

#[test]
fn tradeoff_measures_every_setting_and_recommends_within_budget() {
    let text = &[
        SI_SCENE,
        r#"
[designs]
kind = "ball"
n = 3
rho = "optimal"
race_radius = 0.05
drag = 10.0
[sampling]
samples = 4
unbalance = { distribution = "uniform", min = 0.2, max = 0.8, relative_to = "capacity" }
[metrics]
t_end_revs = 300
"#,
    ]
    .concat();
    let plan = StudyFile::parse(text, "t.toml")
        .unwrap()
        .plan(text, "t.toml")
        .unwrap();
    let all = settings(&plan);
    // Isotropic and constant speed: both frames are swept, plus the two estimates.
    assert!(all.iter().any(|s| s.fidelity == Fidelity::Rotating));
    assert!(all.iter().any(|s| s.fidelity == Fidelity::Linear));
    let runs = spread_runs(&plan, 2);
    let rows = measure(&plan, &runs);
    assert_eq!(rows.len(), runs.len() * all.len());
    let summary = summarize(&rows);
    // The tightest integrations agree with the reference to a fraction of a revolution.
    for s in summary.iter().filter(|s| s.setting.rtol == 1e-10) {
        assert!(
            s.max_error_revs.unwrap() < 0.1,
            "{}: {:?}",
            s.setting.label(),
            s.max_error_revs
        );
        assert_eq!(s.outcome_agreement, 1.0);
    }
    let best = recommend(&summary, 1.0, 0.01).expect("some setting meets 1 rev");
    assert!(best.max_error_revs.unwrap() <= 1.0 && best.outcome_agreement == 1.0);
    let df = rows_frame(&rows).unwrap();
    for c in [
        "fidelity",
        "rtol",
        "settling_error_revs",
        "rhs_calls",
        "wall_time_s",
    ] {
        assert!(df.column(c).is_ok(), "{c}");
    }
}
