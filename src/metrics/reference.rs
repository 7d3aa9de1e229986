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
/// with the cargoes' masses but not their unbalance. The orbit radius is its
/// peak, the measure of r: on anisotropic supports the orbit is an ellipse
/// and A_ref its major semi-axis. For the plane rotor on isotropic supports
/// this is U ω² / |k − M_Σ ω² + i b ω|, evaluated in that closed form.
pub fn a_ref(system: &RotorSystem, omega: f64) -> f64 {
    if is_plane_translation(system)
        && let Some(a) = isotropic_plane_a_ref(system, omega)
    {
        return a;
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

/// A_ref = U ω² / |k − M_Σ ω² + i b ω| for the plane rotor on isotropic
/// supports; `None` when x and y differ (the orbit is then an ellipse).
fn isotropic_plane_a_ref(system: &RotorSystem, omega: f64) -> Option<f64> {
    let rotor = system.rotor();
    let m_total = rotor.mass_matrix()[0][0] + system.cargo().iter().map(|c| c.mass).sum::<f64>();
    // Stiffness and damping along axis i, read off the rotor's forces.
    let axis = |i: usize| {
        let mut unit = [0.0; MAX_DOF];
        unit[i] = 1.0;
        let (mut fk, mut fb) = ([0.0; MAX_DOF], [0.0; MAX_DOF]);
        rotor.forces(&unit, &[0.0; MAX_DOF], omega, &mut fk);
        rotor.forces(&[0.0; MAX_DOF], &unit, omega, &mut fb);
        (-fk[i], -fb[i])
    };
    let (kx, bx) = axis(0);
    (axis(1) == (kx, bx)).then(|| {
        reference_unbalance(system) * omega * omega
            / (kx - m_total * omega * omega).hypot(bx * omega)
    })
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
