//! The net unbalance a balancer leaves: the reference unbalance U and the
//! balancing error ε of cargo angles, for any rotor model. `metrics` names
//! them among its scales (docs/metrics.md); the linear analysis uses them
//! to tell a balanced fixed point from an unbalanced one.

use crate::model::forced::unbalance_forcing;
use crate::model::start::is_plane_translation;
use crate::model::system::RotorSystem;

/// Reference unbalance U: the size of the rotor's own unbalance (M e for the
/// plane rotor, the largest bearing-equivalent one on two supports), or
/// Σ m l when the rotor has none.
pub fn reference_unbalance(system: &RotorSystem) -> f64 {
    let own = system.rotor().own_unbalance();
    if own > 0.0 {
        own
    } else {
        system.cargo().iter().map(|c| c.unbalance()).sum::<f64>()
    }
}

/// Balancing error ε: size of the total unbalance of rotor and cargoes (at
/// angles ψ relative to the rotor) over U; for the plane rotor
/// |Σ m_j l_j e^{iψ_j} + M e e^{iψ₀}| / U.
pub fn balancing_error(system: &RotorSystem, psi: &[f64], unbalance_ref: f64) -> f64 {
    if is_plane_translation(system) {
        let (ux, uy) = crate::model::start::total_unbalance(system, psi);
        return ux.hypot(uy) / unbalance_ref;
    }
    let (fc, _) = unbalance_forcing(system, psi, true);
    system.rotor().unbalance_size(&fc) / unbalance_ref
}
