//! Per-design statistics against hand computations on a small fixture.

use crate::fixtures::SI_SCENE;
use autobal::decide::verdict::{DesignRuns, Verdict, best_versus_rest, settling_horizon};
use autobal::metrics::{Outcome, RunMetrics};
use autobal::stats::bootstrap;
use autobal::stats::interval::wilson_interval;
use autobal::stats::survival::Observation;
use autobal::study::plan::config::StudyFile;
use autobal::study::plan::criterion::Criterion;
use autobal::study::plan::sample::{Purpose, stream};
use autobal::study::results::measured_runs::Scale;
use autobal::study::results::record::RunRecord;
use autobal::study::run::aggregate::summarize;

fn plan() -> autobal::study::plan::config::StudyPlan {
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
samples = 6
unbalance = { distribution = "fixed", value = 0.5, relative_to = "capacity" }
"#,
    ]
    .concat();
    StudyFile::parse(text, "fixture.toml")
        .unwrap()
        .plan(text, "fixture.toml")
        .unwrap()
}

pub(crate) fn record(id: u64, outcome: Outcome, revs: Option<f64>, residual_rel: f64) -> RunRecord {
    RunRecord {
        run_id: id,
        design_id: 0,
        sample_id: id as u32,
        kind: "ball".into(),
        n: 3,
        rho: 0.36,
        race_radius: 0.05,
        weight_mass: 0.2,
        capacity: 0.016,
        drag: 10.0,
        unbalance: 0.008,
        unbalance_fraction: 0.5,
        direction_deg: 0.0,
        initial_angles_deg: vec![0.0, 10.0, 20.0],
        metrics: RunMetrics {
            settled: outcome == Outcome::Settled,
            settling_time: revs.map(|r| r * 0.02),
            settling_revs: revs,
            settling_time_err: 0.001,
            settling_time_eps: None,
            hold_complete: revs.is_some(),
            hold_certified: false,
            residual_abs: residual_rel * 1e-4,
            residual_rel,
            a_ref: 1e-4,
            balancing_error: 0.0,
            peak_r: 1e-3,
            final_rel_angles_deg: vec![120.0, 180.0, 240.0],
            p_final: 0.0,
            outcome,
            reason: String::new(),
            t_final: 10.0,
            steps: 100,
            rhs_calls: 600,
            method: "dp5".into(),
            fidelity: "full".into(),
            contact_model: None,
            min_gap_rad: None,
            final_min_gap_rad: None,
            censoring_revs: None,
            operating_time: Some(0.0),
            final_spin_rate: None,
            pack_slip_rate: None,
            balance_angle_error_deg: None,
            plane_a_ref: None,
            plane_residual_abs: None,
            plane_settling_revs: None,
            plane_balancing_error: None,
            bearing_orbit_peak: None,
            bearing_orbit_rms: None,
        },
        method: "dp5".into(),
        contact: true,
        stall_torque: None,
        wall_time_s: 0.001,
        weights: None,
        couple: None,
        uncertain: Vec::new(),
    }
}

#[test]
fn summary_matches_a_hand_computation() {
    let runs = vec![
        record(0, Outcome::Settled, Some(10.0), 0.01),
        record(1, Outcome::Settled, Some(40.0), 0.02),
        record(2, Outcome::Settled, Some(20.0), 0.03),
        record(3, Outcome::NotSettled, None, 0.50),
        record(4, Outcome::Settled, Some(30.0), 0.04),
        record(5, Outcome::Diverged, None, 99.0),
    ];
    let df = summarize(&plan(), &runs).unwrap();
    let f = |c: &str| df.column(c).unwrap().f64().unwrap().get(0).unwrap();
    let u = |c: &str| df.column(c).unwrap().u64().unwrap().get(0).unwrap();
    assert_eq!(u("runs"), 6);
    assert_eq!(u("settled"), 4);
    assert_eq!(u("not_settled"), 1);
    assert_eq!(u("diverged"), 1);
    assert_eq!(u("solver_failed"), 0);
    assert!((f("settled_fraction") - 4.0 / 6.0).abs() < 1e-15);
    // Every run counts: settled at 10, 20, 30, 40 revolutions; the two that
    // did not settle are censored at the horizon (t_end − W). Kaplan–Meier:
    // S = 5/6, 4/6, 3/6 after 10, 20, 30; S sits on 1/2 until 40, so the
    // median is (30 + 40)/2, as over [10, 20, 30, 40, ∞, ∞].
    assert_eq!(f("settling_revs_median_km"), 35.0);
    let tau = settling_horizon(&plan());
    assert_eq!(f("settling_horizon_revs"), tau);
    // Restricted mean: the area under S from 0 to τ.
    let area =
        10.0 + 10.0 * 5.0 / 6.0 + 10.0 * 4.0 / 6.0 + 10.0 * 3.0 / 6.0 + (tau - 40.0) * 2.0 / 6.0;
    assert!((f("settling_revs_rmst") - area).abs() < 1e-9 * area);
    assert!(f("settling_revs_rmst_lo") < area && area < f("settling_revs_rmst_hi"));
    // The p90 over all six falls among the two runs that did not settle.
    assert!(
        df.column("settling_revs_p90_all_runs")
            .unwrap()
            .f64()
            .unwrap()
            .get(0)
            .is_none()
    );
    // No mean or quantile over the settled runs alone is reported.
    for gone in [
        "settling_revs_mean",
        "settling_revs_median",
        "settling_revs_p95",
    ] {
        assert!(df.column(gone).is_err(), "{gone}");
    }
    // One design: nothing to compare it with.
    assert_eq!(
        df.column("vs_best_verdict").unwrap().str().unwrap().get(0),
        Some("only_design")
    );
    // Residual over the runs simulated to the end (settled or not): 0.01..0.04 and 0.5.
    assert!((f("residual_rel_mean") - 0.6 / 5.0).abs() < 1e-15);
    assert!((f("residual_rel_median") - 0.03).abs() < 1e-15);
}

#[test]
fn median_over_all_runs_counts_runs_that_did_not_settle() {
    let runs = |outcomes: &[(Outcome, Option<f64>)]| -> Vec<RunRecord> {
        outcomes
            .iter()
            .enumerate()
            .map(|(i, (o, t))| record(i as u64, *o, *t, 0.01))
            .collect()
    };
    let median = |rs: &[RunRecord]| {
        let p = plan();
        let df = summarize(&p, rs).unwrap();
        df.column("settling_revs_median_km")
            .unwrap()
            .f64()
            .unwrap()
            .get(0)
    };
    let fast_but_flaky = runs(&[
        (Outcome::Settled, Some(1.0)),
        (Outcome::Settled, Some(1.0)),
        (Outcome::Censored, None),
        (Outcome::Censored, None),
        (Outcome::Diverged, None),
        (Outcome::SolverFailed, None),
    ]);
    // Half or more did not settle: the median lies beyond the run, although
    // the settled runs alone have median 1.
    assert_eq!(median(&fast_but_flaky), None);
    let steady = runs(&[
        (Outcome::Settled, Some(3.0)),
        (Outcome::Settled, Some(4.0)),
        (Outcome::Settled, Some(5.0)),
        (Outcome::Settled, Some(6.0)),
        (Outcome::Settled, Some(7.0)),
        (Outcome::Censored, None),
    ]);
    assert_eq!(median(&steady), Some(5.5));
    // p90 of [3, 4, 5, 6, 7, ∞]: h = 4.5 lies between 7 and ∞, beyond the run.
    let p90 = |rs: &[RunRecord]| {
        summarize(&plan(), rs)
            .unwrap()
            .column("settling_revs_p90_all_runs")
            .unwrap()
            .f64()
            .unwrap()
            .get(0)
    };
    assert_eq!(p90(&steady), None);
    let all_settled = runs(&[
        (Outcome::Settled, Some(1.0)),
        (Outcome::Settled, Some(2.0)),
        (Outcome::Settled, Some(3.0)),
        (Outcome::Settled, Some(4.0)),
        (Outcome::Settled, Some(5.0)),
        (Outcome::Settled, Some(6.0)),
    ]);
    // Read off the Kaplan–Meier curve by the median's convention: S is
    // 1/6 after 5 rev and 0 after 6, so the first time S ≤ 0.1 is 6
    // (interpolating the raw times gave 5.5 before 2026-12-07).
    assert_eq!(p90(&all_settled), Some(6.0));
}

#[test]
fn wilson_interval_matches_closed_forms() {
    // All failures: upper limit z²/(n + z²); all successes: lower limit n/(n + z²).
    let z2 = 1.959_963_984_540_054f64.powi(2);
    let (lo, hi) = wilson_interval(0, 10);
    assert_eq!(lo, 0.0);
    assert!((hi - z2 / (10.0 + z2)).abs() < 1e-12);
    let (lo, hi) = wilson_interval(10, 10);
    assert!((lo - 10.0 / (10.0 + z2)).abs() < 1e-12 && (hi - 1.0).abs() < 1e-15);
    // Newcombe (1998), example: 81/263 → 0.2553 … 0.3662.
    let (lo, hi) = wilson_interval(81, 263);
    assert!(
        (lo - 0.2553).abs() < 5e-5 && (hi - 0.3662).abs() < 5e-5,
        "{lo} {hi}"
    );
}

#[test]
fn bootstrap_is_seeded_and_brackets_the_mean() {
    let values: Vec<f64> = (1..=50).map(f64::from).collect();
    // The stream summarize() uses for design 0 of a study seeded `seed`.
    let ci = |seed| bootstrap::mean_ci(&values, &mut stream(seed, Some(0), 0, Purpose::Bootstrap));
    let a = ci(1).unwrap();
    assert_eq!(a, ci(1).unwrap());
    assert_ne!(a, ci(2).unwrap());
    // Normal approximation: 25.5 ± 1.96·σ/√n with σ ≈ 14.58 → half-width ≈ 4.04.
    assert!(
        (a.0 - (25.5 - 4.04)).abs() < 1.0 && (a.1 - (25.5 + 4.04)).abs() < 1.0,
        "{a:?}"
    );
    assert!(bootstrap::mean_ci(&[1.0], &mut stream(1, Some(0), 0, Purpose::Bootstrap)).is_none());
}

/// Runs of one design at the given settling times (`None`: censored at 100).
fn design(id: u32, times: &[Option<f64>]) -> DesignRuns {
    DesignRuns {
        design_id: id,
        sample_ids: (0..times.len() as u32).collect(),
        settling: times
            .iter()
            .map(|t| Observation {
                time: t.unwrap_or(100.0),
                settled: t.is_some(),
            })
            .collect(),
        residual: vec![Some(0.01); times.len()],
        residual_abs: vec![Some(1e-6); times.len()],
    }
}

/// τ = 100 rev, one revolution 0.02 s.
const SCALE: Scale = Scale {
    tau: 100.0,
    rev_seconds: 0.02,
};

#[test]
fn the_best_design_is_compared_with_every_other_on_paired_runs() {
    let fast: Vec<Option<f64>> = (0..40).map(|i| Some(10.0 + f64::from(i))).collect();
    // Slower by 5 revolutions on every shared sample.
    let slow: Vec<Option<f64>> = fast.iter().map(|t| t.map(|t| t + 5.0)).collect();
    // The same as the fast one but for one sample either way: a tie.
    let mut twin = fast.clone();
    twin.swap(0, 39);
    // Settles sooner on most samples, but never in a quarter of them.
    let flaky: Vec<Option<f64>> = fast
        .iter()
        .enumerate()
        .map(|(i, t)| if i % 4 == 0 { None } else { t.map(|t| t - 1.0) })
        .collect();
    let designs = [
        design(0, &slow),
        design(1, &fast),
        design(2, &twin),
        design(3, &flaky),
    ];
    let v = best_versus_rest(&designs, Criterion::Median, &SCALE, 0.05, true, 1).unwrap();
    assert!(v.paired);
    // Kaplan–Meier medians: fast and twin 29.5 (the same times; equal
    // restricted means, so the first is the best), flaky 35.5 (its 20th and
    // 21st settling times, 35 and 36), slow 34.5.
    assert_eq!(v.best, 1);
    let verdict = |id: u32| v.others.iter().find(|(c, _, _)| c.b == id).unwrap();
    let (vs_slow, p_slow, slow_verdict) = verdict(0);
    let paired = vs_slow.paired.as_ref().unwrap();
    assert_eq!((paired.a_sooner, paired.b_sooner, paired.ties), (40, 0, 0));
    assert_eq!(paired.median_difference, 5.0);
    assert_eq!(*slow_verdict, Verdict::BestBetter);
    // Sign test 2·0.5⁴⁰, the smallest of three p-values: Holm multiplies it by 3.
    assert!((p_slow / (3.0 * 2.0 * 0.5f64.powi(40)) - 1.0).abs() < 1e-9);
    // The twin differs on two samples, one each way: indistinguishable.
    let (vs_twin, p_twin, twin_verdict) = verdict(2);
    assert_eq!(vs_twin.paired.as_ref().unwrap().ties, 38);
    assert_eq!((*p_twin, *twin_verdict), (1.0, Verdict::NotDistinguishable));
    // Flaky wins 30 of 40 pairs although its median is higher: the verdict
    // says the rankings disagree instead of calling the best faster.
    let (vs_flaky, _, flaky_verdict) = verdict(3);
    assert_eq!(vs_flaky.paired.as_ref().unwrap().b_sooner, 30);
    assert_eq!(*flaky_verdict, Verdict::OtherBetter);
    // Holm: adjusted p-values are never below the raw ones.
    for (c, p, _) in &v.others {
        assert!(*p >= c.p_value());
    }
    // Without common random numbers the same runs are compared unpaired (log-rank).
    let unpaired = best_versus_rest(&designs, Criterion::Median, &SCALE, 0.05, false, 1).unwrap();
    assert!(!unpaired.paired);
    assert!(
        unpaired
            .others
            .iter()
            .all(|(c, _, _)| c.paired.is_none() && c.unpaired.is_some())
    );
}

/// The main job's reversal in miniature: design 0 has the lower median but
/// 30 % of its runs take ten times longer; design 1 always takes 12 rev.
fn fast_median_slow_tail() -> [DesignRuns; 2] {
    let tail: Vec<Option<f64>> = (0..80)
        .map(|i| {
            Some(if i % 10 < 3 {
                80.0
            } else {
                8.0 + 0.01 * f64::from(i)
            })
        })
        .collect();
    let steady: Vec<Option<f64>> = (0..80).map(|i| Some(12.0 + 0.01 * f64::from(i))).collect();
    [design(0, &tail), design(1, &steady)]
}

#[test]
fn the_default_criterion_counts_the_tail_and_the_median_win_is_reported_beside_it() {
    let designs = fast_median_slow_tail();
    assert_eq!(Criterion::default(), Criterion::Mean);
    // Ranked by the restricted mean (29.6 against 12.4 rev), the steady design leads.
    let by_mean = best_versus_rest(&designs, Criterion::Mean, &SCALE, 0.05, true, 1).unwrap();
    assert_eq!(by_mean.best, 1);
    let (c, p, verdict) = &by_mean.others[0];
    assert_eq!(*verdict, Verdict::BestBetter, "p {p}");
    // ... and the other design's median win is measured, significant, and on record.
    let median = c.on(Criterion::Median).unwrap();
    assert!(median.b_better_at(0.05), "{median:?}");
    let p90 = c.on(Criterion::P90).unwrap();
    assert!(p90.a_better_at(0.05), "{p90:?}");
    // Ranked by the median, the tail design leads, and the restricted-mean
    // test says the other is better.
    let by_median = best_versus_rest(&designs, Criterion::Median, &SCALE, 0.05, true, 1).unwrap();
    assert_eq!(by_median.best, 0);
    let mean = by_median.others[0].0.on(Criterion::Mean).unwrap();
    assert!(mean.b_better_at(0.05), "{mean:?}");
}

#[test]
fn share_criteria_rank_by_the_share_and_test_the_discordant_pairs() {
    let designs = fast_median_slow_tail();
    // Settled within 30 rev: 56 of 80 against 80 of 80.
    let within = Criterion::parse("settled_by:30rev").unwrap();
    let v = best_versus_rest(&designs, within, &SCALE, 0.05, true, 1).unwrap();
    assert_eq!(v.best, 1);
    let d = v.others[0].0.measures[0].difference.unwrap();
    assert_eq!(d.test, "mcnemar");
    assert!((d.a - 1.0).abs() < 1e-12 && (d.b - 0.7).abs() < 1e-12);
    // 24 discordant pairs, all one way: 2·0.5²⁴.
    assert!((d.p_value / (2.0 * 0.5f64.powi(24)) - 1.0).abs() < 1e-9);
    // In seconds: 30 rev of 0.02 s is 0.6 s, the same ranking.
    let seconds = Criterion::parse("settled_by:0.6s").unwrap();
    assert_eq!(
        seconds.value(&designs[0], &SCALE),
        within.value(&designs[0], &SCALE)
    );
}

#[test]
fn when_nothing_settles_the_design_leaving_the_least_vibration_ranks_first() {
    let never: Vec<Option<f64>> = vec![None; 10];
    let mut shaky = design(0, &never);
    shaky.residual = vec![Some(3.0); 10];
    let mut calm = design(1, &never);
    calm.residual = vec![Some(0.4); 10];
    let v = best_versus_rest(&[shaky, calm], Criterion::Mean, &SCALE, 0.05, true, 1).unwrap();
    assert_eq!(v.best, 1);
    assert!(!v.works, "nothing settled: no design balances");
}
