//! The `[optimize]` table of a study file: objective, free variables, bounds
//! and constraints (documented in `docs/optimize.md`).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What the optimiser maximises or minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// Analytic dimensional capacity S_AB (maximised): Table 1 of seed 000.
    Capacity,
    /// Analytic transient measure ã (eqs 15/16, maximised).
    ATilde,
    /// Restricted mean settling time in revolutions over a Monte Carlo sample
    /// (minimised): a run that does not settle counts as the horizon
    /// t_end − hold, as in the summary's `settling_revs_rmst`.
    SettlingMean,
    /// Median settling time over every run (minimised; runs that do not
    /// settle count as the horizon, which makes it the Kaplan–Meier median).
    SettlingMedian,
    /// 90th percentile of the settling time in revolutions (minimised, same censoring).
    SettlingP90,
    /// Fraction of runs that settle (maximised).
    SettledFraction,
    /// Mean residual vibration relative to A_ref (minimised).
    Residual,
    /// 95th percentile of the absolute residual vibration `residual_abs` (m)
    /// over every run (minimised); a run without a measured residual
    /// (diverged, failed, out of budget) counts as +∞.
    ResidualP95,
    /// Share of runs whose absolute residual vibration is below
    /// `residual_spec` (maximised); a run without a measured residual fails.
    PResidualBelow,
}

impl Objective {
    /// True when larger values are better.
    pub fn maximise(self) -> bool {
        matches!(
            self,
            Objective::Capacity
                | Objective::ATilde
                | Objective::SettledFraction
                | Objective::PResidualBelow
        )
    }

    /// True when the value comes from simulation (and carries a Monte Carlo error).
    pub fn simulated(self) -> bool {
        !matches!(self, Objective::Capacity | Objective::ATilde)
    }

    /// The objective's unit as printed ("rev", "m", "kg·m"; empty for a
    /// share or a dimensionless measure).
    pub fn unit(self) -> &'static str {
        match self {
            Objective::Capacity => "kg·m",
            Objective::SettlingMean | Objective::SettlingMedian | Objective::SettlingP90 => "rev",
            Objective::Residual => "A_ref",
            Objective::ResidualP95 => "m",
            Objective::ATilde | Objective::SettledFraction | Objective::PResidualBelow => "",
        }
    }

    /// snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Objective::Capacity => "capacity",
            Objective::ATilde => "a_tilde",
            Objective::SettlingMean => "settling_mean",
            Objective::SettlingMedian => "settling_median",
            Objective::SettlingP90 => "settling_p90",
            Objective::SettledFraction => "settled_fraction",
            Objective::Residual => "residual",
            Objective::ResidualP95 => "residual_p95",
            Objective::PResidualBelow => "p_residual_below",
        }
    }
}

/// A continuous design variable the optimiser may move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Variable {
    /// Radius ratio ρ.
    Rho,
    /// Drag β.
    Drag,
}

/// The `[optimize]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OptimizeSpec {
    /// The objective.
    pub objective: Objective,
    /// Continuous variables: ["rho"] (Brent per kind and n) or ["rho", "drag"] (Nelder–Mead).
    #[serde(default = "rho_only")]
    pub free: Vec<Variable>,
    /// Bounds on ρ (default: (0.02, ρ_max(n))).
    #[serde(default)]
    pub rho_bounds: Option<crate::pair::Pair>,
    /// Bounds on β (N·s/m) when drag is free.
    #[serde(default)]
    pub drag_bounds: Option<crate::pair::Pair>,
    /// Largest ρ the housing allows (a torus-shaped race limits the weight radius).
    #[serde(default)]
    pub housing_rho_max: Option<f64>,
    /// Required capacity margin: capacity ≥ safety_factor × max_unbalance.
    #[serde(default)]
    pub safety_factor: Option<f64>,
    /// Largest unbalance the machine meets (kg·m), for the capacity constraint.
    #[serde(default)]
    pub max_unbalance: Option<f64>,
    /// Largest start-up whirl allowed: a candidate whose runs' median
    /// `peak_r / a_ref` (the summary's `peak_whirl_over_a_ref_median`, on
    /// the search's samples) exceeds it is infeasible. With an analytic
    /// objective the candidates are simulated for it.
    #[serde(default)]
    pub max_peak_over_a_ref: Option<f64>,
    /// Smallest weight count allowed (e.g. 3, as seed 000 recommends).
    #[serde(default)]
    pub min_n: Option<u32>,
    /// Monte Carlo samples per candidate (default: `sampling.samples`).
    #[serde(default)]
    pub samples: Option<u32>,
    /// Fresh samples on which every (kind, n) optimum of a simulated
    /// objective is evaluated again before the overall pick is made
    /// (default: four times the search's samples; 0 skips the confirmation).
    #[serde(default)]
    pub confirm_samples: Option<u32>,
    /// Objective evaluations per (kind, n) at most.
    #[serde(default = "default_evaluations")]
    pub max_evaluations: u64,
    /// The residual vibration a machine may show (m, against `residual_abs`):
    /// required by, and only used by, `objective = "p_residual_below"`.
    #[serde(default)]
    pub residual_spec: Option<f64>,
}

fn rho_only() -> Vec<Variable> {
    vec![Variable::Rho]
}

fn default_evaluations() -> u64 {
    25
}
