//! Settings that cannot take effect are refused up front, naming both keys
//! (exit 2, nothing written): a contact parameter of the other model,
//! contact switched off and made rigid at once, rigid contact for point
//! masses, a Sobol sequence over a number of samples that is not a power
//! of two, a design compared with itself.

use crate::fixtures::simulate_text;
use std::path::Path;
use std::process::Command;

/// Three steel balls on a soft rotor, with an `[effects.contact]` table of
/// `contact`; 60 revolutions.
fn scene_with_contact(contact: &str) -> String {
    format!(
        r#"[rotor]
mass = 8.0
kx = 14000.0
ky = 14000.0
bx = 33.5
by = 33.5
eccentricity = 1.25e-5
[balancer]
kind = "ball"
n = 3
rho = 0.3
race_radius = 0.025
density = 7850.0
drag = 0.5
[speed]
mode = "constant"
omega = 125.66
[metrics]
t_end_revs = 60
hold_revs = 10
[effects.contact]
{contact}
"#
    )
}

fn refused(out: &std::process::Output, keys: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for key in keys {
        assert!(stderr.contains(key), "{key} not named: {stderr}");
    }
}

#[test]
fn restitution_with_penalty_contact_is_refused_naming_both_keys() {
    let out = simulate_text(&scene_with_contact(
        "model = \"penalty\"\nrestitution = 0.5",
    ));
    refused(
        &out,
        &["effects.contact.restitution", "effects.contact.model"],
    );
    // With rigid contact, the default, it is the impact's rebound: accepted.
    for contact in ["restitution = 0.5", "model = \"rigid\"\nrestitution = 0.5"] {
        let ok = simulate_text(&scene_with_contact(contact));
        assert!(
            ok.status.success(),
            "{contact}: {}",
            String::from_utf8_lossy(&ok.stderr)
        );
    }
}

#[test]
fn a_penalty_springs_keys_with_rigid_contact_are_refused_naming_both_keys() {
    for (contact, key, default) in [
        (
            "frequency_ratio = 50",
            "effects.contact.frequency_ratio",
            true,
        ),
        ("damping_ratio = 0.5", "effects.contact.damping_ratio", true),
        (
            "model = \"rigid\"\nfrequency_ratio = 50",
            "effects.contact.frequency_ratio",
            false,
        ),
    ] {
        let out = simulate_text(&scene_with_contact(contact));
        refused(
            &out,
            &[key, "effects.contact.model", "set model = \"penalty\""],
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.contains("(the default)"), default, "{stderr}");
    }
    // With penalty contact they are its spring: accepted.
    let ok = simulate_text(&scene_with_contact(
        "model = \"penalty\"\nfrequency_ratio = 50\ndamping_ratio = 0.5",
    ));
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}

#[test]
fn rigid_contact_switched_off_is_refused_naming_both_keys() {
    let out = simulate_text(&scene_with_contact("model = \"rigid\"\nenabled = false"));
    refused(&out, &["effects.contact.model", "effects.contact.enabled"]);
}

#[test]
fn rigid_contact_for_point_masses_is_refused() {
    // The main job's scene: three point masses.
    let scene = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/three_balls.toml"),
    )
    .unwrap();
    let text = format!("{scene}\n[effects.contact]\nmodel = \"rigid\"\n");
    refused(
        &simulate_text(&text),
        &["effects.contact.model", "point mass"],
    );
}

#[test]
fn an_optimisation_over_sobol_points_needs_a_power_of_two_of_samples() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("results");
    let text = format!(
        r#"name = "sobol_opt"
output = "{}"
{}drag = 0.5
[sampling]
samples = 8
sequence = "sobol"
unbalance = {{ distribution = "uniform", min = 2e-5, max = 2e-4, relative_to = "absolute" }}
[optimize]
objective = "settling_mean"
samples = 3
max_evaluations = 4
"#,
        out_dir.display(),
        crate::fixtures::SOFT_ROTOR
    );
    let path = dir.path().join("study.toml");
    std::fs::write(&path, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["optimize", path.to_str().unwrap()])
        .output()
        .unwrap();
    refused(
        &out,
        &["optimize.samples", "sampling.sequence", "power of two"],
    );
    assert!(!out_dir.exists(), "a refusal wrote {}", out_dir.display());
}

#[test]
fn a_design_compared_with_itself_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["compare", dir.path().to_str().unwrap(), "--designs", "1,1"])
        .output()
        .unwrap();
    refused(&out, &["--designs 1,1", "itself"]);
}
