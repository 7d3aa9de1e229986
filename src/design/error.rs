//! Typed errors for inputs outside the domain of the design formulas.

use thiserror::Error;

/// Why a design formula cannot be evaluated for the given inputs.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DesignError {
    /// No weights at all: every formula needs n ≥ 1.
    #[error("n = 0: an auto-balancer needs at least one weight (n ≥ 1)")]
    ZeroWeights,
    /// ρ = r/R must lie strictly between 0 and 1.
    #[error("ρ = {rho}: the radius ratio r/R must lie in the open interval (0, 1)")]
    RhoOutOfRange {
        /// The offending radius ratio.
        rho: f64,
    },
    /// n weights of radius ratio ρ do not fit on the race (nα > π).
    #[error(
        "ρ = {rho} exceeds ρ_max({n}) = {rho_max:.6}: {n} weights of that radius do not fit on the race"
    )]
    DoesNotFit {
        /// Number of weights.
        n: u32,
        /// Requested radius ratio.
        rho: f64,
        /// Largest radius ratio for which n weights fit.
        rho_max: f64,
    },
    /// A physical quantity that must be positive (and finite) is not.
    #[error("{name} = {value}: must be positive and finite")]
    NotPositive {
        /// Name of the quantity, e.g. "density γ".
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The position parameter p must lie in [0, 1].
    #[error("p = {0}: the position parameter must lie in [0, 1]")]
    POutOfRange(f64),
    /// A shape name that is neither `ball` nor `roller`.
    #[error("unknown weight shape '{0}': expected 'ball' or 'roller'")]
    UnknownShape(String),
    /// A named ρ rule that does not exist.
    #[error("rho = \"{0}\": expected a number, \"optimal\" or \"half_race\"")]
    UnknownRhoRule(String),
    /// The numerical optimiser failed (should not happen on the valid domain).
    #[error("optimisation of ρ for n = {n} failed: {reason}")]
    Optimizer {
        /// Number of weights.
        n: u32,
        /// What the optimiser reported.
        reason: String,
    },
}

impl DesignError {
    /// The design key the error is about, for messages that name it.
    pub fn key(&self) -> &'static str {
        match self {
            DesignError::ZeroWeights => "n",
            DesignError::RhoOutOfRange { .. }
            | DesignError::DoesNotFit { .. }
            | DesignError::UnknownRhoRule(_) => "rho",
            DesignError::UnknownShape(_) => "kind",
            DesignError::NotPositive { .. }
            | DesignError::POutOfRange(_)
            | DesignError::Optimizer { .. } => "",
        }
    }
}

/// Return `value` if it is positive and finite, else a [`DesignError::NotPositive`].
pub fn require_positive(name: &'static str, value: f64) -> Result<f64, DesignError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(DesignError::NotPositive { name, value })
    }
}
