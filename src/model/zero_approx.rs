//! Seed 003's empirical criterion (eq 1) evaluated numerically for any rotor
//! model, in its "zero approximation": elementary unbalances U_p in the
//! balancer planes, the rotor's steady response without the balancers' mass,
//! and the functional ⟨Σ_p s_p(t)·r_p(t)⟩ over a revolution. It is a real
//! quadratic form Uᵀ Q U in the 2P components of the plane unbalances;
//! auto-balancing occurs when it is negative for every U, i.e. when the
//! largest eigenvalue of Q is negative. For the rotor on two supports this
//! reproduces the closed forms of [`crate::design::criterion`]; anisotropic
//! supports and damping are handled as well.

use super::forced::harmonic_response_with;
use super::rotor::MAX_DOF;
use super::system::RotorSystem;
use nalgebra::DMatrix;

/// The criterion's quadratic form Q (2P × 2P, symmetric) at speed ω, in the
/// basis (Re U_0, Im U_0, Re U_1, …); `None` at an undamped resonance.
pub fn criterion_form(system: &RotorSystem, omega: f64) -> Option<DMatrix<f64>> {
    let rotor = system.rotor();
    let (k, planes) = (rotor.dof(), rotor.planes());
    let mass = rotor.mass_matrix();
    let maps: Vec<_> = (0..planes).map(|p| rotor.plane_map(p)).collect();
    let dot = |g: &[f64; MAX_DOF], v: &[f64; MAX_DOF]| (0..k).map(|i| g[i] * v[i]).sum::<f64>();
    let n = 2 * planes;
    let mut q = DMatrix::zeros(n, n);
    for col in 0..n {
        // Unit unbalance: Re (col even) or Im (col odd) of U_p, p = col / 2.
        let (p, imag) = (col / 2, col % 2 == 1);
        let (ur, ui) = if imag { (0.0, 1.0) } else { (1.0, 0.0) };
        let [gu, gv] = maps[p];
        let (mut fc, mut fs) = ([0.0; MAX_DOF], [0.0; MAX_DOF]);
        for i in 0..k {
            fc[i] = ur * gu[i] + ui * gv[i];
            fs[i] = -ui * gu[i] + ur * gv[i];
        }
        let h = harmonic_response_with(system, &mass, &fc, &fs, omega)?;
        for row in 0..n {
            // ⟨s_row(t)·r_row-plane(t)⟩ = ½(S_c·A + S_s·B) for the unit unbalance `row`.
            let (pr, imag_r) = (row / 2, row % 2 == 1);
            let (sr, si) = if imag_r { (0.0, 1.0) } else { (1.0, 0.0) };
            let [gu, gv] = maps[pr];
            let a = (dot(&gu, &h.cos), dot(&gv, &h.cos));
            let b = (dot(&gu, &h.sin), dot(&gv, &h.sin));
            q[(row, col)] = 0.5 * (sr * a.0 + si * a.1 + (-si) * b.0 + sr * b.1);
        }
    }
    Some(0.5 * (&q + q.transpose()))
}

/// Largest eigenvalue of Q at ω (negative: the criterion predicts
/// balancing); NaN at an undamped resonance.
pub fn criterion_margin(system: &RotorSystem, omega: f64) -> f64 {
    match criterion_form(system, omega) {
        Some(q) => q
            .symmetric_eigenvalues()
            .iter()
            .cloned()
            .fold(f64::MIN, f64::max),
        None => f64::NAN,
    }
}
