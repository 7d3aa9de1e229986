//! What a user asks of the solver for one run (fidelity, method, tolerances,
//! budget) and how the dimensionless tolerance maps onto the state.

use crate::integrate::Method;
use crate::invalid_key::InvalidKey;
use crate::model::system::RotorSystem;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Integrator choice and accuracy.
///
/// `atol` is relative to the problem's scales: displacements get atol·A_ref,
/// velocities atol·A_ref·ω, angles atol (rad), angular rates atol·ω. The
/// settled amplitude sits at a noise floor of roughly 10–300 × the absolute
/// tolerance, so atol·A_ref must stay far below δ·A_ref. Unless a file sets
/// it, atol = rtol/100 (1e-8 at the default rtol = 1e-6, four decades under
/// δ = 0.05): tightening rtol then tightens atol with it, so the answer
/// converges. A fixed atol with a much smaller rtol would leave the residual
/// at the absolute tolerance's noise floor, and Radau5, which maps its
/// tolerances as Hairer does (atol/rtol kept), would even loosen it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSettings {
    /// Formulation: analytic, rotating, full, or auto (rotating when exact for the scene).
    pub fidelity: Fidelity,
    /// Integration method: `auto` (dp5, or dop853 below rtol 1e-7, handing
    /// over to radau5 where the run turns stiff; radau5 from the start with
    /// a stiff effect such as rolling resistance), or `dp5`, `dop853`, `radau5`.
    pub method: MethodChoice,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance relative to the problem's scales (see above);
    /// `None`: rtol/100.
    #[schemars(
        description = "Absolute tolerance relative to the problem's scales (displacements atol·A_ref, velocities atol·A_ref·ω, angles atol rad, angular rates atol·ω); rtol/100 when absent."
    )]
    pub atol: Option<f64>,
    /// Step budget (accepted plus rejected) per integration segment.
    pub max_steps: u64,
    /// Wall-time budget of one run (s): a run that takes longer is recorded
    /// as `budget_exceeded` and the study goes on.
    pub max_wall_seconds: f64,
    /// When an explicit method finds the problem stiff, runs out of steps or
    /// underflows its step size, continue the run from there with Radau5 and
    /// record the switch (`method` becomes e.g. "dp5→radau5").
    pub implicit_fallback: bool,
    /// After that hand-over, return to the explicit method for the rest of
    /// the run when Radau5 makes more than 3 times the RHS calls per
    /// simulated second the explicit method made over its last 16 steps (as
    /// on a contact law's kink); `method` becomes e.g. "dp5→radau5→dp5".
    pub return_when_dearer: bool,
    /// Radau5 solves its full Newton systems instead of the reduced ones of
    /// a second-order system (the reference for the reduction's test; not a
    /// file key).
    #[serde(skip)]
    pub full_newton: bool,
    /// Radau5 keeps dense reduced Newton matrices for a system with many
    /// weights instead of the structured ones (the reference for their
    /// test; not a file key).
    #[serde(skip)]
    pub dense_newton: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            fidelity: Fidelity::Auto,
            method: MethodChoice::Auto,
            rtol: 1e-6,
            atol: None,
            max_steps: 5_000_000,
            max_wall_seconds: 600.0,
            implicit_fallback: true,
            return_when_dearer: true,
            full_newton: false,
            dense_newton: false,
        }
    }
}

/// Per-component absolute tolerances for `system` (see [`SolverSettings`]).
pub fn scaled_atol(system: &RotorSystem, atol: f64, a_ref: f64, omega: f64) -> Vec<f64> {
    let lay = system.layout();
    let nq = lay.nq();
    let mut v = vec![atol; lay.dim()];
    for i in 0..lay.rotor_dof {
        v[i] = atol * a_ref;
        v[nq + i] = atol * a_ref * omega;
    }
    for i in lay.rotor_dof..nq {
        v[nq + i] = atol * omega;
    }
    v
}

/// Accepted relative tolerances: tighter than 1e-13 is below what double
/// precision resolves over a long run; looser than 1e-2 is no answer.
pub const RTOL_RANGE: (f64, f64) = (1e-13, 1e-2);

/// Accepted absolute tolerances (relative to the problem's scales).
pub const ATOL_RANGE: (f64, f64) = (1e-16, 1e-2);

impl SolverSettings {
    /// The absolute tolerance in effect: as given, or rtol/100.
    pub fn atol(&self) -> f64 {
        self.atol.unwrap_or(self.rtol / 100.0)
    }

    /// Check the tolerances and budget; on failure the key, the value and the rule.
    pub fn validate(&self) -> Result<(), InvalidKey> {
        let (lo, hi) = RTOL_RANGE;
        if !(lo..=hi).contains(&self.rtol) {
            return Err(InvalidKey::new(
                "solver.rtol",
                self.rtol.to_string(),
                format!("must lie in [{lo:e}, {hi:e}]"),
            ));
        }
        let (lo, hi) = ATOL_RANGE;
        if let Some(atol) = self.atol
            && !(lo..=hi).contains(&atol)
        {
            return Err(InvalidKey::new(
                "solver.atol",
                atol.to_string(),
                format!(
                    "must lie in [{lo:e}, {hi:e}] (relative to the problem's scales; leave it out for rtol/100)"
                ),
            ));
        }
        if self.max_steps == 0 {
            return Err(InvalidKey::new("solver.max_steps", "0", "must be positive"));
        }
        // A year at most: a deadline beyond the clock's range (1e308 s)
        // overflowed the instant it is added to.
        if !(self.max_wall_seconds > 0.0 && self.max_wall_seconds <= 31_536_000.0) {
            return Err(InvalidKey::new(
                "solver.max_wall_seconds",
                crate::model::validate::shown(self.max_wall_seconds),
                "must be a positive number of seconds, a year (31 536 000 s) at most",
            ));
        }
        Ok(())
    }
}

/// The integrator a study asks for: `"auto"` or any method's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(try_from = "String", into = "String")]
pub enum MethodChoice {
    /// An explicit method chosen by tolerance, handing over to Radau5 where
    /// the problem turns stiff (see [`MethodChoice::resolve`]).
    #[default]
    Auto,
    /// That method in every frame.
    Fixed(Method),
}

/// Below this rtol `auto` takes DOP853, from it up DP5: on the main job's
/// designs the two tie at rtol 1e-6 (1.11 and 1.09 ms per run), DOP853 takes
/// 0.85× DP5's time at 1e-8 and 0.76× at 1e-9 (docs/benchmarks.md).
pub const AUTO_DOP853_BELOW_RTOL: f64 = 1e-7;

impl MethodChoice {
    /// The method for a run at relative tolerance `rtol`. For `auto`: DP5
    /// (DOP853 below [`AUTO_DOP853_BELOW_RTOL`]), handing over to Radau5 if
    /// Hairer's stiffness test fires; but Radau5 from the start when the
    /// caller knows the run is stiff (`implicit_from_start`): a scene effect
    /// that is stiff by construction (rolling resistance's regularisation,
    /// whose stiffness Hairer's test missed in 6 % of runs, which then took
    /// 800 000 DP5 steps), or a run that sits at a fixed point for long (the
    /// rotating frame, where the balanced state is a fixed point, without
    /// early stop).
    /// There an explicit method keeps resolving a whirl that has decayed
    /// below the tolerance in steps of 1/(ω + ω_n), while Radau5 steps across
    /// it: 11× fewer RHS calls over 10 000 revolutions. With early stop the
    /// run ends 50 revolutions after settling, the transient dominates, and
    /// the explicit start is the cheaper: 0.65× Radau5's time per run on the
    /// main job at rtol 1e-6 (docs/benchmarks.md).
    pub fn resolve(self, rtol: f64, implicit_from_start: bool) -> Method {
        match self {
            MethodChoice::Auto if implicit_from_start => Method::Radau5,
            MethodChoice::Auto if rtol < AUTO_DOP853_BELOW_RTOL => Method::Dop853,
            MethodChoice::Auto => Method::Dp5,
            MethodChoice::Fixed(method) => method,
        }
    }

    /// Name in files: "auto" or the method's.
    pub fn name(self) -> &'static str {
        match self {
            MethodChoice::Auto => "auto",
            MethodChoice::Fixed(method) => method.name(),
        }
    }
}

impl TryFrom<String> for MethodChoice {
    type Error = String;

    fn try_from(name: String) -> Result<Self, String> {
        if name == "auto" {
            return Ok(MethodChoice::Auto);
        }
        name.parse().map(MethodChoice::Fixed).map_err(|_| {
            let known: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
            format!(
                "unknown method `{name}`, expected `auto` or one of `{}`",
                known.join("`, `")
            )
        })
    }
}

impl From<MethodChoice> for String {
    fn from(choice: MethodChoice) -> String {
        choice.name().to_string()
    }
}

/// Which formulation computes a run (the fidelity ladder, cheapest first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// Closed-form slow mode (quasi-static, `model::quasi_static`): microseconds,
    /// a settling estimate ln(1/δ)/|Re λ| and nothing else.
    Analytic,
    /// Eigenvalues of the linearisation about the balanced state
    /// (`model::linear`): stability and the slowest decay rate σ; a settling
    /// estimate ln((r₀/A_ref)/δ)/σ. Milliseconds.
    Linear,
    /// Exact equations in the rotor-fixed frame: autonomous for isotropic
    /// supports at constant speed without in-plane gravity.
    Rotating,
    /// Exact equations in the inertial frame: anything.
    Full,
    /// `rotating` when the scene allows it, `full` otherwise.
    #[default]
    Auto,
}

impl Fidelity {
    /// snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Analytic => "analytic",
            Fidelity::Linear => "linear",
            Fidelity::Rotating => "rotating",
            Fidelity::Full => "full",
            Fidelity::Auto => "auto",
        }
    }

    /// A rung that predicts settling in closed form or from the linear
    /// analysis, integrating nothing: its runs are estimates.
    pub fn is_estimate(self) -> bool {
        matches!(self, Fidelity::Analytic | Fidelity::Linear)
    }
}

#[cfg(test)]
mod doc_tests {
    /// The file key's documentation (doc comment, hence the JSON schema and
    /// editors' hints) gives the margin the integrator uses.
    #[test]
    fn the_documented_return_margin_is_the_integrators() {
        let schema =
            serde_json::to_string(&schemars::schema_for!(super::SolverSettings)).expect("a schema");
        let says = format!("more than {} times", crate::integrate::DEARER_BY);
        assert!(schema.contains(&says), "the schema does not say {says:?}");
    }
}
