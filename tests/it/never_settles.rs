//! The certified "not settled" (`metrics.certified_not_settled`,
//! src/metrics/never_settles.rs) ends runs whose state repeats every two
//! revolutions outside the band (or below the operating speed). On every shipped study, run by run, it must
//! report what the full integration reports: `not_settled` only where the
//! full run ends `censored`, the residual within 1 %, the same ε settling
//! time, censoring time and horizon, the peak r and closest approach; a run
//! it does not end early must be the full run, bit for bit.

use crate::fixtures::{shipped_plan_edited, shipped_studies};
use autobal::metrics::Outcome;
use autobal::metrics::never_settles::RESIDUAL_SHARE;
use autobal::study::run::run_one;

/// Samples per design of each shipped study (sample 1 of gravity_horizontal's
/// pendulums locks on a periodic orbit outside the band).
const SAMPLES: u32 = 3;

#[test]
fn certified_not_settled_agrees_with_the_full_integration_on_every_shipped_study() {
    let (mut runs, mut certified) = (0usize, 0usize);
    let (mut worst_residual, mut full_calls, mut early_calls) = (0.0f64, 0u64, 0u64);
    let mut multi_plane_certified = 0usize;
    // The uncertain study's calls, guarded apart (see LATE_STUDY).
    let (mut late_full, mut late_early) = (0u64, 0u64);
    for path in &shipped_studies() {
        let late = path.file_stem().is_some_and(|s| s == LATE_STUDY);
        let full = shipped_plan_edited(path, SAMPLES, |f| f.metrics.certified_not_settled = false);
        let early = shipped_plan_edited(path, SAMPLES, |f| f.metrics.certified_not_settled = true);
        for id in 0..full.total_runs() {
            let a = run_one(&full, id).metrics;
            let b = run_one(&early, id).metrics;
            let what = format!("{} run {id}", path.display());
            assert_ne!(
                a.outcome,
                Outcome::NotSettled,
                "{what}: with the option off"
            );
            runs += 1;
            if b.outcome != Outcome::NotSettled {
                assert_eq!(a, b, "{what}: not certified, so the full run bit for bit");
                continue;
            }
            certified += 1;
            assert_eq!(a.outcome, Outcome::Censored, "{what}: {}", b.reason);
            let off = (b.residual_rel / a.residual_rel - 1.0).abs();
            assert!(
                off <= 0.01,
                "{what}: residual {} against {} of the full run",
                b.residual_rel,
                a.residual_rel
            );
            worst_residual = worst_residual.max(off);
            // Each watched plane's residual too (rotors on two supports).
            if let (Some(pa), Some(pb)) = (&a.plane_residual_abs, &b.plane_residual_abs) {
                for (plane, (x, y)) in pa.iter().zip(pb).enumerate() {
                    assert!(
                        (y / x - 1.0).abs() <= 0.01,
                        "{what}: plane {plane}'s residual {y} against {x} of the full run"
                    );
                }
                multi_plane_certified += 1;
            }
            assert_eq!(a.settling_time_eps, b.settling_time_eps, "{what}");
            assert_eq!(a.censoring_revs, b.censoring_revs, "{what}");
            assert_eq!(a.t_final, b.t_final, "{what}");
            assert_eq!(a.operating_time, b.operating_time, "{what}");
            assert!((b.peak_r / a.peak_r - 1.0).abs() <= 0.01, "{what}: peak r");
            if let (Some(x), Some(y)) = (a.min_gap_rad, b.min_gap_rad) {
                assert!((x - y).abs() <= 1e-4, "{what}: closest approach");
            }
            // The certificate's own bound on every later state, angles in
            // rad among them: its tail is at most RESIDUAL_SHARE of the RMS.
            let bound = RESIDUAL_SHARE * b.residual_rel * 1.01;
            for (x, y) in a.final_rel_angles_deg.iter().zip(&b.final_rel_angles_deg) {
                let d = ((x - y + 180.0).rem_euclid(360.0) - 180.0).to_radians();
                assert!(d.abs() <= bound, "{what}: final angle {y} against {x}");
            }
            // Radau5 may cross a stuck tail in a step or two: never dearer.
            assert!(b.rhs_calls <= a.rhs_calls, "{what}: certified but dearer");
            if late {
                late_full += a.rhs_calls;
                late_early += b.rhs_calls;
            } else {
                full_calls += a.rhs_calls;
                early_calls += b.rhs_calls;
            }
        }
    }
    let late_share = late_early as f64 / late_full.max(1) as f64;
    eprintln!(
        "{certified} of {runs} runs certified not to settle ({multi_plane_certified} on rotors with several planes), at {:.3} of the full runs' RHS calls \
         ({LATE_STUDY}: {late_share:.3}); largest residual change {worst_residual:.2e}",
        early_calls as f64 / full_calls.max(1) as f64
    );
    assert!(
        late_share <= 1.02 * LATE_CALL_SHARE,
        "{LATE_STUDY}'s certified runs at {late_share:.3} of the full runs' RHS calls"
    );
    // Not vacuous: gravity_horizontal's locked pendulums are certified.
    assert!(certified >= 1, "no run certified");
    // The RHS-count guard of the early end: a count, not a time, so a change
    // that makes it later or dearer shows on any machine.
    let share = early_calls as f64 / full_calls as f64;
    assert!(
        share <= 1.02 * MEASURED_CALL_SHARE,
        "certified runs at {share:.3} of the full runs' RHS calls"
    );
}

/// The certified runs' RHS calls over the same runs' in full, measured when
/// the guard was written (28 of the 360 runs, 2026-11-26), over every
/// shipped study but [`LATE_STUDY`].
const MEASURED_CALL_SHARE: f64 = 0.383;

/// A shipped study whose certified runs end late, guarded apart so that
/// its share does not hide a regression of the others': its balls, held by
/// rolling resistance in a dead band on an off-centre race, are certified
/// only near the horizon (measured 2026-11-29).
const LATE_STUDY: &str = "three_balls_uncertain";

/// [`LATE_STUDY`]'s certified runs' RHS calls over the same runs' in full.
const LATE_CALL_SHARE: f64 = 0.949;

/// A rotor on two supports whose balls stick in their dead band (rolling
/// resistance μ = 0.05) from the start: its state repeats every revolution
/// while both planes whirl far outside their bands. The watch, which sees
/// each plane's body-frame state and whirl, certifies it early; the full
/// run to the horizon must agree (outcome, the rotor's and each plane's
/// residual within 1 %, the final angles within the certificate's bound).
#[test]
fn a_two_support_rotor_with_stuck_balls_is_certified_and_agrees_with_the_full_run() {
    let text = |certify: bool| {
        format!(
            r#"
[rotor]
model = "two_support"
mass = 4.0
transverse_inertia = 0.02
polar_inertia = 0.004
k1 = 2.0e4
l1 = 0.08
k2 = 2.0e4
l2 = 0.08
b1 = 400.0
b2 = 400.0
planes = [-0.12, 0.12]
static_unbalance = 8.0e-5
moment_unbalance = 4.0e-6

[speed]
mode = "constant"
rpm = 3000

[effects.gravity]
g = 9.81

[effects.rolling_resistance]
coefficient = 0.05
static_ratio = 1.5

[[balancers]]
plane = 0
kind = "ball"
n = 2
rho = 0.1
race_radius = 0.05
density = 7850.0
drag = 0.5

[[balancers]]
plane = 1
kind = "ball"
n = 2
rho = 0.1
race_radius = 0.05
density = 7850.0
drag = 0.5

[metrics]
t_end_revs = 400
hold_revs = 50
certified_not_settled = {certify}
"#
        )
    };
    let run = |certify: bool| {
        autobal::scene_file::SceneFile::parse(&text(certify), "scene.toml")
            .expect("valid scene")
            .simulation("scene.toml")
            .expect("simulation")
            .run(false)
            .expect("runs")
            .metrics
    };
    let (full, early) = (run(false), run(true));
    assert_eq!(full.outcome, Outcome::Censored, "{}", full.reason);
    assert_eq!(early.outcome, Outcome::NotSettled, "{}", early.reason);
    assert!(
        early.rhs_calls * 3 < full.rhs_calls,
        "{} against {}",
        early.rhs_calls,
        full.rhs_calls
    );
    assert_eq!(full.t_final, early.t_final);
    assert!((early.residual_rel / full.residual_rel - 1.0).abs() <= 0.01);
    let (pa, pb) = (
        full.plane_residual_abs.expect("planes"),
        early.plane_residual_abs.expect("planes"),
    );
    for (x, y) in pa.iter().zip(&pb) {
        assert!(
            (y / x - 1.0).abs() <= 0.01,
            "plane residual {y} against {x}"
        );
    }
    let bound = RESIDUAL_SHARE * early.residual_rel * 1.01;
    for (x, y) in full
        .final_rel_angles_deg
        .iter()
        .zip(&early.final_rel_angles_deg)
    {
        let d = ((x - y + 180.0).rem_euclid(360.0) - 180.0).to_radians();
        assert!(d.abs() <= bound, "final angle {y} against {x}");
    }
}
