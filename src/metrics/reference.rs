//! Reference scales: A_ref, the reference unbalance U, the vibration r and
//! the balancing error ε, for any rotor model (definitions in `docs/metrics.md`).

use crate::model::forced::{harmonic_response, plane_orbit_radius, unbalance_forcing};
use crate::model::rotor::MAX_DOF;
use crate::model::start::is_plane_translation;
use crate::model::system::RotorSystem;

// The unbalance measures are model quantities (the linear analysis needs
// them too); they are defined there and named here with the other scales.
use crate::model::unbalance::planar_norm;
pub use crate::model::unbalance::{balancing_error, plane_balancing_errors, reference_unbalance};

/// A_ref at speed ω: the largest orbit radius over the watched planes
/// (balancer planes, and the rotor's own unbalance planes) of the locked
/// response to the rotor's own unbalance (to U in plane 0 when it has none),
/// with the cargoes' masses but not their unbalance. For the plane rotor this
/// is U ω² / |k_x − M_Σ ω² + i b_x ω| (its x amplitude, the orbit radius for
/// isotropic supports), evaluated in that closed form.
pub fn a_ref(system: &RotorSystem, omega: f64) -> f64 {
    if is_plane_translation(system) {
        return plane_a_ref(system, omega);
    }
    plane_a_refs(system, omega).into_iter().fold(0.0, f64::max)
}

/// A_ref of each watched plane (balancer planes, then the rotor's own
/// unbalance planes; [`RotorSystem::watch_maps`]): its orbit radius in the
/// locked response of [`a_ref`], whose largest it is.
pub fn plane_a_refs(system: &RotorSystem, omega: f64) -> Vec<f64> {
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
    let maps = system.watch_maps();
    match harmonic_response(system, &fc, &fs, omega) {
        Some(h) => maps.iter().map(|map| plane_orbit_radius(&h, map)).collect(),
        None => vec![f64::INFINITY; maps.len()],
    }
}

/// The displacement |(u_p, v_p)| of every watched plane at positions q, into `out`.
pub fn plane_whirls(system: &RotorSystem, q: &[f64], out: &mut [f64]) {
    let k = system.rotor().dof();
    for (r, &[gu, gv]) in out.iter_mut().zip(system.watch_maps()) {
        let u: f64 = (0..k).map(|i| gu[i] * q[i]).sum();
        let v: f64 = (0..k).map(|i| gv[i] * q[i]).sum();
        *r = planar_norm(u, v);
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
/// planes and any other plane the rotor watches, where its own unbalance
/// sits (for the plane rotor, sqrt(x² + y²)).
pub fn vibration(system: &RotorSystem, q: &[f64]) -> f64 {
    let rotor = system.rotor();
    if is_plane_translation(system) {
        return planar_norm(q[0], q[1]);
    }
    let k = rotor.dof();
    system
        .watch_maps()
        .iter()
        .map(|&[gu, gv]| {
            let u: f64 = (0..k).map(|i| gu[i] * q[i]).sum();
            let v: f64 = (0..k).map(|i| gv[i] * q[i]).sum();
            planar_norm(u, v)
        })
        .fold(0.0, |acc: f64, r| {
            if acc.is_nan() || r.is_nan() {
                f64::NAN
            } else {
                acc.max(r)
            }
        })
}
