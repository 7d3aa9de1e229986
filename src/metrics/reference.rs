//! Reference scales: A_ref, the reference unbalance U, the vibration r and
//! the balancing error ε, for any rotor model (definitions in `docs/metrics.md`).

use crate::model::forced::{harmonic_response, plane_orbit_radius, unbalance_forcing};
use crate::model::rotor::MAX_DOF;
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

/// A_ref at speed ω: the largest balancer-plane orbit radius of the locked
/// response to the rotor's own unbalance (to U in plane 0 when it has none),
/// with the cargoes' masses but not their unbalance. For the plane rotor this
/// is U ω² / |k_x − M_Σ ω² + i b_x ω| (its x amplitude, the orbit radius for
/// isotropic supports), evaluated in that closed form.
pub fn a_ref(system: &RotorSystem, omega: f64) -> f64 {
    if is_plane_translation(system) {
        return plane_a_ref(system, omega);
    }
    let rotor = system.rotor();
    let (mut fc, mut fs) = unbalance_forcing(system, &[], true);
    if rotor.own_unbalance() == 0.0 {
        let u = reference_unbalance(system);
        let [gu, gv] = rotor.plane_map(0);
        for i in 0..MAX_DOF {
            fc[i] = u * gu[i];
            fs[i] = u * gv[i];
        }
    }
    match harmonic_response(system, &fc, &fs, omega) {
        Some(h) => (0..rotor.planes())
            .map(|p| plane_orbit_radius(&h, &rotor.plane_map(p)))
            .fold(0.0, f64::max),
        None => f64::INFINITY,
    }
}

/// A_ref = U ω² / |k_x − M_Σ ω² + i b_x ω| for the plane rotor.
fn plane_a_ref(system: &RotorSystem, omega: f64) -> f64 {
    let rotor = system.rotor();
    let m_total = rotor.mass_matrix()[0][0] + system.cargo().iter().map(|c| c.mass).sum::<f64>();
    let mut f = [0.0; MAX_DOF];
    let mut unit = [0.0; MAX_DOF];
    unit[0] = 1.0;
    rotor.forces(&unit, &[0.0; MAX_DOF], omega, &mut f);
    let kx = -f[0];
    let mut f = [0.0; MAX_DOF];
    rotor.forces(&[0.0; MAX_DOF], &unit, omega, &mut f);
    let bx = -f[0];
    reference_unbalance(system) * omega * omega / (kx - m_total * omega * omega).hypot(bx * omega)
}

/// Vibration r: the largest displacement |(u_p, v_p)| over the balancer
/// planes (for the plane rotor, sqrt(x² + y²)).
pub fn vibration(system: &RotorSystem, q: &[f64]) -> f64 {
    let rotor = system.rotor();
    if is_plane_translation(system) {
        return q[0].hypot(q[1]);
    }
    let k = rotor.dof();
    (0..rotor.planes())
        .map(|p| {
            let [gu, gv] = rotor.plane_map(p);
            let u: f64 = (0..k).map(|i| gu[i] * q[i]).sum();
            let v: f64 = (0..k).map(|i| gv[i] * q[i]).sum();
            u.hypot(v)
        })
        .fold(0.0, |acc: f64, r| {
            if acc.is_nan() || r.is_nan() {
                f64::NAN
            } else {
                acc.max(r)
            }
        })
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
