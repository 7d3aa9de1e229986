//! Weights are solid by default: on every shipped study, as shipped (contact
//! on unless the study says otherwise), no two weights overlap by more than
//! 2 % of their touching angle 2α during any run, and none overlaps at the
//! end. Without contact the same runs do overlap, which is the bug this
//! default fixes.

use crate::contact_gauge::{STUDIES, plan, worst_overlap};

/// Samples per design: enough to meet the packed and clustered cases.
const SAMPLES: u32 = 4;

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

/// Sampled starts never place two weights closer than their touching angle,
/// whatever the start rule: the clustered start presses them to touching,
/// the uniform one spaces them without overlap, the even one is a regular
/// polygon, and a balanced fan that would need steps below 2α falls back to
/// the pressed cluster.
#[test]
fn sampled_starts_never_overlap() {
    use autobal::model::gap::start_clash;
    use autobal::study::plan::config::InitialSpec;
    use autobal::study::plan::sample::draw_sample;
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
