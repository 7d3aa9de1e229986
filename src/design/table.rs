//! Rows of the design table (Table 1 of seed 000, extended with p_max, ã and excess weights).

use super::Shape;
use super::capacity::dimensionless_capacity;
use super::error::DesignError;
use super::geometry::{excess_weights, rho_max, sector_angle};
use super::optimum::optimal_rho;
use super::transient::{a_tilde, p_max};
use serde::Serialize;

/// One design (shape, n, ρ) with the analytic figures of merit of seed 000.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignRow {
    /// Number of weights.
    pub n: u32,
    /// Weight shape.
    pub kind: Shape,
    /// Radius ratio ρ = r/R (the capacity optimum in [`optimal_row`]).
    pub rho_opt: f64,
    /// Sector of the race filled by the weights pressed together, 2nα in degrees
    /// (`None` for n = 1, where the paper prints "–").
    pub sector_deg: Option<f64>,
    /// Dimensionless capacity s(ρ) of eq 9.
    pub s: f64,
    /// Largest ρ for which n weights fit (1 for n = 1).
    pub rho_max: f64,
    /// Largest position parameter p_max(n, ρ) (eqs 10, 13).
    pub p_max: f64,
    /// Dimensionless transient measure ã(ρ) (eqs 15, 16).
    pub a_tilde: f64,
    /// Weights whose centre lies above the horizontal through the race centre
    /// when all are pressed together symmetrically (both sides counted).
    pub excess: u32,
}

/// Evaluate every figure of merit for a given design (shape, n, ρ).
pub fn row_at(shape: Shape, n: u32, rho: f64) -> Result<DesignRow, DesignError> {
    let s = dimensionless_capacity(shape, n, rho)?;
    Ok(DesignRow {
        n,
        kind: shape,
        rho_opt: rho,
        sector_deg: if n >= 2 {
            Some(sector_angle(n, rho)?.to_degrees())
        } else {
            None
        },
        s,
        rho_max: rho_max(n)?,
        p_max: p_max(n, rho)?,
        a_tilde: a_tilde(shape, n, rho)?,
        excess: excess_weights(n, rho)?,
    })
}

/// The Table 1 row for (shape, n): every figure evaluated at the capacity-optimal ρ.
pub fn optimal_row(shape: Shape, n: u32) -> Result<DesignRow, DesignError> {
    let opt = optimal_rho(shape, n)?;
    row_at(shape, n, opt.rho)
}
