//! Initial states of a run.
//!
//! The default, `locked_steady`, starts the rotor in the forced steady state
//! it would have with the cargoes locked at their initial positions (any
//! rotor model: [`crate::model::forced`]) and
//! releases the cargoes with zero relative speed: settling time then measures
//! the balancer, not the decay of the start-up whirl through the support
//! damping (which is what starting from rest at full speed measures).

use super::forced::{harmonic_response, unbalance_forcing};
use super::system::RotorSystem;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// How the rotor and cargoes start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum StartMode {
    /// Rotor in the forced steady state with the cargoes locked; cargoes released at t = 0.
    #[default]
    LockedSteady,
    /// Rotor at rest (no vibration) at full speed: shows the start-up whirl.
    Rest,
    /// The system balanced for another unbalance; the unbalance has just jumped
    /// (cargo angles balanced for the old direction, rotor quiet).
    Step,
    /// Variable speed from rest (use with a motor or ramp speed law).
    Runup,
}

/// Initial state for `mode` with cargo angles `psi0` relative to the rotor.
///
/// The cargoes always start with zero speed relative to the rotor; the spin
/// starts at the speed law's initial rate.
pub fn initial_state(system: &RotorSystem, mode: StartMode, psi0: &[f64]) -> Vec<f64> {
    let lay = system.layout();
    let nq = lay.nq();
    let mut y = vec![0.0; lay.dim()];
    for (j, &psi) in psi0.iter().enumerate() {
        y[lay.psi(j)] = psi;
    }
    let rate = system.speed().initial_rate();
    if lay.spin_free {
        y[nq + lay.phi()] = rate;
    }
    if mode == StartMode::LockedSteady {
        if is_plane_translation(system) {
            let [x, xd, yy, yd] = locked_response(system, psi0, rate);
            y[0] = x;
            y[1] = yy;
            y[nq] = xd;
            y[nq + 1] = yd;
        } else {
            let (mut fc, mut fs) = unbalance_forcing(system, psi0, true);
            // An off-centre race carries the weights' mass off the axis too.
            system.effects_locked_forcing(&mut fc, &mut fs);
            if let Some(h) = harmonic_response(system, &fc, &fs, rate) {
                // At t = 0: q = a, q̇ = ω b.
                for i in 0..lay.rotor_dof {
                    y[i] = h.cos[i];
                    y[nq + i] = rate * h.sin[i];
                }
            }
        }
    }
    y
}

/// True for a rotor whose two coordinates are its single plane's (x, y):
/// the plane rotor, whose locked response has a closed form per axis.
pub fn is_plane_translation(system: &RotorSystem) -> bool {
    let rotor = system.rotor();
    rotor.dof() == 2 && rotor.planes() == 1
}

/// Forced steady state (x, ẋ, y, ẏ) at t = 0 of the plane rotor spinning at ω
/// (the closed form of [`harmonic_response`] for two uncoupled axes)
/// with the cargoes locked at `psi0`: each axis answers the rotating total
/// unbalance U e^{i(ωt+θ)} as M_Σ ẍ + b ẋ + k x = ω² U cos(ωt + θ).
pub fn locked_response(system: &RotorSystem, psi0: &[f64], omega: f64) -> [f64; 4] {
    let (ux, uy) = total_unbalance(system, psi0);
    // With an off-centre race the weights' own mass is carried at e_r too
    // (on the plane rotor the cos φ part is (U_x, U_y) itself).
    let (mut extra, mut turned) = ([0.0; super::rotor::MAX_DOF], [0.0; super::rotor::MAX_DOF]);
    system.effects_locked_forcing(&mut extra, &mut turned);
    let (ux, uy) = if extra[..2] == [0.0, 0.0] {
        (ux, uy)
    } else {
        (ux + extra[0], uy + extra[1])
    };
    let rotor = system.rotor();
    let m_total = rotor.mass_matrix()[0][0] + system.cargo().iter().map(|c| c.mass).sum::<f64>();
    // Support stiffness and damping along each axis, read off the rotor's forces.
    let axis = |i: usize| {
        let mut f = [0.0; super::rotor::MAX_DOF];
        let mut q = [0.0; super::rotor::MAX_DOF];
        q[i] = 1.0;
        rotor.forces(&q, &[0.0; super::rotor::MAX_DOF], omega, &mut f);
        let k = -f[i];
        let mut f = [0.0; super::rotor::MAX_DOF];
        rotor.forces(&[0.0; super::rotor::MAX_DOF], &q, omega, &mut f);
        (k, -f[i])
    };
    let w2 = omega * omega;
    // x = Re[ω² U e^{iωt} / D], D = k − M_Σ ω² + i b ω, with U = ux + i uy.
    let response = |k: f64, b: f64, ure: f64, uim: f64| {
        let (dre, dim) = (k - m_total * w2, b * omega);
        let den = dre * dre + dim * dim;
        let re = w2 * (ure * dre + uim * dim) / den;
        let im = w2 * (uim * dre - ure * dim) / den;
        (re, -omega * im)
    };
    let (kx, bx) = axis(0);
    let (ky, by) = axis(1);
    let (x, xd) = response(kx, bx, ux, uy);
    // y is driven by sin: −i U.
    let (y, yd) = response(ky, by, uy, -ux);
    [x, xd, y, yd]
}

/// Total unbalance (kg·m) of rotor and cargoes at φ = 0 as (U_x, U_y).
pub fn total_unbalance(system: &RotorSystem, psi: &[f64]) -> (f64, f64) {
    let cargo = system.cargo().iter().map(|c| c.unbalance());
    add_cargo_unbalance(rotor_unbalance(system), cargo.zip(psi.iter().copied()))
}

/// The rotor's own unbalance (kg·m) at φ = 0 as (U_x, U_y).
pub(crate) fn rotor_unbalance(system: &RotorSystem) -> (f64, f64) {
    let (me, angle) = system.rotor().static_unbalance();
    let (sa, ca) = super::trig::sin_cos(angle);
    (me * ca, me * sa)
}

/// `start` plus each cargo's unbalance m l e^{iψ}, given as (m l, ψ) pairs,
/// added in order (so that every caller gets the same bits).
pub(crate) fn add_cargo_unbalance(
    start: (f64, f64),
    cargo: impl Iterator<Item = (f64, f64)>,
) -> (f64, f64) {
    let (mut ux, mut uy) = start;
    for (u, p) in cargo {
        let (s, co) = super::trig::sin_cos(p);
        ux += u * co;
        uy += u * s;
    }
    (ux, uy)
}

/// Angles of n equal cargoes, each of unbalance `cargo_unbalance` (m l), that
/// cancel an unbalance of magnitude `unbalance` at angle `direction`: a fan
/// symmetric about the opposite direction with equal spacing δ solving
/// sin(nδ/2)/sin(δ/2) = unbalance/cargo_unbalance. `None` when it cannot be
/// balanced (more than the cargoes' total, or one cargo of another size).
pub fn balanced_fan(
    n: usize,
    cargo_unbalance: f64,
    unbalance: f64,
    direction: f64,
) -> Option<Vec<f64>> {
    let ratio = unbalance / cargo_unbalance;
    let nf = n as f64;
    if n == 0 || !(0.0..=nf).contains(&ratio) {
        return None;
    }
    if n == 1 {
        return ((ratio - 1.0).abs() < 1e-12).then(|| vec![direction + PI]);
    }
    let sum = |delta: f64| {
        if delta < 1e-12 {
            nf
        } else {
            (nf * delta / 2.0).sin() / (delta / 2.0).sin()
        }
    };
    // sum decreases from n at δ = 0 to 0 at δ = 2π/n: bisection is exact enough.
    let (mut lo, mut hi) = (0.0, 2.0 * PI / nf);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if sum(mid) > ratio { lo = mid } else { hi = mid }
    }
    let delta = 0.5 * (lo + hi);
    Some(
        (0..n)
            .map(|j| direction + PI + (j as f64 - (nf - 1.0) / 2.0) * delta)
            .collect(),
    )
}
