//! The claims experiment end to end on a tiny configuration.

use crate::fixtures::SI_SCENE;
use autobal::claims::normalisation::{Normalisation, design_capacity, rho_for};
use autobal::claims::{report::render, run_claims};
use autobal::model::balancer::Kind;
use autobal::study::plan::config::StudyFile;
use autobal::study::run::NoProgress;

#[test]
fn normalisations_hold_what_they_promise() {
    let text = &[
        SI_SCENE,
        r#"
[designs]
kind = "ball"
n = [2, 3, 4, 5]
rho = "optimal"
race_radius = 0.05
drag = 10.0
[sampling]
samples = 1
unbalance = { distribution = "fixed", value = 0.5, relative_to = "capacity" }
"#,
    ]
    .concat();
    let file = StudyFile::parse(text, "n.toml").unwrap();
    let g = &file.designs;
    let ns = [2, 3, 4, 5];
    let mass = |n: u32, rho: f64| f64::from(n) * rho.powi(3);
    let r3 = rho_for(Normalisation::Paper, g, Kind::Ball, 3, &ns).unwrap();
    let caps: Vec<f64> = ns
        .iter()
        .map(|&n| {
            design_capacity(
                g,
                Kind::Ball,
                n,
                rho_for(Normalisation::EqualCapacity, g, Kind::Ball, n, &ns).unwrap(),
            )
            .unwrap()
        })
        .collect();
    for &n in &ns {
        let rm = rho_for(Normalisation::EqualMass, g, Kind::Ball, n, &ns).unwrap();
        assert!(
            (mass(n, rm) / mass(3, r3) - 1.0).abs() < 1e-12,
            "equal mass n={n}"
        );
    }
    for c in &caps {
        assert!((c / caps[0] - 1.0).abs() < 1e-9, "equal capacity {caps:?}");
    }
}

#[test]
fn tiny_claims_run_reports_every_claim() {
    let tmp = tempfile::tempdir().unwrap();
    let text = format!(
        r#"
name = "claims"
output = "{}"
[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[scene.speed]
mode = "constant"
omega = 300.0
[scene.effects.contact]
[designs]
kind = "ball"
n = [2, 3]
rho = "optimal"
race_radius = 0.05
drag = 10.0
[sampling]
samples = 6
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.8, relative_to = "capacity" }}
[metrics]
t_end_revs = 300
"#,
        tmp.path().display()
    );
    let plan = StudyFile::parse(&text, "claims.toml")
        .unwrap()
        .plan(&text, "claims.toml")
        .unwrap();
    let out = run_claims(&plan, &NoProgress).unwrap();
    // Claim 1: pressed weights deliver eq 5's capacity at every scanned radius.
    assert!(!out.capacity.is_empty());
    for p in &out.capacity {
        let peak = out
            .capacity
            .iter()
            .filter(|q| q.n == p.n)
            .map(|q| q.analytic)
            .fold(0.0, f64::max);
        assert!((p.simulated - p.analytic).abs() < 0.02 * peak, "{p:?}");
    }
    // Claims 2 and 3: every normalisation × n was run.
    assert_eq!(out.shift.len(), 3 * 2);
    assert_eq!(out.fastest.len(), 3 * 2);
    let report = render(&plan, &out, "study claims claims.toml");
    for heading in [
        "## Claim 1",
        "## Claim 2",
        "## Claim 3",
        "### paper",
        "### equal_mass",
        "### equal_capacity",
        "**Verdict.**",
    ] {
        assert!(report.contains(heading), "missing {heading}");
    }
    // Every claim-3 verdict names the measure it rests on, lists the others,
    // and states the one Holm family over the whole claim.
    let claim3 = &report[report.find("## Claim 3").unwrap()..report.find("## Notes").unwrap()];
    let verdicts: Vec<&str> = claim3.lines().filter(|l| l.starts_with("- ")).collect();
    assert!(!verdicts.is_empty(), "{claim3}");
    for v in verdicts {
        assert!(v.contains(" on the restricted mean settling time"), "{v}");
        for measure in [
            "median settling time",
            "p90 settling time",
            "p95 residual/A_ref",
        ] {
            assert!(v.contains(measure), "{measure} missing in {v}");
        }
        assert!(v.contains("every kind and normalisation together"), "{v}");
    }
    // Claim 2: one Holm family over the normalisations.
    assert!(
        report.contains("Holm over the 3 normalisations answering claim 2"),
        "{report}"
    );
    // --rank-by median switches the measure the verdicts rest on.
    let mut by_median = plan.clone();
    by_median.file.summary.rank_by = autobal::study::plan::criterion::Criterion::Median;
    let report = render(
        &by_median,
        &out,
        "study claims claims.toml --rank-by median",
    );
    assert!(report.contains("on the median settling time"), "{report}");
    assert!(
        tmp.path()
            .join("claims")
            .join("fastest_paper")
            .join("summary.parquet")
            .exists()
    );
}
