//! Rigid contact on a whole design, against its reference and its cost:
//! the peer design (`bench/lean/peer.toml`, three steel balls started
//! clustered on the main job's rotor) with `model = "rigid"` settles run by
//! run as the rigid limit does (the same model at rtol 1e-10, where `auto`
//! takes DOP853), stays on the explicit method throughout, never overlaps,
//! and costs no more RHS calls per run than measured.

use crate::fixtures::shipped_plan_edited;
use autobal::metrics::RunMetrics;
use autobal::model::effect::contact::ContactModel;
use autobal::study::plan::config::StudyPlan;
use autobal::study::run::run_one;
use std::path::PathBuf;

/// Runs of the peer design each test makes (measured on 1 000 too, below).
const SAMPLES: u32 = 60;

/// The peer design with rigid contact at `rtol`.
fn peer(rtol: f64) -> StudyPlan {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("bench/lean/peer.toml");
    shipped_plan_edited(&path, SAMPLES, |file| {
        let contact = file.scene.effects.contact.as_mut().expect("contact is on");
        contact.model = Some(ContactModel::Rigid);
        file.solver.rtol = rtol;
    })
}

fn runs(plan: &StudyPlan) -> Vec<RunMetrics> {
    (0..plan.total_runs())
        .map(|id| run_one(plan, id).metrics)
        .collect()
}

/// The same outcome in every run and the settling time within one sample
/// (1/32 rev) in at least 95 % of them, as the issue asked of a contact
/// model. Measured on 1 000 runs (`bench/lean/peer.toml` at its shipped
/// 1 000 samples, rigid at rtol 1e-6 against 1e-10): all 1 000 the same
/// outcome and the same settling sample; the penalty model at its defaults
/// against the same reference: 948 of 1 000 within a sample (its contact
/// rebounds at about 5 %, tests/it/rigid_contact.rs).
#[test]
fn the_peer_design_settles_run_by_run_as_the_rigid_limit_does() {
    let (default, limit) = (runs(&peer(1e-6)), runs(&peer(1e-10)));
    let sample = 1.0 / 32.0;
    let mut within = 0;
    for (i, (a, b)) in default.iter().zip(&limit).enumerate() {
        assert_eq!(a.outcome, b.outcome, "run {i}: {} / {}", a.reason, b.reason);
        assert_eq!(a.contact_model, Some("rigid"));
        if let (Some(x), Some(y)) = (a.settling_revs, b.settling_revs)
            && (x - y).abs() <= sample + 1e-9
        {
            within += 1;
        }
        // No overlap beyond the event's offset: the model's point.
        assert!(
            a.min_gap_rad.unwrap() >= -1e-11,
            "run {i}: {:?}",
            a.min_gap_rad
        );
        // No stiffness left: the explicit method throughout.
        assert_eq!(a.method, "dp5", "run {i}");
    }
    assert!(
        f64::from(within) >= 0.95 * f64::from(SAMPLES),
        "{within} of {SAMPLES} within a sample"
    );
}

/// RHS calls per run of the rigid peer design (the events' own right-hand
/// sides and the certified hold's included): a count, not a time, so a
/// change that makes rigid runs costlier shows here on any machine.
/// Measured when written: 2 940 per run on these 60 runs (3 248 on 1 000;
/// the penalty model takes 3 800 there, contact off 2 740); 2 819 since a
/// clustered start settles its links once instead of relinking them for 64
/// rounds.
#[test]
fn the_rigid_peer_design_costs_no_more_rhs_calls_per_run_than_measured() {
    let metrics = runs(&peer(1e-6));
    let per_run = metrics.iter().map(|m| m.rhs_calls).sum::<u64>() as f64 / metrics.len() as f64;
    eprintln!("{per_run:.0} RHS calls per run (guard: {MEASURED_RHS_PER_RUN} + 2 %)");
    assert!(
        per_run <= 1.02 * MEASURED_RHS_PER_RUN,
        "{per_run:.0} RHS calls per run"
    );
}

/// See [`the_rigid_peer_design_costs_no_more_rhs_calls_per_run_than_measured`].
const MEASURED_RHS_PER_RUN: f64 = 2819.0;
