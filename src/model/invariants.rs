//! Energy and angular momentum of the plane rotor with cargoes, written from
//! the Lagrangian of seed 004 (eqs 6–12) independently of the equations of
//! motion, so that conservation checks test the equations themselves.

use super::system::RotorSystem;

/// Kinetic energy T plus support and gravity potential of state y at time t.
///
/// `gravity_in_plane` is g cos α (0 when gravity is off). Valid for rotors
/// whose coordinates are the plane displacement (x, y).
pub fn energy(system: &RotorSystem, t: f64, y: &[f64], gravity_in_plane: f64) -> f64 {
    let v = Velocities::new(system, t, y);
    let rotor = system.rotor();
    let lay = system.layout();
    let nq = lay.nq();
    let m_rotor = rotor.mass_matrix()[0][0];
    let coupling = rotor.spin_coupling(v.phi);
    let (xd, yd) = (y[nq], y[nq + 1]);
    let mut kinetic = 0.5 * m_rotor * (xd * xd + yd * yd)
        + v.spin_rate * (coupling[0] * xd + coupling[1] * yd)
        + 0.5 * rotor.spin_inertia() * v.spin_rate * v.spin_rate;
    let (me, angle) = rotor.static_unbalance();
    let mut potential = me * gravity_in_plane * (v.phi + angle).sin();
    for (j, c) in system.cargo().iter().enumerate() {
        let phi_j = v.phi + y[lay.psi(j)];
        let rate_j = v.spin_rate + y[nq + lay.psi(j)];
        let (s, co) = phi_j.sin_cos();
        let ml = c.mass * c.track_radius;
        kinetic += 0.5 * c.mass * (xd * xd + yd * yd)
            + ml * rate_j * (-xd * s + yd * co)
            + 0.5 * c.inertia() * rate_j * rate_j
            + 0.5 * c.rolling_inertia * v.spin_rate * v.spin_rate
            - c.rolling_coupling * v.spin_rate * rate_j;
        potential += ml * gravity_in_plane * s;
    }
    let mut f = [0.0; super::rotor::MAX_DOF];
    // −(forces at zero velocity) = K q for a linear elastic rotor.
    rotor.forces(
        &y[..lay.rotor_dof],
        &[0.0; super::rotor::MAX_DOF],
        0.0,
        &mut f,
    );
    let elastic = -0.5 * (f[0] * y[0] + f[1] * y[1]);
    kinetic + potential + elastic
}

/// Angular momentum about the fixed axis through O: x p_y − y p_x + p_φ,
/// the momentum conjugate to turning the whole system about O (conserved for
/// isotropic supports without torque, damping or gravity).
pub fn angular_momentum(system: &RotorSystem, t: f64, y: &[f64]) -> f64 {
    let v = Velocities::new(system, t, y);
    let rotor = system.rotor();
    let lay = system.layout();
    let nq = lay.nq();
    let m_rotor = rotor.mass_matrix()[0][0];
    let coupling = rotor.spin_coupling(v.phi);
    let (x, yy, xd, yd) = (y[0], y[1], y[nq], y[nq + 1]);
    let mut px = m_rotor * xd + coupling[0] * v.spin_rate;
    let mut py = m_rotor * yd + coupling[1] * v.spin_rate;
    let mut p_phi = coupling[0] * xd + coupling[1] * yd + rotor.spin_inertia() * v.spin_rate;
    for (j, c) in system.cargo().iter().enumerate() {
        let rate_j = v.spin_rate + y[nq + lay.psi(j)];
        let (s, co) = (v.phi + y[lay.psi(j)]).sin_cos();
        let ml = c.mass * c.track_radius;
        px += c.mass * xd - ml * s * rate_j;
        py += c.mass * yd + ml * co * rate_j;
        // ∂T/∂φ̇ at fixed φ_j plus ∂T/∂φ̇_j: the momentum of φ at fixed ψ_j.
        p_phi += c.rolling_inertia * v.spin_rate - c.rolling_coupling * rate_j;
        p_phi += ml * (-xd * s + yd * co) + c.inertia() * rate_j - c.rolling_coupling * v.spin_rate;
    }
    x * py - yy * px + p_phi
}

/// Spin angle and rate, whether prescribed or free.
struct Velocities {
    phi: f64,
    spin_rate: f64,
}

impl Velocities {
    fn new(system: &RotorSystem, t: f64, y: &[f64]) -> Self {
        let (phi, spin_rate) = system.spin(t, y);
        Velocities { phi, spin_rate }
    }
}
