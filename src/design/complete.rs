//! The paper's "complete optimisation" of count and radius together (seed 000,
//! §5.3.2): grow the weights' radius continuously and remove a weight the
//! moment one becomes excess, until the housing limits the radius.

use super::Shape;
use super::capacity::dimensionless_capacity;
use super::error::DesignError;
use super::geometry::{check_basic, rho_half_race};
use super::optimum::optimal_rho;

/// One stage of the path: n weights while ρ grows from `rho_from` to `rho_to`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Stage {
    /// Number of weights during the stage.
    pub n: u32,
    /// ρ at which the stage starts.
    pub rho_from: f64,
    /// ρ at which it ends (a weight becomes excess, or the housing limit).
    pub rho_to: f64,
    /// Capacity s(n, ρ_to) at the end of the stage.
    pub s_end: f64,
}

/// Result of the complete optimisation.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CompleteOptimum {
    /// The stages, from the start count down to the final one.
    pub stages: Vec<Stage>,
    /// Final number of weights.
    pub n: u32,
    /// Final radius ratio (the housing limit).
    pub rho: f64,
    /// Final dimensionless capacity.
    pub s: f64,
}

/// ρ at which the outermost of n pressed weights rises above the horizontal
/// ((n − 1)α = π/2): exactly the half-race ρ of n − 1 weights. None for n = 1.
pub fn rho_excess_onset(n: u32) -> Result<Option<f64>, DesignError> {
    match n {
        0 => Err(DesignError::ZeroWeights),
        1 => Ok(None),
        _ => Ok(Some(rho_half_race(n - 1)?)),
    }
}

/// Run the complete optimisation from `n_start` weights up to the housing limit `rho_limit`.
pub fn complete_optimization(
    shape: Shape,
    n_start: u32,
    rho_limit: f64,
) -> Result<CompleteOptimum, DesignError> {
    check_basic(n_start, rho_limit)?;
    let mut n = n_start;
    let mut rho = 0.0;
    let mut stages = Vec::new();
    loop {
        let onset = rho_excess_onset(n)?;
        match onset {
            Some(drop_at) if drop_at < rho_limit => {
                stages.push(Stage {
                    n,
                    rho_from: rho,
                    rho_to: drop_at,
                    s_end: dimensionless_capacity(shape, n, drop_at)?,
                });
                rho = drop_at;
                n -= 1;
            }
            _ => {
                let s = dimensionless_capacity(shape, n, rho_limit)?;
                stages.push(Stage {
                    n,
                    rho_from: rho,
                    rho_to: rho_limit,
                    s_end: s,
                });
                return Ok(CompleteOptimum {
                    stages,
                    n,
                    rho: rho_limit,
                    s,
                });
            }
        }
    }
}

/// The best per-n optimum under the same housing limit: max over n ≤ `n_max`
/// of s(n, min(ρ_opt(n), ρ_limit)). Returns (n, ρ, s).
pub fn best_per_n_optimum(
    shape: Shape,
    n_max: u32,
    rho_limit: f64,
) -> Result<(u32, f64, f64), DesignError> {
    let mut best = (0, 0.0, f64::NEG_INFINITY);
    for n in 1..=n_max {
        let rho = optimal_rho(shape, n)?.rho.min(rho_limit);
        let s = dimensionless_capacity(shape, n, rho)?;
        if s > best.2 {
            best = (n, rho, s);
        }
    }
    Ok(best)
}
