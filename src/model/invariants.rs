//! Energy and angular momentum of a rotor with cargoes, written from the
//! Lagrangian (seed 004 eqs 6–12 for the plane rotor; the kinetic energy of
//! `rotor::two_support` for the spatial one) independently of the
//! assembled equations of motion, so that conservation checks test them.
//!
//! Kinetic energy: ½ q̇ᵀM q̇ + φ̇ c(φ, q)·q̇ + ½ J_P φ̇² for the rotor (M, c
//! and J_P from the [`Rotor`](super::rotor::Rotor) model) plus, per cargo j in
//! plane p with (u̇, v̇) = G_p q̇: ½ m (u̇² + v̇²) + m l φ̇_j (−u̇ sin φ_j +
//! v̇ cos φ_j) + ½ κ m l² φ̇_j² and the rolling terms.

use super::rotor::MAX_DOF;
use super::system::RotorSystem;

/// Kinetic energy T plus support and gravity potential of state y at time t.
///
/// `gravity_in_plane` is g cos α (0 when gravity is off).
pub fn energy(system: &RotorSystem, t: f64, y: &[f64], gravity_in_plane: f64) -> f64 {
    let (phi, spin_rate) = system.spin(t, y);
    let rotor = system.rotor();
    let lay = system.layout();
    let (k, nq) = (lay.rotor_dof, lay.nq());
    let (q, qd) = (&y[..k], &y[nq..nq + k]);
    let m = rotor.mass_matrix();
    let coupling = rotor.spin_coupling(phi, q);
    let mut kinetic = 0.5 * rotor.spin_inertia() * spin_rate * spin_rate;
    for a in 0..k {
        kinetic += spin_rate * coupling[a] * qd[a];
        for b in 0..k {
            kinetic += 0.5 * m[a][b] * qd[a] * qd[b];
        }
    }
    let (me, angle) = rotor.static_unbalance();
    let mut potential = me * gravity_in_plane * (phi + angle).sin();
    for (j, c) in system.cargo().iter().enumerate() {
        let phi_j = phi + y[lay.psi(j)];
        let rate_j = spin_rate + y[nq + lay.psi(j)];
        let (s, co) = phi_j.sin_cos();
        let (ud, vd) = plane_velocity(system, j, qd);
        let ml = c.mass * c.track_radius;
        kinetic += 0.5 * c.mass * (ud * ud + vd * vd)
            + ml * rate_j * (-ud * s + vd * co)
            + 0.5 * c.inertia() * rate_j * rate_j
            + 0.5 * c.rolling_inertia * spin_rate * spin_rate
            - c.rolling_coupling * spin_rate * rate_j;
        potential += ml * gravity_in_plane * s;
    }
    let mut f = [0.0; MAX_DOF];
    // −(forces at zero velocity) = K q for a linear elastic rotor.
    rotor.forces(q, &[0.0; MAX_DOF], 0.0, &mut f);
    let elastic: f64 = -0.5 * (0..k).map(|a| f[a] * q[a]).sum::<f64>();
    kinetic + potential + elastic
}

/// Angular momentum about the fixed spin axis: Σ over coordinate pairs
/// (q₀ p₁ − q₁ p₀) + p_φ, the momentum conjugate to turning the whole system
/// about the axis (conserved for isotropic supports without torque, damping
/// or gravity).
pub fn angular_momentum(system: &RotorSystem, t: f64, y: &[f64]) -> f64 {
    let (phi, spin_rate) = system.spin(t, y);
    let rotor = system.rotor();
    let lay = system.layout();
    let (k, nq) = (lay.rotor_dof, lay.nq());
    let (q, qd) = (&y[..k], &y[nq..nq + k]);
    let m = rotor.mass_matrix();
    let coupling = rotor.spin_coupling(phi, q);
    let mut p = [0.0; MAX_DOF];
    let mut p_phi = rotor.spin_inertia() * spin_rate;
    for a in 0..k {
        p[a] = coupling[a] * spin_rate;
        p_phi += coupling[a] * qd[a];
        for b in 0..k {
            p[a] += m[a][b] * qd[b];
        }
    }
    for (j, c) in system.cargo().iter().enumerate() {
        let rate_j = spin_rate + y[nq + lay.psi(j)];
        let (s, co) = (phi + y[lay.psi(j)]).sin_cos();
        let [gu, gv] = system.cargo_plane_map(j);
        let (ud, vd) = plane_velocity(system, j, qd);
        let ml = c.mass * c.track_radius;
        // ∂T/∂(u̇, v̇) of the cargo, mapped onto the rotor coordinates.
        let pu = c.mass * ud - ml * s * rate_j;
        let pv = c.mass * vd + ml * co * rate_j;
        for a in 0..k {
            p[a] += gu[a] * pu + gv[a] * pv;
        }
        // ∂T/∂φ̇ at fixed φ_j plus ∂T/∂φ̇_j: the momentum of φ at fixed ψ_j.
        p_phi += c.rolling_inertia * spin_rate - c.rolling_coupling * rate_j;
        p_phi += ml * (-ud * s + vd * co) + c.inertia() * rate_j - c.rolling_coupling * spin_rate;
    }
    let mut l = p_phi;
    for pair in 0..k / 2 {
        let (a, b) = (2 * pair, 2 * pair + 1);
        l += q[a] * p[b] - q[b] * p[a];
    }
    l
}

/// Velocity (u̇, v̇) of the centre of cargo j's plane.
fn plane_velocity(system: &RotorSystem, j: usize, qd: &[f64]) -> (f64, f64) {
    let [gu, gv] = system.cargo_plane_map(j);
    let mut ud = 0.0;
    let mut vd = 0.0;
    for (i, v) in qd.iter().enumerate() {
        ud += gu[i] * v;
        vd += gv[i] * v;
    }
    (ud, vd)
}
