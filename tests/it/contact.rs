//! Weights are solid by default: on every shipped study, as shipped (contact
//! on unless the study says otherwise), no two weights overlap by more than
//! 2 % of their touching angle 2α during any run, and none overlaps at the
//! end. Without contact the same runs do overlap, which is the bug this
//! default fixes.

use autobal::model::gap::GapGauge;
use autobal::study::config::{StudyFile, StudyPlan};
use autobal::study::run::run_one;
use std::path::PathBuf;

/// Samples per design: enough to meet the packed and clustered cases.
const SAMPLES: u32 = 4;

fn plan(name: &str, samples: u32, contact: Option<bool>) -> StudyPlan {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("studies")
        .join(name);
    let text = std::fs::read_to_string(&path).expect("study file");
    let text: String = text
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("samples =") {
                format!("samples = {samples}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let mut plan = StudyFile::parse(&text, name)
        .and_then(|f| f.plan(&text, name))
        .expect("shipped study");
    if let Some(on) = contact {
        let spec = plan
            .file
            .scene
            .effects
            .contact
            .get_or_insert_with(Default::default);
        spec.enabled = on;
    }
    plan
}

/// Largest overlap over the runs as a fraction of the pair's touching angle,
/// and the number of runs that end overlapped by more than that tolerance.
fn worst_overlap(plan: &StudyPlan) -> (f64, usize, usize) {
    let samples = u64::from(plan.file.sampling.samples);
    let (mut worst, mut ended_overlapped, mut runs) = (0.0_f64, 0, 0);
    for id in 0..plan.total_runs() {
        let record = run_one(plan, id);
        let design = &plan.designs[(id / samples) as usize];
        let scene = plan.scene(design, record.unbalance, record.direction_deg.to_radians());
        let Some(gauge) = GapGauge::new(&scene.cargoes().expect("cargoes")) else {
            continue;
        };
        let scale = gauge.contact_angle();
        let (Some(min_gap), Some(final_gap)) =
            (record.metrics.min_gap_rad, record.metrics.final_min_gap_rad)
        else {
            panic!("run {id} of sized weights has no gap: {:?}", record.metrics);
        };
        runs += 1;
        worst = worst.max(-min_gap / scale);
        if -final_gap / scale > 0.02 {
            ended_overlapped += 1;
        }
    }
    (worst, ended_overlapped, runs)
}

/// Every study shipped in studies/.
const STUDIES: [&str; 9] = [
    "three_balls.toml",
    "five_rollers.toml",
    "balls_vs_rollers.toml",
    "gravity_horizontal.toml",
    "runup.toml",
    "regression.toml",
    "paper_claims.toml",
    "optimize_settling.toml",
    "optimize_capacity.toml",
];

#[test]
fn shipped_studies_keep_their_weights_solid() {
    for name in STUDIES {
        let (worst, ended, runs) = worst_overlap(&plan(name, SAMPLES, None));
        assert!(runs > 0, "{name}: no run with sized weights");
        assert!(
            worst <= 0.02,
            "{name}: weights overlapped by {:.2} % of 2α",
            100.0 * worst
        );
        assert_eq!(ended, 0, "{name}");
    }
}

#[test]
fn without_contact_the_main_job_lets_weights_pass_through_each_other() {
    let (worst, ended, runs) = worst_overlap(&plan("three_balls.toml", 2, Some(false)));
    assert!(runs > 0);
    assert!(worst > 0.5, "largest overlap only {:.2} of 2α", worst);
    assert!(ended > 0, "no run ended overlapped");
}

/// The cost and effect of contact on every shipped study, as the table in
/// docs/model.md: `cargo test --release --test it contact_cost_table -- --ignored --nocapture`
/// (or without --release: the ratios are the same).
#[test]
#[ignore]
fn contact_cost_table() {
    use autobal::stats::quantile::median;
    println!(
        "| study | runs | contact | runs/s | settled | median t_s (rev) | median residual (A_ref) | worst overlap (2α) |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    for name in STUDIES {
        for on in [false, true] {
            let p = plan(name, 20, Some(on));
            let clock = std::time::Instant::now();
            let runs: Vec<_> = (0..p.total_runs()).map(|id| run_one(&p, id)).collect();
            let rate = runs.len() as f64 / clock.elapsed().as_secs_f64();
            // Every run counts: one that did not settle is later than any
            // that did (the Kaplan–Meier median under censoring at the horizon).
            let times: Vec<f64> = runs
                .iter()
                .map(|r| r.metrics.settling_revs.unwrap_or(f64::INFINITY))
                .collect();
            let settled = times.iter().filter(|t| t.is_finite()).count();
            let residual: Vec<f64> = runs.iter().map(|r| r.metrics.residual_rel).collect();
            let (worst, _, _) = worst_overlap(&p);
            println!(
                "| {name} | {} | {} | {rate:.0} | {:.1} % | {} | {:.4} | {:.1} % |",
                runs.len(),
                if on { "on" } else { "off" },
                100.0 * settled as f64 / runs.len() as f64,
                median(&times)
                    .filter(|m| m.is_finite())
                    .map_or("beyond the run".into(), |m| format!("{m:.1}")),
                median(&residual).unwrap_or(f64::NAN),
                100.0 * worst,
            );
        }
    }
}

/// Sampled starts never place two weights closer than their touching angle,
/// whatever the start rule: the clustered start presses them to touching,
/// the uniform one spaces them without overlap, the even one is a regular
/// polygon, and a balanced fan that would need steps below 2α falls back to
/// the pressed cluster.
#[test]
fn sampled_starts_never_overlap() {
    use autobal::model::gap::start_clash;
    use autobal::study::config::InitialSpec;
    use autobal::study::sample::draw_sample;
    for name in STUDIES {
        for initial in [
            InitialSpec::Clustered,
            InitialSpec::Uniform,
            InitialSpec::Even,
            InitialSpec::BalancedForShift(90.0),
            InitialSpec::BalancedForShift(10.0),
        ] {
            let mut p = plan(name, 6, None);
            p.file.sampling.initial = initial.clone();
            for design in &p.designs {
                for sample in 0..6 {
                    let s = draw_sample(&p, design, sample);
                    let scene = p.scene(design, s.unbalance, s.direction);
                    let cargo = scene.cargoes().expect("cargoes");
                    assert_eq!(
                        start_clash(&cargo, &s.initial_angles),
                        None,
                        "{name}, {initial:?}, design {}, sample {sample}: {:?}",
                        design.id,
                        s.initial_angles
                    );
                }
            }
        }
    }
}

fn simulate_scene(text: &str) -> std::process::Output {
    crate::fixtures::simulate_text(text)
}

fn point_scene() -> String {
    crate::fixtures::point_weights_scene(2) + "[speed]\nmode = \"constant\"\nomega = 4.0\n"
}

#[test]
fn coincident_point_weights_are_refused_naming_the_key_and_the_weights() {
    let out = simulate_scene(&format!(
        "{}[start]\nangles_deg = [30, 30]\n",
        point_scene()
    ));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("start.angles_deg"), "{err}");
    assert!(err.contains("weights 1 and 2"), "{err}");
    // A start apart is fine.
    let ok = simulate_scene(&format!(
        "{}[start]\nangles_deg = [30, 31]\n",
        point_scene()
    ));
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}

#[test]
fn overlapping_solid_weights_are_refused_with_their_touching_angle() {
    let scene = r#"
[rotor]
mass = 10.0
eccentricity = 0.001
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[balancer]
kind = "ball"
n = 3
rho = 0.3
race_radius = 0.05
density = 7850.0
drag = 5.0
[speed]
mode = "constant"
omega = 300.0
[start]
angles_deg = [0, 20, 200]
"#;
    let out = simulate_scene(scene);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("start.angles_deg"), "{err}");
    assert!(err.contains("weights 1 and 2"), "{err}");
    // 2α = 2 asin(0.3/0.7) = 50.754°.
    assert!(err.contains("2α = 50.754°"), "{err}");
}
