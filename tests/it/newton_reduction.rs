//! Radau5's reduced Newton systems (m×m for a second-order system of
//! dimension 2m) give the answers of the full 2m×2m ones on every shipped
//! study with Radau5 throughout.
//!
//! Where the answer is smooth in the rounding — the rotating frame without
//! rolling resistance, which is the main job's default path — run by run:
//! the same outcome, the same settling time, the residual within 1 %.
//!
//! Elsewhere a rounding-level change alone moves some runs: a weight that
//! stops near its breakaway torque stops elsewhere in its dead band (rolling
//! resistance), swinging weights under gravity and a rotor crawling through
//! resonance on a weak motor follow another path. There the yardstick is the
//! full solver itself with its tolerance changed by one part in 10¹²: the
//! reduction may move no more runs than that does (measured when written:
//! 160 runs agree run by run; of 76 other runs the reduction moved 5 and the
//! 1e-12 change of rtol 4).

use crate::fixtures::{shipped_plan, shipped_studies};
use autobal::integrate::Method;
use autobal::metrics::RunMetrics;
use autobal::simulation::MethodChoice;
use autobal::study::run::run_one;

/// Whether `b` gives `a`'s outcome and settling time and its residual within 1 %.
fn agree(a: &RunMetrics, b: &RunMetrics) -> bool {
    a.outcome == b.outcome
        && a.settling_revs == b.settling_revs
        && (a.residual_rel / b.residual_rel - 1.0).abs() <= 0.01
}

#[test]
fn reduced_newton_systems_settle_when_and_where_full_ones_do_on_every_shipped_study() {
    let radau5 = MethodChoice::Fixed(Method::Radau5);
    let (mut strict, mut bits_moved) = (0, 0);
    let (mut sensitive, mut moved_by_reduction, mut moved_by_rounding) = (0, 0, 0);
    for path in &shipped_studies() {
        let sticks = std::fs::read_to_string(path)
            .unwrap()
            .contains("rolling_resistance");
        let reduced = shipped_plan(path, 2, |s| s.method = radau5);
        let full = shipped_plan(path, 2, |s| {
            s.method = radau5;
            s.full_newton = true;
        });
        let nudged = shipped_plan(path, 2, |s| {
            s.method = radau5;
            s.full_newton = true;
            s.rtol *= 1.0 + 1e-12;
        });
        for id in 0..reduced.total_runs() {
            let new = run_one(&reduced, id).metrics;
            let old = run_one(&full, id).metrics;
            let what = format!("{} run {id}", path.display());
            bits_moved += usize::from(new.residual_rel != old.residual_rel);
            assert_eq!(new.outcome, old.outcome, "{what}");
            if new.fidelity == "rotating" && !sticks {
                assert!(
                    agree(&new, &old),
                    "{what}: settling {:?} vs {:?}, residual {} vs {}",
                    new.settling_revs,
                    old.settling_revs,
                    new.residual_rel,
                    old.residual_rel
                );
                strict += 1;
            } else {
                let other = run_one(&nudged, id).metrics;
                sensitive += 1;
                moved_by_reduction += usize::from(!agree(&new, &old));
                moved_by_rounding += usize::from(!agree(&other, &old));
            }
        }
    }
    eprintln!(
        "{strict} runs agree; of {sensitive} sensitive runs the reduction moved \
         {moved_by_reduction}, a 1e-12 change of rtol {moved_by_rounding}; \
         {bits_moved} runs not bit-identical"
    );
    assert!(strict > 100, "only {strict} runs compared run by run");
    assert!(sensitive > 40, "only {sensitive} sensitive runs");
    assert!(
        moved_by_reduction <= 2 * moved_by_rounding + 2,
        "the reduction moved {moved_by_reduction} of {sensitive} runs, rounding {moved_by_rounding}"
    );
    // The two really are different computations (rounding differs): were the
    // option ignored, every residual would match bit for bit.
    assert!(
        bits_moved > (strict + sensitive) / 10,
        "only {bits_moved} runs differ at all"
    );
}
