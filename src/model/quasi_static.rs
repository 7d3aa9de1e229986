//! The `analytic` fidelity: the slow mode of the balancer in closed form.
//!
//! When the weights move slowly compared with the rotor (heavy drag), the
//! rotor follows the total unbalance quasi-statically, w = H Σ̂ with
//! H = ω²/(k − M_Σω² + i b ω), and each weight drifts as
//! β l² ψ̇_j = m l ω² Im[w e^{−iψ_j}]. Linearised about a balanced position
//! this is a rank-two system whose only non-zero eigenvalues are
//!
//!   λ± = (c n/2) [cos θ ± sqrt(p² − sin² θ)],  c = m² ω² |H| / β,  θ = arg H,
//!
//! with p the position parameter of seed 000 (eq 2). Above resonance θ ≈ π and
//! the slow root is λ ≈ −c n (1 − p)/2: the structure of eq 1 in its
//! overdamped limit, λ ≈ −(1 − p) m n b_cr²/(4 b̃). The n − 2 zero roots are
//! the neutral family of balanced positions.

use super::scene::Scene;
use super::speed::SpeedLaw;
use super::start::balanced_fan;
use crate::design::transient::position_parameter;

/// The closed-form slow mode of a scene at its balanced position.
#[derive(Debug, Clone, PartialEq)]
pub struct SlowMode {
    /// Position parameter p at the balanced position used.
    pub p: f64,
    /// Real part of the slowest non-zero root (1/s); negative when balancing occurs.
    pub decay_rate: f64,
    /// Imaginary part of that root (rad/s).
    pub frequency: f64,
}

/// Why the analytic fidelity does not apply.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AnalyticError {
    /// The closed form needs identical cargoes.
    #[error("the analytic estimate needs identical cargoes")]
    UnequalCargoes,
    /// The closed form needs a constant speed.
    #[error("the analytic estimate needs a constant speed")]
    VariableSpeed,
    /// The cargoes cannot cancel the unbalance.
    #[error("the unbalance exceeds what the cargoes can cancel")]
    NotBalanceable,
    /// The closed form is derived for a plane rotor on isotropic supports.
    #[error("the analytic estimate is derived for the plane rotor on isotropic supports")]
    NotPlane,
    /// The closed form needs drag.
    #[error("the analytic estimate needs a positive drag")]
    NoDrag,
}

/// The slow mode at the symmetric balanced fan of the scene's unbalance.
pub fn slow_mode(scene: &Scene) -> Result<SlowMode, AnalyticError> {
    let SpeedLaw::Constant { omega } = scene.speed else {
        return Err(AnalyticError::VariableSpeed);
    };
    let cargo = scene.cargoes().map_err(|_| AnalyticError::UnequalCargoes)?;
    let first = cargo.first().ok_or(AnalyticError::UnequalCargoes)?;
    if cargo.iter().any(|c| {
        c.mass != first.mass || c.track_radius != first.track_radius || c.drag != first.drag
    }) {
        return Err(AnalyticError::UnequalCargoes);
    }
    if first.drag <= 0.0 {
        return Err(AnalyticError::NoDrag);
    }
    let Ok(r) = scene.rotor.as_rotor().isotropic_plane() else {
        return Err(AnalyticError::NotPlane);
    };
    let m_total = r.mass + cargo.iter().map(|c| c.mass).sum::<f64>();
    let unbalance = r.unbalance;
    let angles = balanced_fan(cargo.len(), first.unbalance(), unbalance, r.unbalance_angle)
        .ok_or(AnalyticError::NotBalanceable)?;
    let p = position_parameter(&angles);
    let (dre, dim) = (r.stiffness - m_total * omega * omega, r.damping * omega);
    let h_abs = omega * omega / dre.hypot(dim);
    let theta = (-dim).atan2(dre);
    let c = first.mass * first.mass * omega * omega * h_abs / first.drag;
    let n = cargo.len() as f64;
    let disc = p * p - theta.sin().powi(2);
    let (decay_rate, frequency) = if disc >= 0.0 {
        (0.5 * c * n * (theta.cos() + disc.sqrt()), 0.0)
    } else {
        (0.5 * c * n * theta.cos(), 0.5 * c * n * (-disc).sqrt())
    };
    Ok(SlowMode {
        p,
        decay_rate,
        frequency,
    })
}
