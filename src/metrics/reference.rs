//! Reference scales: A_ref, the reference unbalance U and the balancing error ε.

use crate::model::system::RotorSystem;

/// Reference unbalance U: the rotor's M e, or Σ m l when e = 0.
pub fn reference_unbalance(system: &RotorSystem) -> f64 {
    let (me, _) = system.rotor().static_unbalance();
    if me > 0.0 {
        me
    } else {
        system.cargo().iter().map(|c| c.unbalance()).sum::<f64>()
    }
}

/// A_ref = U ω² / |k_x − M_Σ ω² + i b_x ω| at speed ω.
pub fn a_ref(system: &RotorSystem, omega: f64) -> f64 {
    let rotor = system.rotor();
    let m_total = rotor.mass_matrix()[0][0] + system.cargo().iter().map(|c| c.mass).sum::<f64>();
    let mut f = [0.0; crate::model::rotor::MAX_DOF];
    let mut unit = [0.0; crate::model::rotor::MAX_DOF];
    unit[0] = 1.0;
    rotor.forces(&unit, &[0.0; crate::model::rotor::MAX_DOF], omega, &mut f);
    let kx = -f[0];
    let mut f = [0.0; crate::model::rotor::MAX_DOF];
    rotor.forces(&[0.0; crate::model::rotor::MAX_DOF], &unit, omega, &mut f);
    let bx = -f[0];
    reference_unbalance(system) * omega * omega / (kx - m_total * omega * omega).hypot(bx * omega)
}

/// Balancing error ε = |Σ m_j l_j e^{iψ_j} + M e e^{iψ₀}| / U for cargo angles ψ relative to the rotor.
pub fn balancing_error(system: &RotorSystem, psi: &[f64], unbalance_ref: f64) -> f64 {
    let (ux, uy) = crate::model::start::total_unbalance(system, psi);
    ux.hypot(uy) / unbalance_ref
}
