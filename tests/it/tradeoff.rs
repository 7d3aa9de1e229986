//! `study tradeoff`: every setting measured on the same runs against the reference.

use crate::fixtures::SI_SCENE;
use autobal::model::effect::contact::ContactModel;
use autobal::simulation::Fidelity;
use autobal::study::plan::config::StudyFile;
use autobal::tradeoff::{measure, recommend, rows_frame, settings, spread_runs, summarize};

/// The designs of both studies here, up to their drag.
const THREE_BALLS: &str = r#"
[designs]
kind = "ball"
n = 3
rho = "optimal"
race_radius = 0.05
"#;

#[test]
fn tradeoff_measures_every_setting_and_recommends_within_budget() {
    let text = &[
        SI_SCENE,
        THREE_BALLS,
        r#"drag = [2.0, 10.0]
[sampling]
samples = 2
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
    let runs = spread_runs(&plan, 4);
    let rows = measure(&plan, &runs);
    assert_eq!(rows.len(), runs.len() * all.len());
    let summary = summarize(&rows);
    // The other contact model is measured too (these balls touch): penalty
    // contact in the rotating frame, at the study's tolerance and at 1e-10.
    let penalty: Vec<_> = summary
        .iter()
        .filter(|s| s.setting.contact == Some(ContactModel::Penalty))
        .collect();
    assert_eq!(penalty.len(), 2);
    assert!(
        penalty
            .iter()
            .all(|s| s.setting.fidelity == Fidelity::Rotating
                && s.setting.label().ends_with("/penalty contact")
                && s.setting.keys().contains("model = \"penalty\""))
    );
    // Against the rigid reference it differs by the model (the penalty
    // contact rebounds, rigid contact's impacts are dead), not by the
    // integration, so it agrees on the outcomes but not to a fraction of a
    // revolution.
    for s in &penalty {
        assert_eq!(s.outcome_agreement, 1.0, "{}", s.setting.label());
    }
    // The tightest integrations of the study's own model agree with the
    // reference to a fraction of a revolution.
    for s in summary
        .iter()
        .filter(|s| s.setting.rtol == 1e-10 && s.setting.contact.is_none())
    {
        assert!(
            s.max_error_revs.unwrap() < 0.1,
            "{}: {:?}",
            s.setting.label(),
            s.max_error_revs
        );
        assert_eq!(s.outcome_agreement, 1.0);
    }
    // The decision: each setting ranks the two designs by their runs, and
    // the tightest integrations rank them as the reference does.
    for s in &summary {
        assert_eq!(s.designs_ranked, 2, "{}", s.setting.label());
    }
    for s in summary
        .iter()
        .filter(|s| s.setting.rtol == 1e-10 && s.setting.contact.is_none())
    {
        assert_eq!(s.same_best, Some(true), "{}", s.setting.label());
        assert_eq!(s.kendall_tau, Some(1.0), "{}", s.setting.label());
    }
    // Recomputed from the rows: the reference's #1 is the design with the
    // smaller mean settling time, censored at the horizon.
    let mean_of = |design: u32, reference: bool| {
        let v: Vec<f64> = rows
            .iter()
            .filter(|r| r.design_id == design && r.setting == summary[0].setting)
            .map(|r| {
                let t = if reference {
                    r.reference_settling_revs
                } else {
                    r.settling_revs
                };
                t.map_or(r.horizon_revs, |t| t.min(r.horizon_revs))
            })
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let analytic_same =
        (mean_of(0, false) < mean_of(1, false)) == (mean_of(0, true) < mean_of(1, true));
    assert_eq!(
        summary[0].same_best,
        Some(analytic_same),
        "{}",
        summary[0].setting.label()
    );
    let best = recommend(&summary, 1.0, 0.01).expect("some setting meets 1 rev");
    assert_ne!(best.same_best, Some(false));
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

/// Where runs may return from Radau5, the sweep measures the same runs kept
/// on Radau5 at the study's tolerance, named by the key that selects it; a
/// study that already keeps them gets no such setting.
#[test]
fn the_sweep_measures_runs_kept_on_radau5_beside_the_return() {
    let study = |solver: &str| {
        let text = [
            SI_SCENE,
            THREE_BALLS,
            r#"drag = 2.0
[sampling]
samples = 1
unbalance = { distribution = "uniform", min = 0.2, max = 0.8, relative_to = "capacity" }
"#,
            solver,
        ]
        .concat();
        StudyFile::parse(&text, "t.toml")
            .unwrap()
            .plan(&text, "t.toml")
            .unwrap()
    };
    let all = settings(&study("[solver]\nrtol = 1e-7\n"));
    let kept: Vec<_> = all.iter().filter(|s| !s.return_when_dearer).collect();
    assert_eq!(kept.len(), 1, "{all:?}");
    assert_eq!(kept[0].fidelity, Fidelity::Full);
    assert_eq!(kept[0].rtol, 1e-7);
    assert_eq!(kept[0].label(), "full/dp5/1e-7/kept on radau5");
    assert!(
        kept[0].keys().ends_with("return_when_dearer = false"),
        "{}",
        kept[0].keys()
    );
    let none = settings(&study("[solver]\nreturn_when_dearer = false\n"));
    assert!(none.iter().all(|s| s.return_when_dearer), "{none:?}");
}
