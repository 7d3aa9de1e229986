//! `study tradeoff`: what each fidelity and tolerance costs and how far its
//! answers are from a reference, on a sample of a study's runs.
//!
//! Reference: the inertial (`full`) equations with DOP853 at rtol 1e-11,
//! with the study's contact model. Where the weights touch, the other
//! contact model is measured too (rigid contact for a penalty study, penalty
//! for a rigid one), in the cheapest frame the scene has. Each setting is
//! measured on the same runs; errors are per run (settling time in
//! revolutions, residual vibration in units of A_ref, final cargo angles,
//! outcome class), costs are wall time and right-hand-side calls.

use crate::integrate::Method;
use crate::metrics::RunMetrics;
use crate::model::effect::contact::ContactModel;
use crate::model::frame::rotating_frame_obstacle;
use crate::simulation::{Fidelity, MethodChoice};
use crate::stats::quantile::{Interpolation, quantile_sorted};
use crate::study::plan::config::StudyPlan;
use crate::study::results::io::{Provenance, write_parquet};
use crate::study::run::sample_simulation;
use polars::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// One fidelity/method/tolerance combination.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Setting {
    /// Formulation.
    pub fidelity: Fidelity,
    /// Integrator.
    pub method: MethodChoice,
    /// Relative tolerance (0 for the analytic estimate).
    pub rtol: f64,
    /// Whether a run handed over to Radau5 may return to the explicit
    /// method (`[solver] return_when_dearer`).
    pub return_when_dearer: bool,
    /// The contact model, when not the study's own.
    pub contact: Option<ContactModel>,
}

impl Setting {
    /// "rotating/radau5/1e-6".
    pub fn label(&self) -> String {
        if self.fidelity.is_estimate() {
            self.fidelity.name().into()
        } else {
            let kept = if self.return_when_dearer {
                ""
            } else {
                "/kept on radau5"
            };
            let contact = self
                .contact
                .map_or(String::new(), |m| format!("/{} contact", m.name()));
            format!(
                "{}/{}/{:.0e}{kept}{contact}",
                self.fidelity.name(),
                self.method.name(),
                self.rtol
            )
        }
    }
}

impl Setting {
    /// The study-file keys that select this setting, as a user writes them.
    pub fn keys(&self) -> String {
        let fidelity = format!("[solver] fidelity = \"{}\"", self.fidelity.name());
        if self.fidelity.is_estimate() {
            fidelity
        } else {
            let kept = if self.return_when_dearer {
                ""
            } else {
                ", return_when_dearer = false"
            };
            let contact = self.contact.map_or(String::new(), |m| {
                format!("; [scene.effects.contact] model = \"{}\"", m.name())
            });
            format!(
                "{fidelity}, method = \"{}\", rtol = {:.0e}{kept}{contact}",
                self.method.name(),
                self.rtol
            )
        }
    }
}

/// One run measured at one setting, against the reference.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TradeoffRow {
    /// Run index in the study.
    pub run_id: u64,
    /// The run's design.
    pub design_id: u32,
    /// The setting.
    pub setting: Setting,
    /// Settling time (revolutions), if settled.
    pub settling_revs: Option<f64>,
    /// The reference's settling time (revolutions), if it settled.
    pub reference_settling_revs: Option<f64>,
    /// The settling horizon t_end − hold (revolutions): where a run that
    /// does not settle is censored.
    pub horizon_revs: f64,
    /// |t_s − t_s,ref| in revolutions (0 when neither settles; None when only one does).
    pub settling_error_revs: Option<f64>,
    /// |residual − residual_ref| in units of A_ref.
    pub residual_error: f64,
    /// Largest difference of the sorted final cargo angles (degrees).
    pub angle_error_deg: Option<f64>,
    /// True when the outcome class equals the reference's.
    pub outcome_agrees: bool,
    /// Right-hand-side calls.
    pub rhs_calls: u64,
    /// Wall time (s).
    pub wall_time_s: f64,
    /// Integrator actually used (after any automatic switch).
    pub method_used: String,
}

/// One line of the work-precision table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SettingSummary {
    /// The setting.
    pub setting: Setting,
    /// Upper median |Δt_s| (the higher middle value) over the runs where both settled (revolutions).
    pub median_error_revs: Option<f64>,
    /// Largest |Δt_s| (revolutions).
    pub max_error_revs: Option<f64>,
    /// Largest |residual − residual_ref| (units of A_ref).
    pub max_residual_error: f64,
    /// Fraction of runs whose outcome class matches the reference.
    pub outcome_agreement: f64,
    /// Mean right-hand-side calls per run.
    pub mean_rhs_calls: f64,
    /// Mean wall time per run (s).
    pub mean_wall_time_s: f64,
    /// Designs with measured runs, ranked by this setting and the reference.
    pub designs_ranked: usize,
    /// Whether this setting's #1 design is the reference's (None: fewer than two designs).
    pub same_best: Option<bool>,
    /// Kendall's τ-b between this setting's ranking of the designs and the reference's.
    pub kendall_tau: Option<f64>,
}

/// The settings swept: analytic; linear; each applicable frame with its default
/// method at rtol 1e-3 … 1e-10; DOP853 in the inertial frame; and DP5 in the
/// inertial frame at the study's rtol kept on Radau5 once handed over.
pub fn settings(plan: &StudyPlan) -> Vec<Setting> {
    let estimate = |fidelity| Setting {
        fidelity,
        method: MethodChoice::Auto,
        rtol: 0.0,
        return_when_dearer: true,
        contact: None,
    };

    let mut v = Vec::new();
    let probe = plan.scene(&plan.designs[0], 0.0, 0.0);
    let mut frames = vec![
        (Fidelity::Full, MethodChoice::Fixed(Method::Dp5)),
        (Fidelity::Full, MethodChoice::Fixed(Method::Dop853)),
    ];
    // The estimates hold where the rotating frame is exact (isotropic, constant
    // speed, no in-plane gravity); elsewhere they do not apply at all.
    if rotating_frame_obstacle(&probe).is_none() {
        v.push(estimate(Fidelity::Analytic));
        v.push(estimate(Fidelity::Linear));
        frames.push((Fidelity::Rotating, MethodChoice::Fixed(Method::Radau5)));
        frames.push((Fidelity::Rotating, MethodChoice::Fixed(Method::Dp5)));
    }
    for (fidelity, method) in frames {
        for e in 3..=10 {
            v.push(Setting {
                fidelity,
                method,
                rtol: 10f64.powi(-e),
                return_when_dearer: true,
                contact: None,
            });
        }
    }
    // The other contact model, where the weights touch, in the cheapest
    // frame: at the study's tolerance and at 1e-10.
    if let Some(model) = study_contact(plan) {
        let other = match model {
            ContactModel::Penalty => ContactModel::Rigid,
            ContactModel::Rigid => ContactModel::Penalty,
        };
        let fidelity = if rotating_frame_obstacle(&probe).is_none() {
            Fidelity::Rotating
        } else {
            Fidelity::Full
        };
        for rtol in [plan.file.solver.rtol, 1e-10] {
            v.push(Setting {
                fidelity,
                method: MethodChoice::Fixed(Method::Dp5),
                rtol,
                return_when_dearer: true,
                contact: Some(other),
            });
        }
    }
    // Where inertial runs may return from Radau5, the same runs kept on
    // Radau5, at the study's tolerance: what the return costs in answers.
    let solver = &plan.file.solver;
    if solver.implicit_fallback && solver.return_when_dearer {
        v.push(Setting {
            fidelity: Fidelity::Full,
            method: MethodChoice::Fixed(Method::Dp5),
            rtol: solver.rtol,
            return_when_dearer: false,
            contact: None,
        });
    }
    v
}

/// The setting every other is measured against: the inertial equations with
/// DOP853 at rtol 1e-11, with the study's contact model.
pub fn reference(_plan: &StudyPlan) -> Setting {
    Setting {
        fidelity: Fidelity::Full,
        method: MethodChoice::Fixed(Method::Dop853),
        rtol: 1e-11,
        return_when_dearer: true,
        contact: None,
    }
}

/// The study's contact model, when its weights can touch (contact on and
/// the first design's weights have a size).
fn study_contact(plan: &StudyPlan) -> Option<ContactModel> {
    let spec = plan.file.scene.effects.contact.as_ref()?;
    let sized = plan
        .scene(&plan.designs[0], 0.0, 0.0)
        .cargoes()
        .ok()?
        .iter()
        .any(|c| c.radius > 0.0);
    (spec.enabled && sized).then_some(spec.model())
}

/// Run `run_id` of the plan at a setting (early stop as the study says).
fn simulate(plan: &StudyPlan, run_id: u64, setting: Setting) -> (RunMetrics, f64) {
    let samples = u64::from(plan.file.sampling.samples);
    let design = &plan.designs[(run_id / samples) as usize];
    let (_, mut sim) = sample_simulation(plan, design, run_id % samples);
    sim.solver.fidelity = setting.fidelity;
    sim.solver.method = setting.method;
    sim.solver.return_when_dearer = setting.return_when_dearer;
    if let (Some(model), Some(contact)) = (setting.contact, sim.scene.effects.contact.as_mut()) {
        *contact = contact.switched_to(model);
    }
    if setting.rtol > 0.0 {
        sim.solver.rtol = setting.rtol;
        sim.solver.atol = None;
    }
    let clock = Instant::now();
    let metrics = match sim.run(false) {
        Ok(r) => r.metrics,
        Err(e) => panic!("the plan validated every scene: {e}"),
    };
    (metrics, clock.elapsed().as_secs_f64())
}

fn sorted_angles(m: &RunMetrics) -> Vec<f64> {
    let mut v = m.final_rel_angles_deg.clone();
    v.sort_by(f64::total_cmp);
    v
}

/// Measure every setting on `runs` of the plan (run indices), serially so
/// that wall times are comparable.
pub fn measure(plan: &StudyPlan, runs: &[u64]) -> Vec<TradeoffRow> {
    let reference = reference(plan);
    let mut rows = Vec::new();
    let samples = u64::from(plan.file.sampling.samples);
    let horizon_revs = crate::decide::verdict::settling_horizon(plan);
    for &run_id in runs {
        let design_id = plan.designs[(run_id / samples) as usize].id;
        let (reference, _) = simulate(plan, run_id, reference);
        let ref_angles = sorted_angles(&reference);
        for setting in settings(plan) {
            let (m, wall) = simulate(plan, run_id, setting);
            let settling_error_revs = match (m.settling_revs, reference.settling_revs) {
                (Some(a), Some(b)) => Some((a - b).abs()),
                // Both agree that the run does not settle.
                (None, None) => Some(0.0),
                _ => None,
            };
            let angles = sorted_angles(&m);
            let angle_error_deg =
                (angles.len() == ref_angles.len() && !angles.is_empty()).then(|| {
                    angles
                        .iter()
                        .zip(&ref_angles)
                        .map(|(a, b)| {
                            let d = (a - b).rem_euclid(360.0);
                            d.min(360.0 - d)
                        })
                        .fold(0.0, f64::max)
                });
            rows.push(TradeoffRow {
                run_id,
                design_id,
                setting,
                settling_revs: m.settling_revs,
                reference_settling_revs: reference.settling_revs,
                horizon_revs,
                settling_error_revs,
                residual_error: (m.residual_rel - reference.residual_rel).abs(),
                angle_error_deg,
                outcome_agrees: m.outcome == reference.outcome,
                rhs_calls: m.rhs_calls,
                wall_time_s: wall,
                method_used: if m.method.is_empty() {
                    Method::Dp5.name().into()
                } else {
                    m.method.clone()
                },
            });
        }
    }
    rows
}

/// Aggregate rows per setting, in sweep order.
pub fn summarize(rows: &[TradeoffRow]) -> Vec<SettingSummary> {
    let mut out: Vec<SettingSummary> = Vec::new();
    let mut seen: Vec<Setting> = Vec::new();
    for r in rows {
        if !seen.contains(&r.setting) {
            seen.push(r.setting);
        }
    }
    for s in seen {
        let mine: Vec<&TradeoffRow> = rows.iter().filter(|r| r.setting == s).collect();
        let mut errs: Vec<f64> = mine.iter().filter_map(|r| r.settling_error_revs).collect();
        errs.sort_by(f64::total_cmp);
        let n = mine.len() as f64;
        out.push(SettingSummary {
            setting: s,
            median_error_revs: quantile_sorted(&errs, 0.5, Interpolation::Higher),
            max_error_revs: errs.last().copied(),
            max_residual_error: mine.iter().map(|r| r.residual_error).fold(0.0, f64::max),
            outcome_agreement: mine.iter().filter(|r| r.outcome_agrees).count() as f64 / n,
            mean_rhs_calls: mine.iter().map(|r| r.rhs_calls as f64).sum::<f64>() / n,
            mean_wall_time_s: mine.iter().map(|r| r.wall_time_s).sum::<f64>() / n,
            designs_ranked: 0,
            same_best: None,
            kendall_tau: None,
        });
        let decision = decision_agreement(&mine);
        let last = out.last_mut().expect("just pushed");
        (last.designs_ranked, last.same_best, last.kendall_tau) = decision;
    }
    out
}

/// How far a setting's ranking of the designs agrees with the reference's
/// on the same runs: each design ranked by its restricted mean settling time
/// (a run that does not settle counts as the horizon), then whether the two
/// #1 are the same design (ties: the first design) and Kendall's τ-b of the
/// two rankings. The decision a study takes, not a run's error, is what a
/// cheap rung must keep.
fn decision_agreement(rows: &[&TradeoffRow]) -> (usize, Option<bool>, Option<f64>) {
    let mut designs: Vec<u32> = rows.iter().map(|r| r.design_id).collect();
    designs.sort_unstable();
    designs.dedup();
    let censored = |t: Option<f64>, horizon: f64| t.map_or(horizon, |t| t.min(horizon));
    let means = |pick: &dyn Fn(&TradeoffRow) -> f64| -> Vec<f64> {
        designs
            .iter()
            .map(|&d| {
                let v: Vec<f64> = rows
                    .iter()
                    .filter(|r| r.design_id == d)
                    .map(|r| pick(r))
                    .collect();
                v.iter().sum::<f64>() / v.len() as f64
            })
            .collect()
    };
    let mine = means(&|r| censored(r.settling_revs, r.horizon_revs));
    let reference = means(&|r| censored(r.reference_settling_revs, r.horizon_revs));
    if designs.len() < 2 {
        return (designs.len(), None, None);
    }
    let best = |v: &[f64]| {
        (0..v.len())
            .min_by(|&a, &b| v[a].total_cmp(&v[b]))
            .expect("two designs")
    };
    (
        designs.len(),
        Some(best(&mine) == best(&reference)),
        crate::stats::kendall::kendall_tau_b(&mine, &reference),
    )
}

/// The cheapest setting (by mean wall time) whose largest settling error is
/// within `budget_revs`, whose residual error is within `budget_residual`
/// (units of A_ref; estimates, which give no residual, are judged on settling
/// only), whose outcomes all agree with the reference, and which ranks the
/// same design first (where two or more designs were measured).
pub fn recommend(
    summary: &[SettingSummary],
    budget_revs: f64,
    budget_residual: f64,
) -> Option<&SettingSummary> {
    summary
        .iter()
        .filter(|s| {
            s.outcome_agreement == 1.0 && s.max_error_revs.is_some_and(|e| e <= budget_revs)
        })
        .filter(|s| s.setting.rtol == 0.0 || s.max_residual_error <= budget_residual)
        .filter(|s| s.same_best != Some(false))
        .min_by(|a, b| a.mean_wall_time_s.total_cmp(&b.mean_wall_time_s))
}

/// The rows as a DataFrame (the columns `study plot tradeoff` reads).
pub fn rows_frame(rows: &[TradeoffRow]) -> PolarsResult<DataFrame> {
    DataFrame::new(
        rows.len(),
        vec![
            Column::new(
                "run_id".into(),
                rows.iter().map(|r| r.run_id).collect::<Vec<_>>(),
            ),
            Column::new(
                "design_id".into(),
                rows.iter().map(|r| r.design_id).collect::<Vec<_>>(),
            ),
            Column::new(
                "fidelity".into(),
                rows.iter()
                    .map(|r| r.setting.fidelity.name().to_string())
                    .collect::<Vec<_>>(),
            ),
            Column::new(
                "method".into(),
                rows.iter()
                    .map(|r| r.setting.method.name().to_string())
                    .collect::<Vec<_>>(),
            ),
            Column::new(
                "method_used".into(),
                rows.iter()
                    .map(|r| r.method_used.clone())
                    .collect::<Vec<_>>(),
            ),
            Column::new(
                "rtol".into(),
                rows.iter().map(|r| r.setting.rtol).collect::<Vec<_>>(),
            ),
            Column::new(
                "return_when_dearer".into(),
                rows.iter()
                    .map(|r| r.setting.return_when_dearer)
                    .collect::<Vec<_>>(),
            ),
            Column::new(
                "settling_revs".into(),
                rows.iter().map(|r| r.settling_revs).collect::<Vec<_>>(),
            ),
            Column::new(
                "reference_settling_revs".into(),
                rows.iter()
                    .map(|r| r.reference_settling_revs)
                    .collect::<Vec<_>>(),
            ),
            Column::new(
                "settling_error_revs".into(),
                rows.iter()
                    .map(|r| r.settling_error_revs)
                    .collect::<Vec<_>>(),
            ),
            Column::new(
                "residual_error".into(),
                rows.iter().map(|r| r.residual_error).collect::<Vec<_>>(),
            ),
            Column::new(
                "angle_error_deg".into(),
                rows.iter().map(|r| r.angle_error_deg).collect::<Vec<_>>(),
            ),
            Column::new(
                "outcome_agrees".into(),
                rows.iter().map(|r| r.outcome_agrees).collect::<Vec<_>>(),
            ),
            Column::new(
                "rhs_calls".into(),
                rows.iter().map(|r| r.rhs_calls).collect::<Vec<_>>(),
            ),
            Column::new(
                "wall_time_s".into(),
                rows.iter().map(|r| r.wall_time_s).collect::<Vec<_>>(),
            ),
        ],
    )
}

/// Write `tradeoff.parquet` under the study's output folder; returns its path.
pub fn write(
    plan: &StudyPlan,
    rows: &[TradeoffRow],
) -> Result<std::path::PathBuf, Box<dyn std::error::Error>> {
    let dir = crate::study::run::output_dir(plan, None);
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("tradeoff.parquet");
    let mut df = rows_frame(rows)?;
    write_parquet(
        &path,
        &mut df,
        &Provenance::new(&plan.text, plan.file.seed, "tradeoff"),
    )?;
    Ok(path)
}

/// Run indices spread evenly over the plan: `count` of them.
pub fn spread_runs(plan: &StudyPlan, count: u64) -> Vec<u64> {
    let total = plan.total_runs();
    let count = count.clamp(1, total);
    (0..count).map(|i| i * total / count).collect()
}
