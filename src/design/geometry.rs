//! Geometry of n weights of radius r pressed together in a race of radius R.
//!
//! Centres lie on the circle l = R − r; neighbouring centres subtend 2α at the
//! race centre with α = arcsin(ρ/(1 − ρ)) (eq 4).

use super::error::DesignError;
use std::f64::consts::PI;

/// Check n ≥ 1 and 0 < ρ < 1, the domain shared by every formula.
pub fn check_basic(n: u32, rho: f64) -> Result<(), DesignError> {
    if n == 0 {
        return Err(DesignError::ZeroWeights);
    }
    if !(rho > 0.0 && rho < 1.0) {
        return Err(DesignError::RhoOutOfRange { rho });
    }
    Ok(())
}

/// Largest ρ for which n weights fit on the race: 1/(1 + csc(π/n)) for n ≥ 2, 1 for n = 1.
pub fn rho_max(n: u32) -> Result<f64, DesignError> {
    match n {
        0 => Err(DesignError::ZeroWeights),
        1 => Ok(1.0),
        _ => {
            let s = (PI / f64::from(n)).sin();
            Ok(s / (1.0 + s))
        }
    }
}

/// Check that n weights of radius ratio ρ fit on the race (nα ≤ π; any ρ < 1 when n = 1).
pub fn check_fits(n: u32, rho: f64) -> Result<(), DesignError> {
    check_basic(n, rho)?;
    let limit = rho_max(n)?;
    // A hair of slack so that ρ_max itself, computed by the caller, is accepted.
    if n >= 2 && rho > limit * (1.0 + 4.0 * f64::EPSILON) {
        return Err(DesignError::DoesNotFit {
            n,
            rho,
            rho_max: limit,
        });
    }
    Ok(())
}

/// Half-angle α = arcsin(ρ/(1 − ρ)) subtended by one weight (eq 4); needs ρ ≤ 1/2.
pub fn half_angle(rho: f64) -> Result<f64, DesignError> {
    if !(rho > 0.0 && rho <= 0.5) {
        return Err(DesignError::RhoOutOfRange { rho });
    }
    // Clamp: at ρ = 1/2 rounding can push the ratio a hair above 1.
    Ok((rho / (1.0 - rho)).min(1.0).asin())
}

/// ρ at which n weights fill exactly half the race (2nα = π): sin(π/2n)/(1 + sin(π/2n)).
pub fn rho_half_race(n: u32) -> Result<f64, DesignError> {
    if n == 0 {
        return Err(DesignError::ZeroWeights);
    }
    let s = (PI / (2.0 * f64::from(n))).sin();
    Ok(s / (1.0 + s))
}

/// Sector of the race filled by n weights pressed together, φ = 2nα, in radians (n ≥ 2).
pub fn sector_angle(n: u32, rho: f64) -> Result<f64, DesignError> {
    check_fits(n, rho)?;
    Ok(2.0 * f64::from(n) * half_angle(rho)?)
}

/// Angles of the centres of n weights pressed together, symmetric about the
/// capacity direction: θ_j = −α(n + 1 − 2j), j = 1..n (seed 000, Fig. 2).
pub fn pressed_angles(n: u32, rho: f64) -> Result<Vec<f64>, DesignError> {
    check_fits(n, rho)?;
    if n == 1 {
        return Ok(vec![0.0]);
    }
    let alpha = half_angle(rho)?;
    Ok((1..=n)
        .map(|j| -alpha * (f64::from(n) + 1.0 - 2.0 * f64::from(j)))
        .collect())
}

/// Number of weights whose centre lies beyond the horizontal through the race
/// centre (|θ_j| > π/2) when n weights are pressed together: the "excess"
/// weights of seed 000 that reduce the capacity instead of adding to it.
pub fn excess_weights(n: u32, rho: f64) -> Result<u32, DesignError> {
    let angles = pressed_angles(n, rho)?;
    Ok(angles.iter().filter(|t| t.abs() > PI / 2.0).count() as u32)
}
