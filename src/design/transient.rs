//! Speed of auto-balancing: the position parameter p (eq 2), its largest value
//! p_max for weights of finite size (eqs 10–14), the transient measures a and ã
//! (eqs 3, 15, 16) and the slowest characteristic root λ (eq 1).
//!
//! A larger a = (1 − p) m n means a faster approach to the balanced state.

use super::Shape;
use super::error::{DesignError, require_positive};
use super::geometry::{check_fits, half_angle};

/// Position parameter p = sqrt(Σ_{i,k} cos 2(ψ_i − ψ_k)) / n ∈ [0, 1] of eq 2.
///
/// Computed as |Σ_j e^{2iψ_j}| / n, which equals eq 2 exactly (the double sum
/// is the squared modulus of that single sum) in O(n) and is never negative
/// under the square root. An empty slice gives 0.
pub fn position_parameter(angles: &[f64]) -> f64 {
    if angles.is_empty() {
        return 0.0;
    }
    let (mut c, mut s) = (0.0, 0.0);
    for a in angles {
        let (sin, cos) = (2.0 * a).sin_cos();
        c += cos;
        s += sin;
    }
    (c.hypot(s) / angles.len() as f64).min(1.0)
}

/// Largest p reachable by n weights of radius ratio ρ that cannot pass through
/// each other: 2 sin nα/(n sin 2α) for even n (eq 10), sin nα/(n sin α) for odd n (eq 13).
///
/// n = 1 gives 1 for any ρ < 1 (a single weight always has p = 1).
pub fn p_max(n: u32, rho: f64) -> Result<f64, DesignError> {
    check_fits(n, rho)?;
    if n == 1 {
        return Ok(1.0);
    }
    let alpha = half_angle(rho)?;
    let nf = f64::from(n);
    let value = if n.is_multiple_of(2) {
        // At ρ = ρ_max(2) = 1/2 both sin terms vanish; the limit is 1.
        let denom = nf * (2.0 * alpha).sin();
        if denom.abs() < 1e-300 {
            1.0
        } else {
            2.0 * (nf * alpha).sin() / denom
        }
    } else {
        (nf * alpha).sin() / (nf * alpha.sin())
    };
    Ok(value.clamp(0.0, 1.0))
}

/// p_max when the weights fill exactly half the race: 2/(n sin(π/n)) for even n
/// (eq 12), 1/(n sin(π/(2n))) for odd n (eq 14).
pub fn p_max_half_race(n: u32) -> Result<f64, DesignError> {
    use std::f64::consts::PI;
    let nf = f64::from(n);
    match n {
        0 => Err(DesignError::ZeroWeights),
        _ if n.is_multiple_of(2) => Ok(2.0 / (nf * (PI / nf).sin())),
        _ => Ok(1.0 / (nf * (PI / (2.0 * nf)).sin())),
    }
}

/// Transient measure a = (1 − p) m n of eq 3: larger means faster balancing.
pub fn transient_measure(p: f64, mass: f64, n: u32) -> Result<f64, DesignError> {
    if !(0.0..=1.0).contains(&p) {
        return Err(DesignError::POutOfRange(p));
    }
    require_positive("weight mass m", mass)?;
    if n == 0 {
        return Err(DesignError::ZeroWeights);
    }
    Ok((1.0 - p) * mass * f64::from(n))
}

/// Dimensionless transient measure ã(ρ) = (1 − p_max) n ρ^k at p = p_max
/// (eq 3 with the weight mass in units of π γ R³ h for rollers, k = 2, or
/// 4/3 π γ R³ for balls, k = 3).
///
/// This is eq 15 (odd n) and eq 16 (even n, with the sqrt(1 − 2ρ) divisor of
/// docs/design-theory.md) in closed form: ã_r = ρ[nρ − (1−ρ) sin nα] and
/// ã_r = ρ[nρ − (1−ρ)² sin nα / sqrt(1−2ρ)], ã_b = ρ ã_r. Evaluating it through
/// p_max keeps ã ≥ 0 where the printed forms cancel to −1e-17 (n = 2). n = 1 gives 0.
pub fn a_tilde(shape: Shape, n: u32, rho: f64) -> Result<f64, DesignError> {
    let p = p_max(n, rho)?;
    Ok((1.0 - p) * f64::from(n) * rho.powi(shape.mass_exponent()))
}

/// A characteristic root λ = re + i·im.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Root {
    /// Real part: the decay rate is −re.
    pub re: f64,
    /// Imaginary part (zero for a real root).
    pub im: f64,
}

impl Root {
    /// True when the root is real.
    pub fn is_real(&self) -> bool {
        self.im == 0.0
    }
}

/// Slowest root of eq 1: λ = −[b̃ − sqrt(b̃² − (1 − p) m n b_cr²)]/2.
///
/// When b̃² < (1 − p) m n b_cr² the pair is complex; the root with positive
/// imaginary part is returned (its real part −b̃/2 sets the decay rate).
pub fn slowest_root(
    b_tilde: f64,
    p: f64,
    mass: f64,
    n: u32,
    b_cr: f64,
) -> Result<Root, DesignError> {
    require_positive("drag parameter b̃", b_tilde)?;
    require_positive("critical parameter b_cr", b_cr)?;
    let a = transient_measure(p, mass, n)?;
    let disc = b_tilde * b_tilde - a * b_cr * b_cr;
    Ok(if disc >= 0.0 {
        // b̃ − sqrt(disc) rewritten as a·b_cr²/(b̃ + sqrt(disc)) to avoid cancellation.
        Root {
            re: -(a * b_cr * b_cr) / (b_tilde + disc.sqrt()) / 2.0,
            im: 0.0,
        }
    } else {
        Root {
            re: -b_tilde / 2.0,
            im: (-disc).sqrt() / 2.0,
        }
    })
}
