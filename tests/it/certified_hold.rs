//! The certified hold (`metrics.certified_hold`, src/metrics/certify.rs)
//! ends settled runs before their hold window is over. On every shipped
//! study, run by run, it must report what the full hold reports: the same
//! outcome, settling times (on r and on ε) and peak r, the residual within
//! 1 % and the closest approach of the weights within 1e-4 rad; a run it
//! does not end early must be the full hold's run, bit for bit.

use crate::fixtures::{shipped_plan_edited, shipped_studies};
use autobal::study::run::run_one;

/// Samples per design of each shipped study.
const SAMPLES: u32 = 3;

#[test]
fn certified_hold_reports_the_full_holds_settling_and_residual_on_every_shipped_study() {
    let (mut runs, mut certified) = (0usize, 0usize);
    let (mut worst_residual, mut full_revs, mut certified_revs) = (0.0f64, 0.0, 0.0);
    let mut worst_gap = 0.0f64;
    for path in &shipped_studies() {
        let full = shipped_plan_edited(path, SAMPLES, |f| f.metrics.certified_hold = false);
        let early = shipped_plan_edited(path, SAMPLES, |f| f.metrics.certified_hold = true);
        for id in 0..full.total_runs() {
            let a = run_one(&full, id).metrics;
            let b = run_one(&early, id).metrics;
            let what = format!("{} run {id}", path.display());
            assert!(!a.hold_certified, "{what}: certified with the option off");
            assert_eq!(a.outcome, b.outcome, "{what}");
            assert_eq!(a.settling_time, b.settling_time, "{what}");
            assert_eq!(a.settling_revs, b.settling_revs, "{what}");
            assert_eq!(a.settling_time_eps, b.settling_time_eps, "{what}");
            assert_eq!(a.hold_complete, b.hold_complete, "{what}");
            let gap_off = match (a.min_gap_rad, b.min_gap_rad) {
                (Some(x), Some(y)) => (x - y).abs(),
                (x, y) => {
                    assert_eq!(x, y, "{what}");
                    0.0
                }
            };
            // The tail's gaps are the flow's, checked every few samples.
            assert!(
                gap_off <= 1e-4,
                "{what}: closest approach {:?} against {:?} of the full hold",
                b.min_gap_rad,
                a.min_gap_rad
            );
            worst_gap = worst_gap.max(gap_off);
            assert_eq!(a.peak_r, b.peak_r, "{what}");
            runs += 1;
            if b.hold_certified {
                certified += 1;
                let off = (b.residual_rel / a.residual_rel - 1.0).abs();
                assert!(
                    off <= 0.01,
                    "{what}: residual {} against {} of the full hold",
                    b.residual_rel,
                    a.residual_rel
                );
                assert!(b.t_final < a.t_final, "{what}: certified but not shorter");
                worst_residual = worst_residual.max(off);
                full_revs += a.t_final;
                certified_revs += b.t_final;
            } else {
                assert_eq!(a.residual_rel, b.residual_rel, "{what}");
                assert_eq!(a.t_final, b.t_final, "{what}");
                assert_eq!(a.final_rel_angles_deg, b.final_rel_angles_deg, "{what}");
            }
        }
    }
    eprintln!(
        "{certified} of {runs} runs certified early, simulated time {:.2} of the full hold's; \
         largest residual change {worst_residual:.2e}, of the closest approach {worst_gap:.2e} rad",
        certified_revs / full_revs
    );
    // Not vacuous: the default path (rotating frame, early stop) is most runs.
    assert!(
        certified * 3 >= runs,
        "only {certified} of {runs} runs certified"
    );
}

/// A tighter tolerance asks for a residual as accurate: at rtol 1e-9 the
/// certified hold may move Σ r² by 1e4·rtol = 1e-5 of itself at most, so the
/// residual by 5e-6 (`certify::residual_share`).
#[test]
fn a_tight_tolerance_tightens_the_certified_residual() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/three_balls.toml");
    let tight = |certified: bool| {
        shipped_plan_edited(&path, 2, |f| {
            f.solver.rtol = 1e-9;
            f.metrics.certified_hold = certified;
        })
    };
    let (full, early) = (tight(false), tight(true));
    let mut certified = 0;
    for id in 0..full.total_runs() {
        let (a, b) = (run_one(&full, id).metrics, run_one(&early, id).metrics);
        assert_eq!(a.settling_revs, b.settling_revs, "run {id}");
        let off = (b.residual_rel / a.residual_rel - 1.0).abs();
        assert!(off <= 5e-6, "run {id}: residual moved {off:.1e}");
        certified += usize::from(b.hold_certified);
    }
    assert!(certified > 0, "no run certified at rtol 1e-9");
}
