//! What a run's outcome is, defined once and used by every report.
//!
//! Definitions (also in `docs/metrics.md`):
//! - A_ref = U ω² / |k_x − M_Σ ω² + i b_x ω|: the vibration amplitude the
//!   rotor's own unbalance U = M e would cause with the balancer locked
//!   (U = Σ m_j l_j when e = 0, so that the scale stays meaningful). For a
//!   rotor with several coordinates: the largest balancer-plane orbit radius
//!   of that locked response (`reference::a_ref`).
//! - r(t) = sqrt(x² + y²) (the largest balancer-plane displacement for other
//!   rotors); ε(t) = |Σ m_j l_j e^{iψ_j} + M e e^{iψ₀}| / U (the size of the
//!   total unbalance, e.g. the largest bearing-equivalent one, over U).
//! - Settling time t_s: the start of the first stretch during which
//!   r ≤ δ·A_ref holds continuously for W revolutions, judged only once the
//!   rotor runs at its operating speed (after a ramp; for a motor or a free
//!   rotor, once φ̇ is within δ of the nominal speed), checked on dense output
//!   at `samples_per_rev` points per revolution (≥ 32). A run stops early
//!   once the hold is satisfied. The same rule on ε ≤ δ gives t_s(ε). t_s is
//!   resolved to one sampling interval, reported as `settling_time_err`.
//!   A run that reaches its end without a complete hold is censored: its
//!   t_s is only known to exceed `censoring_revs`.
//! - Residual vibration: RMS of r over the last W revolutions simulated,
//!   absolute and relative to A_ref.
//! - Outcome: settled, censored (simulated to the end without settling),
//!   not_settled (an estimate that predicts no settling), diverged
//!   (non-finite state, or r beyond `divergence_factor` times the larger of
//!   A_ref and the whirl (U + Σ m l)/U · A_ref the weights can drive) or
//!   solver_failed, or merged (two identical weights coincided exactly, a
//!   state the equations never leave), each with a reason.
//!
//! A "revolution" is 2π/ω at the scene's nominal speed (the constant speed,
//! the ramp's final speed or the motor's synchronous speed).

use crate::integrate::Failure;
use crate::invalid_key::InvalidKey;
pub mod balance_angle;
pub mod bearing_orbit;
pub mod certify;
pub mod never_settles;
pub mod observer;
pub mod peak_whirl;
pub mod reference;

use crate::model::speed::SpeedLaw;
use crate::model::validate::SceneError;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Parameters of the metric definitions (docs/metrics.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct MetricOptions {
    /// Settling band δ as a fraction of A_ref (and of U for ε).
    pub delta: f64,
    /// Hold window W in revolutions.
    pub hold_revs: f64,
    /// Run length T_end in revolutions.
    pub t_end_revs: f64,
    /// Dense-output samples per revolution (at least [`MIN_SAMPLES_PER_REV`] = 32).
    pub samples_per_rev: u32,
    /// Stop the run as soon as the hold is satisfied.
    pub stop_when_settled: bool,
    /// r beyond this multiple of max(A_ref, (U + Σ m l)/U · A_ref) counts as divergence.
    pub divergence_factor: f64,
    /// End a settled run's hold window early once the linearised flow,
    /// checked against the run, bounds the rest of it (rotating frame with
    /// early stop; docs/metrics.md, "Certified hold").
    pub certified_hold: bool,
    /// End a run early as `not_settled` once its state repeats every
    /// revolution, contracting, outside the band or below the operating
    /// speed (early stop; docs/metrics.md, "Certified not settled").
    pub certified_not_settled: bool,
}

impl Default for MetricOptions {
    fn default() -> Self {
        MetricOptions {
            delta: 0.05,
            hold_revs: 50.0,
            t_end_revs: 2000.0,
            samples_per_rev: 32,
            stop_when_settled: true,
            divergence_factor: 1e4,
            certified_hold: true,
            certified_not_settled: true,
        }
    }
}

/// Fewest dense-output samples per revolution the settling rule accepts.
pub const MIN_SAMPLES_PER_REV: u32 = 32;

/// How a run ended, in physical terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// r stayed within δ·A_ref for the whole hold window at the operating speed.
    Settled,
    /// The run reached its end without a complete hold: t_s exceeds the
    /// censoring time; never counted as settled.
    Censored,
    /// A closed-form or linear estimate that predicts no settling.
    NotSettled,
    /// The state became non-finite or r exceeded the divergence bound.
    Diverged,
    /// The run exhausted its step or wall-time budget.
    BudgetExceeded,
    /// The integrator could not continue (step-size underflow, Newton failure).
    SolverFailed,
    /// Two identical weights coincided exactly (angle and rate): the
    /// equations keep identical weights together for ever, which no real
    /// pair of weights does, so the rest of the run is not physics and it
    /// ends here (docs/model.md, "Identical weights that meet").
    Merged,
}

impl Outcome {
    /// Every outcome, in the order of the summary's count columns.
    pub const ALL: [Outcome; 7] = [
        Outcome::Settled,
        Outcome::Censored,
        Outcome::NotSettled,
        Outcome::Diverged,
        Outcome::BudgetExceeded,
        Outcome::SolverFailed,
        Outcome::Merged,
    ];

    /// The outcome of a name written by [`Outcome::name`]; `None` for
    /// another text. The one place, with `name`, where outcomes are strings.
    pub fn parse(name: &str) -> Option<Outcome> {
        Outcome::ALL.into_iter().find(|o| o.name() == name)
    }

    /// A run the solver could not finish (out of budget, or failed): counted
    /// as not settled in every settling statistic and named in the
    /// failure advice. Divergence and merging are physics, not failures.
    pub fn is_failure(self) -> bool {
        matches!(self, Outcome::SolverFailed | Outcome::BudgetExceeded)
    }

    /// True for the outcomes whose run reached a residual the metrics
    /// describe (settled, censored, not settled), false for a run that
    /// failed, diverged or merged. An estimate's `not_settled` measured
    /// nothing: [`RunMetrics::has_measured_residual`] tells them apart.
    pub fn has_residual(self) -> bool {
        matches!(
            self,
            Outcome::Settled | Outcome::Censored | Outcome::NotSettled
        )
    }

    /// snake_case name used in files.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Settled => "settled",
            Outcome::Censored => "censored",
            Outcome::NotSettled => "not_settled",
            Outcome::Diverged => "diverged",
            Outcome::BudgetExceeded => "budget_exceeded",
            Outcome::SolverFailed => "solver_failed",
            Outcome::Merged => "merged",
        }
    }
}

/// Which budget a run exceeded, from the reason it records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Budget {
    /// `[solver] max_steps`.
    Steps,
    /// `[solver] max_wall_seconds`.
    WallTime,
}

impl Budget {
    /// The budget a solver failure exhausted, if it was a budget.
    pub fn of_failure(failure: &Failure) -> Option<Budget> {
        match failure {
            Failure::TooManySteps { .. } => Some(Budget::Steps),
            Failure::WallTimeExceeded { .. } => Some(Budget::WallTime),
            _ => None,
        }
    }

    /// The budget named by a `budget_exceeded` run's recorded reason (the
    /// failure's text, as [`Budget::of_failure`] classed it when written).
    pub fn of_reason(reason: &str) -> Budget {
        if reason.contains("wall-time") {
            Budget::WallTime
        } else {
            Budget::Steps
        }
    }
}

/// Every metric of one run (the fields of `study simulate --json`).
#[derive(Clone, PartialEq, Serialize)]
pub struct RunMetrics {
    /// True when the settling rule on r was met.
    pub settled: bool,
    /// Settling time t_s on r (s), if settled.
    pub settling_time: Option<f64>,
    /// t_s in revolutions.
    pub settling_revs: Option<f64>,
    /// Resolution of t_s (one sampling interval, s).
    pub settling_time_err: f64,
    /// Settling time on the balancing error ε ≤ δ (s), if met.
    pub settling_time_eps: Option<f64>,
    /// True when the band held for the whole window W (false: only until the end of the run).
    pub hold_complete: bool,
    /// True when a certified hold ended the run before the window's end
    /// (`metrics.certified_hold`): the rest of the window is bounded on the
    /// linearised flow, and the final state is the one at that earlier end.
    pub hold_certified: bool,
    /// RMS of r over the last W revolutions.
    pub residual_abs: f64,
    /// residual_abs / A_ref.
    pub residual_rel: f64,
    /// Reference amplitude A_ref.
    pub a_ref: f64,
    /// Balancing error ε at the end of the run.
    pub balancing_error: f64,
    /// Largest r seen.
    pub peak_r: f64,
    /// Final cargo angles relative to the rotor, degrees in [0, 360).
    pub final_rel_angles_deg: Vec<f64>,
    /// Position parameter p (eq 2 of seed 000) of the final cargo angles.
    pub p_final: f64,
    /// Outcome class.
    pub outcome: Outcome,
    /// Why the run ended as it did.
    pub reason: String,
    /// Time simulated (s).
    pub t_final: f64,
    /// Accepted integrator steps.
    pub steps: u64,
    /// Right-hand-side evaluations.
    pub rhs_calls: u64,
    /// Integrator that produced the result ("dp5", or "dp5→radau5" after an automatic switch).
    pub method: String,
    /// Formulation that produced it ("rotating", "full", "analytic").
    pub fidelity: String,
    /// How contact between the weights was modelled ("rigid" or
    /// "penalty"); `None` when the run models none (contact off, point
    /// masses, or an estimate).
    pub contact_model: Option<&'static str>,
    /// Smallest gap between two weights of one plane over the sampled run
    /// (rad of centre angle beyond touching, 2α); negative: they overlapped.
    /// `None` for point masses, which have no size.
    pub min_gap_rad: Option<f64>,
    /// The same gap at the end of the run.
    pub final_min_gap_rad: Option<f64>,
    /// For a censored run: its settling time is known to exceed this many
    /// revolutions (the end of the run less the hold window, and no earlier
    /// than the operating point).
    pub censoring_revs: Option<f64>,
    /// When the speed first reached its operating value (s): 0 at constant
    /// speed, the ramp's end, or for a motor the first sample with
    /// |φ̇ − ω| ≤ δ·ω; `None` if it never did (captured below it).
    pub operating_time: Option<f64>,
    /// Spin rate φ̇ at the end of the run (rad/s); `None` for estimates.
    pub final_spin_rate: Option<f64>,
    /// The weights' mean angular rate relative to the rotor at the end of
    /// the run (rad/s, negative: behind it): about 0 for weights that
    /// settled or stopped in the race, far from 0 for a pack that
    /// circulates; `None` for estimates.
    pub pack_slip_rate: Option<f64>,
    /// With rolling resistance: the largest angle (degrees) between a
    /// weight's final position and the balanced position nearest the final
    /// ones (`None` without it, at variable speed, or with no balanced state
    /// near).
    pub balance_angle_error_deg: Option<f64>,
    /// A_ref of each watched plane (m; rotors with several planes: the
    /// balancer planes, then the load's planes; docs/metrics.md).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plane_a_ref: Option<Vec<f64>>,
    /// The residual of each watched plane: the RMS of its whirl over the
    /// last hold window (m), in the order of `plane_a_ref`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plane_residual_abs: Option<Vec<f64>>,
    /// When each watched plane's whirl entered its own band δ·A_ref of the
    /// plane for good (revolutions from t₀, the hold met), in the order of
    /// `plane_a_ref`; `None` for a plane that did not settle. The run
    /// settles only when every plane has.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plane_settling_revs: Option<Vec<Option<f64>>>,
    /// ε per balancer plane at the end of the run: the unbalance left, as
    /// equivalent unbalances in each balancer plane, over U (two balancer
    /// planes on two supports; `None` elsewhere).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plane_balancing_error: Option<Vec<f64>>,
    /// Peak radial displacement of each bearing over the revolution after
    /// the run (m; rotors with bearings of their own, in support order;
    /// `src/metrics/bearing_orbit.rs`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bearing_orbit_peak: Option<Vec<f64>>,
    /// RMS radial displacement of each bearing over the same revolution (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bearing_orbit_rms: Option<Vec<f64>>,
}

/// As derived, but the per-plane fields are shown only for rotors with
/// several planes: the golden files print metrics with `{:?}`, and a plane
/// rotor's run must print exactly what it printed before they existed.
impl std::fmt::Debug for RunMetrics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("RunMetrics");
        s.field("settled", &self.settled);
        s.field("settling_time", &self.settling_time);
        s.field("settling_revs", &self.settling_revs);
        s.field("settling_time_err", &self.settling_time_err);
        s.field("settling_time_eps", &self.settling_time_eps);
        s.field("hold_complete", &self.hold_complete);
        s.field("hold_certified", &self.hold_certified);
        s.field("residual_abs", &self.residual_abs);
        s.field("residual_rel", &self.residual_rel);
        s.field("a_ref", &self.a_ref);
        s.field("balancing_error", &self.balancing_error);
        s.field("peak_r", &self.peak_r);
        s.field("final_rel_angles_deg", &self.final_rel_angles_deg);
        s.field("p_final", &self.p_final);
        s.field("outcome", &self.outcome);
        s.field("reason", &self.reason);
        s.field("t_final", &self.t_final);
        s.field("steps", &self.steps);
        s.field("rhs_calls", &self.rhs_calls);
        s.field("method", &self.method);
        s.field("fidelity", &self.fidelity);
        s.field("contact_model", &self.contact_model);
        s.field("min_gap_rad", &self.min_gap_rad);
        s.field("final_min_gap_rad", &self.final_min_gap_rad);
        s.field("censoring_revs", &self.censoring_revs);
        s.field("operating_time", &self.operating_time);
        s.field("final_spin_rate", &self.final_spin_rate);
        s.field("pack_slip_rate", &self.pack_slip_rate);
        s.field("balance_angle_error_deg", &self.balance_angle_error_deg);
        if let Some(a) = &self.plane_a_ref {
            s.field("plane_a_ref", a);
        }
        if let Some(r) = &self.plane_residual_abs {
            s.field("plane_residual_abs", r);
        }
        if let Some(r) = &self.plane_settling_revs {
            s.field("plane_settling_revs", r);
        }
        if let Some(e) = &self.plane_balancing_error {
            s.field("plane_balancing_error", e);
        }
        if let Some(p) = &self.bearing_orbit_peak {
            s.field("bearing_orbit_peak", p);
        }
        if let Some(r) = &self.bearing_orbit_rms {
            s.field("bearing_orbit_rms", r);
        }
        s.finish()
    }
}

impl RunMetrics {
    /// Whether the run measured its residual, the RMS of r over its last
    /// hold window: a settled or censored run, or one integrated and
    /// certified not to settle (an estimate's `not_settled` took no step
    /// and measured nothing), with a finite value.
    pub fn has_measured_residual(&self) -> bool {
        let measured = match self.outcome {
            Outcome::Settled | Outcome::Censored => true,
            Outcome::NotSettled => self.steps > 0,
            _ => false,
        };
        measured && self.residual_abs.is_finite()
    }

    /// Metrics of a run that was not integrated (a closed-form estimate, or
    /// a run that could not be simulated at all): nothing settled, no
    /// residual, no work; estimates fill in what they know.
    pub fn not_integrated(a_ref: f64, outcome: Outcome, reason: String, method: &str) -> Self {
        RunMetrics {
            settled: false,
            settling_time: None,
            settling_revs: None,
            settling_time_err: 0.0,
            settling_time_eps: None,
            hold_complete: false,
            hold_certified: false,
            residual_abs: 0.0,
            residual_rel: 0.0,
            a_ref,
            balancing_error: 0.0,
            peak_r: 0.0,
            final_rel_angles_deg: Vec::new(),
            p_final: 0.0,
            outcome,
            reason,
            t_final: 0.0,
            steps: 0,
            rhs_calls: 0,
            method: method.to_string(),
            fidelity: String::new(),
            contact_model: None,
            min_gap_rad: None,
            final_min_gap_rad: None,
            censoring_revs: None,
            operating_time: None,
            final_spin_rate: None,
            pack_slip_rate: None,
            balance_angle_error_deg: None,
            plane_a_ref: None,
            plane_residual_abs: None,
            plane_settling_revs: None,
            plane_balancing_error: None,
            bearing_orbit_peak: None,
            bearing_orbit_rms: None,
        }
    }
}

/// Longest horizon a run may have (revolutions).
pub const MAX_REVS: f64 = 1e7;
/// Most samples of a hold window (the ring every run keeps).
pub const MAX_WINDOW_SAMPLES: f64 = 1e7;

impl MetricOptions {
    /// Check each definition's parameter; on failure the key, the value and the rule.
    pub fn validate(&self) -> Result<(), InvalidKey> {
        let fail = |key, value: f64, rule: &str| {
            Err(InvalidKey::new(
                key,
                crate::model::validate::shown(value),
                rule.to_string(),
            ))
        };
        if !(self.delta > 0.0 && self.delta < 1.0) {
            return fail(
                "metrics.delta",
                self.delta,
                "must lie strictly between 0 and 1 (a fraction of A_ref)",
            );
        }
        if !(self.hold_revs.is_finite() && self.hold_revs > 0.0) {
            return fail(
                "metrics.hold_revs",
                self.hold_revs,
                "must be a positive number of revolutions",
            );
        }
        if !(self.t_end_revs.is_finite() && self.t_end_revs > 0.0) {
            return fail(
                "metrics.t_end_revs",
                self.t_end_revs,
                "must be a positive number of revolutions",
            );
        }
        if !(self.divergence_factor.is_finite() && self.divergence_factor > 1.0) {
            return fail(
                "metrics.divergence_factor",
                self.divergence_factor,
                "must be a finite multiple of A_ref above 1",
            );
        }
        if !(MIN_SAMPLES_PER_REV..=100_000).contains(&self.samples_per_rev) {
            return fail(
                "metrics.samples_per_rev",
                f64::from(self.samples_per_rev),
                "must lie in [32, 100000]: fewer samples cannot resolve the whirl, which turns once per revolution",
            );
        }
        if self.t_end_revs > MAX_REVS {
            return fail(
                "metrics.t_end_revs",
                self.t_end_revs,
                &format!(
                    "at most {MAX_REVS:e} revolutions: no run can take the steps a longer horizon needs (solver.max_steps)"
                ),
            );
        }
        // The hold window's samples are kept in memory, per run and thread.
        let window = self.hold_revs * f64::from(self.samples_per_rev);
        if window > MAX_WINDOW_SAMPLES {
            return fail(
                "metrics.hold_revs",
                self.hold_revs,
                &format!(
                    "hold_revs × samples_per_rev = {window:e} samples, more than the {MAX_WINDOW_SAMPLES:e} a run keeps in memory (8 bytes each, per plane and thread); shorten the hold or sample less often"
                ),
            );
        }
        Ok(())
    }

    /// A run must be long enough to show settling at its operating point:
    /// t_end ≥ (end of the speed ramp) + hold window. Checked before any run.
    pub fn check_horizon(&self, speed: &SpeedLaw) -> Result<(), SceneError> {
        let omega = speed.nominal_speed();
        let rev = 2.0 * std::f64::consts::PI / omega;
        let t_op = speed.operating_time().unwrap_or(0.0);
        let needed = t_op + self.hold_revs * rev;
        let t_end = self.t_end_revs * rev;
        if omega > 0.0 && t_end < needed {
            return Err(SceneError::Invalid {
                field: "metrics.t_end_revs".into(),
                value: self.t_end_revs.to_string(),
                reason: format!(
                    "the run would end at t = {t_end:.4} s, before the speed reaches its operating value (t = {t_op} s) plus the hold window ({:.4} s): settling could not be judged; use t_end_revs ≥ {}",
                    self.hold_revs * rev,
                    (needed / rev).ceil()
                ),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{Budget, Failure, Outcome};

    /// Every name reads back as its outcome, and nothing else reads as one.
    #[test]
    fn outcome_names_round_trip() {
        for o in Outcome::ALL {
            assert_eq!(Outcome::parse(o.name()), Some(o));
        }
        assert_eq!(Outcome::parse("failed"), None);
        assert_eq!(Outcome::parse("Settled"), None);
    }

    /// Failures are the solver's: divergence and merging are physics, and
    /// they are the outcomes without a residual that are not failures.
    #[test]
    fn failures_are_the_solvers_alone() {
        let failures: Vec<Outcome> = Outcome::ALL
            .into_iter()
            .filter(|o| o.is_failure())
            .collect();
        assert_eq!(
            failures,
            vec![Outcome::BudgetExceeded, Outcome::SolverFailed]
        );
        for o in Outcome::ALL {
            assert!(!(o.is_failure() && o.has_residual()), "{o:?}");
        }
        // The reader recovers from the written text what the writer typed.
        let failures = [
            Failure::TooManySteps { t: 1.5, max: 150 },
            Failure::WallTimeExceeded {
                t: 1.2,
                limit_s: 5.0,
            },
            Failure::StepSizeUnderflow { t: 0.1, h: 1e-300 },
        ];
        for f in &failures {
            match Budget::of_failure(f) {
                Some(b) => assert_eq!(Budget::of_reason(&f.to_string()), b, "{f}"),
                None => assert!(matches!(f, Failure::StepSizeUnderflow { .. })),
            }
        }
        assert_eq!(Budget::of_failure(&failures[1]), Some(Budget::WallTime));
    }
}

/// The share of the rotor's speed a pack's slip rate must reach for its
/// weights to count as circulating ([`circulates`]): 10 %, far above the
/// creep of weights that settled or stopped (≈ 0) and far below the
/// trapped washer pack that ran 99 rad/s behind a 147 rad/s drum.
pub const CIRCULATING_SLIP_SHARE: f64 = 0.1;

/// Whether a run's weights circulate instead of balancing: the run did not
/// settle and, at its end, the pack moved relative to the rotor at
/// [`CIRCULATING_SLIP_SHARE`] or more of the rotor's speed.
pub fn circulates(metrics: &RunMetrics) -> bool {
    circulating(
        metrics.settled,
        metrics.pack_slip_rate,
        metrics.final_spin_rate,
    )
}

/// [`circulates`] on the columns of runs.parquet (`settled`,
/// `pack_slip_rate`, `final_spin_rate`).
pub fn circulating(settled: bool, slip: Option<f64>, spin: Option<f64>) -> bool {
    match (slip, spin) {
        (Some(slip), Some(spin)) => {
            !settled && spin.abs() > 0.0 && slip.abs() >= CIRCULATING_SLIP_SHARE * spin.abs()
        }
        _ => false,
    }
}

#[cfg(test)]
mod circulation_tests {
    use super::circulating;

    /// The washer's trapped pack (99 rad/s behind a 147 rad/s drum)
    /// circulates; a settled pack, a slow creep and a run that settled
    /// despite slipping do not; a run without the rates is not judged.
    #[test]
    fn a_pack_circulates_only_when_it_slips_and_did_not_settle() {
        assert!(circulating(false, Some(-99.0), Some(146.6)));
        assert!(!circulating(false, Some(-0.05), Some(146.6)));
        assert!(!circulating(true, Some(-99.0), Some(146.6)));
        assert!(!circulating(false, None, Some(146.6)));
        assert!(!circulating(false, Some(-99.0), Some(0.0)));
    }
}
