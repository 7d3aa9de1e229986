//! Balancing capacity S_AB of n weights pressed together (seed 000, eqs 5–9).
//!
//! S_AB = m (R − r) sin(nα)/sin α: the largest static unbalance the weights can
//! cancel. The dimensionless forms s_b(ρ), s_r(ρ) of eq 9 are S_AB divided by
//! (4π/3) γ R⁴ for balls and by π γ R³ h for rollers.

use super::Shape;
use super::error::{DesignError, require_positive};
use super::geometry::{check_fits, half_angle};
use std::f64::consts::PI;

/// sin(nα)/sin α for n weights of radius ratio ρ pressed together (1 when n = 1).
///
/// This is the ratio of the capacity of n weights to that of one weight of the
/// same mass on the same circle.
pub fn cluster_factor(n: u32, rho: f64) -> Result<f64, DesignError> {
    check_fits(n, rho)?;
    if n == 1 {
        return Ok(1.0);
    }
    let alpha = half_angle(rho)?;
    Ok((f64::from(n) * alpha).sin() / alpha.sin())
}

/// Capacity m (R − r) sin(nα)/sin α of n weights of mass `mass` each (eq 5), in kg·m.
pub fn capacity_from_mass(
    n: u32,
    rho: f64,
    mass: f64,
    race_radius: f64,
) -> Result<f64, DesignError> {
    require_positive("weight mass m", mass)?;
    require_positive("race radius R", race_radius)?;
    Ok(mass * race_radius * (1.0 - rho) * cluster_factor(n, rho)?)
}

/// Dimensionless capacity s(ρ) of eq 9: s_r = ρ(1−ρ)² sin(n arcsin(ρ/(1−ρ))), s_b = ρ s_r.
///
/// For n = 1 the arcsin form is undefined beyond ρ = 1/2; the equivalent
/// s = ρ^k (1 − ρ) (k = 3 balls, 2 rollers) holds for every ρ < 1.
pub fn dimensionless_capacity(shape: Shape, n: u32, rho: f64) -> Result<f64, DesignError> {
    let k = shape.mass_exponent();
    Ok(rho.powi(k) * (1.0 - rho) * cluster_factor(n, rho)?)
}

/// Mass of one weight: 4/3 π r³ γ for a ball, π r² h γ for a roller (eq 6), in kg.
///
/// `roller_height` is ignored for balls.
pub fn weight_mass(
    shape: Shape,
    density: f64,
    race_radius: f64,
    rho: f64,
    roller_height: f64,
) -> Result<f64, DesignError> {
    require_positive("density γ", density)?;
    require_positive("race radius R", race_radius)?;
    if !(rho > 0.0 && rho < 1.0) {
        return Err(DesignError::RhoOutOfRange { rho });
    }
    let r = rho * race_radius;
    Ok(match shape {
        Shape::Ball => 4.0 / 3.0 * PI * r.powi(3) * density,
        Shape::Roller => PI * r * r * require_positive("roller height h", roller_height)? * density,
    })
}

/// Dimensional capacity S_AB of eq 7 in kg·m, from density γ, race radius R and roller height h.
pub fn capacity(
    shape: Shape,
    n: u32,
    rho: f64,
    density: f64,
    race_radius: f64,
    roller_height: f64,
) -> Result<f64, DesignError> {
    let m = weight_mass(shape, density, race_radius, rho, roller_height)?;
    capacity_from_mass(n, rho, m, race_radius)
}

/// Factor that turns the dimensionless s(ρ) into S_AB: 4π/3 γ R⁴ (balls) or π γ R³ h (rollers).
pub fn capacity_scale(
    shape: Shape,
    density: f64,
    race_radius: f64,
    roller_height: f64,
) -> Result<f64, DesignError> {
    require_positive("density γ", density)?;
    require_positive("race radius R", race_radius)?;
    Ok(match shape {
        Shape::Ball => 4.0 / 3.0 * PI * density * race_radius.powi(4),
        Shape::Roller => {
            PI * density * race_radius.powi(3) * require_positive("roller height h", roller_height)?
        }
    })
}

/// Capacity π R⁴ γ / 4 of a solid hemisphere of the sphere's radius (the non-classical weight of seed 000).
pub fn hemisphere_capacity(density: f64, race_radius: f64) -> Result<f64, DesignError> {
    require_positive("density γ", density)?;
    require_positive("race radius R", race_radius)?;
    Ok(PI * race_radius.powi(4) * density / 4.0)
}

/// Capacity 2 R³ h γ / 3 of a solid semi-cylindrical sector filling half a cylindrical race.
pub fn semicylinder_sector_capacity(
    density: f64,
    race_radius: f64,
    height: f64,
) -> Result<f64, DesignError> {
    require_positive("density γ", density)?;
    require_positive("race radius R", race_radius)?;
    require_positive("height h", height)?;
    Ok(2.0 * race_radius.powi(3) * height * density / 3.0)
}
