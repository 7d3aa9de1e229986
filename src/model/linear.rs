//! Linear stability of the balanced state, for any rotor model.
//!
//! At constant speed ω with isotropic supports (and no gravity) the equations
//! are autonomous in the frame turning with the rotor: with q = R(ωt) q_r on
//! every coordinate pair (see the [`Rotor`](super::rotor::Rotor) conventions)
//! and ψ already relative to the rotor,
//! q̈_r = R⁻¹q̈ − 2ωJ q̇_r + ω² q_r (J the quarter turn of each pair).
//! The balanced state, where the rotor does not move in that frame, is then a
//! fixed point: we find it by damped Newton from the balancing cargo fans,
//! differentiate the rotating-frame right-hand side numerically (central
//! differences) and take the eigenvalues of the Jacobian (nalgebra's
//! Schur-based `complex_eigenvalues`). This is equivalent to a Routh–Hurwitz
//! test of the characteristic polynomial (seed 002, eq 29).
//!
//! n ≥ 3 weights in one plane balance on an (n − 2)-dimensional family of
//! positions: its neutral directions give as many zero eigenvalues, which are
//! set aside; stability and the slowest decay rate refer to the others.

use super::forced::unbalance_forcing;
use super::rotor::MAX_DOF;
use super::start::balanced_fan;
use super::system::RotorSystem;
use crate::integrate::OdeSystem;
use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::Serialize;
use std::f64::consts::PI;

/// Why the linearisation is not available.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinearError {
    /// The speed law is not a constant speed.
    #[error("linear stability needs a constant speed law")]
    NotConstantSpeed,
    /// The rotating-frame equations depend on time (anisotropic supports, gravity).
    #[error(
        "the equations are not autonomous in the rotating frame (anisotropic supports or gravity): relative change {0:.2e}"
    )]
    NotAutonomous(f64),
    /// The QR iteration of the eigenvalue solver hit its iteration bound.
    #[error(
        "the eigenvalues of the {dim} × {dim} Jacobian did not converge within {iterations} QR iterations"
    )]
    EigenvaluesDidNotConverge {
        /// Size of the Jacobian.
        dim: usize,
        /// The bound that was reached.
        iterations: usize,
    },
    /// Newton did not find a steady state in the rotating frame.
    #[error("no steady state found near the balancing positions (residual {0:.2e})")]
    NoSteadyState(f64),
}

/// The outcome of the linear analysis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinearReport {
    /// Speed ω (rad/s).
    pub omega: f64,
    /// True when every eigenvalue other than the neutral ones has Re λ < 0.
    pub stable: bool,
    /// σ = min(−Re λ) over the non-neutral eigenvalues (negative: unstable), 1/s.
    pub slowest_decay: f64,
    /// The eigenvalue that sets σ (re, im).
    pub slowest: (f64, f64),
    /// Every eigenvalue (re, im), sorted by decreasing real part.
    pub eigenvalues: Vec<(f64, f64)>,
    /// Number of eigenvalues set aside as the balanced family's neutral directions.
    pub neutral: usize,
    /// The steady state in the rotating frame: [q_r, ψ, q̇_r, ψ̇].
    pub state: Vec<f64>,
    /// Size of the total unbalance at the steady state over U (0: fully balanced).
    pub balancing_error: f64,
}

impl LinearReport {
    /// Linear prediction of the settling time from a deviation of relative size `from` to the band δ: ln(from/δ)/σ.
    pub fn settling_time(&self, from: f64, delta: f64) -> f64 {
        (from / delta).ln() / self.slowest_decay
    }
}

/// The rotating-frame vector field of a constant-speed system.
pub struct RotatingFrame<'a> {
    system: &'a RotorSystem,
    omega: f64,
}

impl<'a> RotatingFrame<'a> {
    /// The rotating frame of `system`; its speed law must be constant.
    pub fn new(system: &'a RotorSystem) -> Result<Self, LinearError> {
        match *system.speed() {
            super::speed::SpeedLaw::Constant { omega } => Ok(RotatingFrame { system, omega }),
            _ => Err(LinearError::NotConstantSpeed),
        }
    }

    /// Time derivative of the rotating-frame state z, evaluated at time t.
    pub fn rhs_at(&self, t: f64, z: &[f64], dz: &mut [f64]) {
        let lay = self.system.layout();
        let (k, nq) = (lay.rotor_dof, lay.nq());
        let w = self.omega;
        let (s, c) = (w * t).sin_cos();
        let turn = |v: &[f64], sign: f64, out: &mut [f64]| {
            for p in 0..k / 2 {
                let (a, b) = (v[2 * p], v[2 * p + 1]);
                out[2 * p] = c * a - sign * s * b;
                out[2 * p + 1] = sign * s * a + c * b;
            }
        };
        let mut y = z.to_vec();
        let mut vel = [0.0; MAX_DOF];
        for p in 0..k / 2 {
            // q̇_r + ωJ q_r, J(a, b) = (−b, a).
            vel[2 * p] = z[nq + 2 * p] - w * z[2 * p + 1];
            vel[2 * p + 1] = z[nq + 2 * p + 1] + w * z[2 * p];
        }
        turn(&z[..k], 1.0, &mut y[..k]);
        turn(&vel[..k], 1.0, &mut y[nq..nq + k]);
        let mut dy = vec![0.0; y.len()];
        self.system.rhs(t, &y, &mut dy);
        dz.copy_from_slice(&dy);
        dz[..nq].copy_from_slice(&z[nq..]);
        let mut acc = [0.0; MAX_DOF];
        turn(&dy[nq..nq + k], -1.0, &mut acc[..k]);
        for p in 0..k / 2 {
            let (a, b) = (2 * p, 2 * p + 1);
            dz[nq + a] = acc[a] + 2.0 * w * z[nq + b] + w * w * z[a];
            dz[nq + b] = acc[b] - 2.0 * w * z[nq + a] + w * w * z[b];
        }
    }

    /// Numerical Jacobian ∂ż/∂z by central differences.
    pub fn jacobian(&self, z: &[f64]) -> DMatrix<f64> {
        let n = z.len();
        let mut jac = DMatrix::zeros(n, n);
        let (mut zp, mut zm) = (z.to_vec(), z.to_vec());
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        for col in 0..n {
            let h = 1e-6 * (1.0 + z[col].abs());
            zp[col] = z[col] + h;
            zm[col] = z[col] - h;
            self.rhs_at(0.0, &zp, &mut fp);
            self.rhs_at(0.0, &zm, &mut fm);
            for row in 0..n {
                jac[(row, col)] = (fp[row] - fm[row]) / (2.0 * h);
            }
            zp[col] = z[col];
            zm[col] = z[col];
        }
        jac
    }
}

/// Plane unbalances U_p (kg·m, at φ = 0) that cancel the rotor's own
/// unbalance as well as the planes can (least squares over the rotor coordinates).
pub fn correction_unbalances(system: &RotorSystem) -> Vec<Complex64> {
    let rotor = system.rotor();
    let (k, planes) = (rotor.dof(), rotor.planes());
    let (fc, _) = unbalance_forcing(system, &[], true);
    // Columns: Re U_p → G_u, Im U_p → G_v (the cos part of the forcing).
    let mut a = DMatrix::zeros(k, 2 * planes);
    for p in 0..planes {
        let [gu, gv] = rotor.plane_map(p);
        for i in 0..k {
            a[(i, 2 * p)] = gu[i];
            a[(i, 2 * p + 1)] = gv[i];
        }
    }
    let b = DMatrix::from_iterator(k, 1, fc[..k].iter().map(|v| -v));
    let x = a
        .clone()
        .svd(true, true)
        .solve(&b, 1e-12)
        .unwrap_or_else(|_| DMatrix::zeros(2 * planes, 1));
    (0..planes)
        .map(|p| Complex64::new(x[2 * p], x[2 * p + 1]))
        .collect()
}

/// Initial guess of the cargo angles: in each plane a fan that produces the
/// plane's correction unbalance, or the closest the cargoes can reach.
pub fn balancing_angles(system: &RotorSystem) -> Vec<f64> {
    let targets = correction_unbalances(system);
    let cargo = system.cargo();
    let mut psi = vec![0.0; cargo.len()];
    for (p, target) in targets.iter().enumerate() {
        let members: Vec<usize> = (0..cargo.len()).filter(|&j| cargo[j].plane == p).collect();
        if members.is_empty() {
            continue;
        }
        let ml = members.iter().map(|&j| cargo[j].unbalance()).sum::<f64>() / members.len() as f64;
        let cap = ml * members.len() as f64;
        let size = target.norm().min(cap * (1.0 - 1e-9));
        // balanced_fan cancels an unbalance at `direction`: ask for the opposite one.
        let fan = balanced_fan(members.len(), ml, size, target.arg() + PI)
            .unwrap_or_else(|| vec![target.arg(); members.len()]);
        for (&j, a) in members.iter().zip(fan) {
            psi[j] = a;
        }
    }
    psi
}

/// The steady state in the rotating frame near the cargo angles `psi0`
/// (damped Newton on the full state; the balanced families make the
/// Jacobian singular, so each step is a Levenberg–Marquardt step).
pub fn steady_state(frame: &RotatingFrame<'_>, psi0: &[f64]) -> Result<Vec<f64>, LinearError> {
    let lay = frame.system.layout();
    let (k, nq) = (lay.rotor_dof, lay.nq());
    let mut z = vec![0.0; 2 * nq];
    z[k..nq].copy_from_slice(psi0);
    // Start the rotor on the forced response to what the cargoes leave unbalanced.
    let (fc, fs) = unbalance_forcing(frame.system, psi0, true);
    if let Some(h) = super::forced::harmonic_response(frame.system, &fc, &fs, frame.omega) {
        z[..k].copy_from_slice(&h.cos[..k]);
    }
    let n = z.len();
    let mut f = vec![0.0; n];
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    frame.rhs_at(0.0, &z, &mut f);
    let scale = 1.0 + norm(&z);
    let mut res = norm(&f);
    let mut mu = 1e-8;
    for _ in 0..100 {
        if res < 1e-13 * scale {
            break;
        }
        let jac = frame.jacobian(&z);
        let jt = jac.transpose();
        let jtj = &jt * &jac;
        let g = &jt * DMatrix::from_column_slice(n, 1, &f);
        let mut improved = false;
        for _ in 0..30 {
            let mut lhs = jtj.clone();
            for i in 0..n {
                lhs[(i, i)] += mu * (1.0 + jtj[(i, i)]);
            }
            let Some(step) = lhs.lu().solve(&g) else {
                mu *= 10.0;
                continue;
            };
            let trial: Vec<f64> = z.iter().zip(step.iter()).map(|(a, d)| a - d).collect();
            let mut ft = vec![0.0; n];
            frame.rhs_at(0.0, &trial, &mut ft);
            let rt = norm(&ft);
            if rt < res {
                z = trial;
                f = ft;
                res = rt;
                mu = (mu * 0.1).max(1e-14);
                improved = true;
                break;
            }
            mu *= 10.0;
        }
        if !improved {
            break;
        }
    }
    if res < 1e-9 * scale {
        Ok(z)
    } else {
        Err(LinearError::NoSteadyState(res))
    }
}

/// QR iterations allowed per eigenvalue: LAPACK's dhseqr allows 30; a few
/// more cost nothing and leave room for clustered eigenvalues.
const SCHUR_ITERATIONS_PER_EIGENVALUE: usize = 50;

/// Linear stability of the balanced state of a constant-speed system, from
/// the cargo angles `psi0` (the balancing fans when `None`).
pub fn analyse(system: &RotorSystem, psi0: Option<&[f64]>) -> Result<LinearReport, LinearError> {
    let frame = RotatingFrame::new(system)?;
    let guess = match psi0 {
        Some(p) => p.to_vec(),
        None => balancing_angles(system),
    };
    let z = steady_state(&frame, &guess)?;
    check_autonomous(&frame, &z)?;
    let jac = frame.jacobian(&z);
    // nalgebra's `complex_eigenvalues` iterates without a limit (and was seen
    // to spin forever on small weights on a flexible shaft); the Schur form
    // with a bounded QR iteration count either converges or says so.
    let dim = jac.nrows();
    let max_iterations = SCHUR_ITERATIONS_PER_EIGENVALUE * dim;
    let schur = nalgebra::linalg::Schur::try_new(jac, f64::EPSILON, max_iterations).ok_or(
        LinearError::EigenvaluesDidNotConverge {
            dim,
            iterations: max_iterations,
        },
    )?;
    let mut eig: Vec<(f64, f64)> = schur
        .complex_eigenvalues()
        .iter()
        .map(|c| (c.re, c.im))
        .collect();
    eig.sort_by(|a, b| b.0.total_cmp(&a.0).then(b.1.total_cmp(&a.1)));
    // Neutral directions of the balanced families: n_p − 2 per plane.
    let planes = system.rotor().planes();
    let expected: usize = (0..planes)
        .map(|p| {
            let n = system.cargo().iter().filter(|c| c.plane == p).count();
            n.saturating_sub(2)
        })
        .sum();
    let biggest = eig.iter().map(|e| e.0.hypot(e.1)).fold(0.0, f64::max);
    let mut by_size: Vec<usize> = (0..eig.len()).collect();
    by_size.sort_by(|&a, &b| {
        eig[a]
            .0
            .hypot(eig[a].1)
            .total_cmp(&eig[b].0.hypot(eig[b].1))
    });
    let neutral: Vec<usize> = by_size
        .into_iter()
        .take(expected)
        .filter(|&i| eig[i].0.hypot(eig[i].1) < 1e-6 * biggest.max(1.0))
        .collect();
    let (slowest, decay) = eig
        .iter()
        .enumerate()
        .filter(|(i, _)| !neutral.contains(i))
        .map(|(_, e)| (*e, -e.0))
        .fold(((0.0, 0.0), f64::INFINITY), |acc, x| {
            if x.1 < acc.1 { x } else { acc }
        });
    let lay = system.layout();
    let psi = &z[lay.rotor_dof..lay.nq()];
    let u_ref = crate::model::unbalance::reference_unbalance(system);
    Ok(LinearReport {
        omega: frame.omega,
        stable: decay > 0.0,
        slowest_decay: decay,
        slowest,
        eigenvalues: eig,
        neutral: neutral.len(),
        balancing_error: crate::model::unbalance::balancing_error(system, psi, u_ref),
        state: z,
    })
}

/// The rotating-frame field must not depend on time.
fn check_autonomous(frame: &RotatingFrame<'_>, z: &[f64]) -> Result<(), LinearError> {
    let n = z.len();
    // A state off the fixed point, so that every term is exercised.
    let probe: Vec<f64> = z
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-3 * (1.0 + 0.37 * i as f64).sin())
        .collect();
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    frame.rhs_at(0.0, &probe, &mut a);
    frame.rhs_at(0.731 / frame.omega.max(1e-9), &probe, &mut b);
    let size = a.iter().map(|x| x.abs()).fold(0.0, f64::max).max(1e-300);
    let diff = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / size;
    if diff > 1e-9 {
        Err(LinearError::NotAutonomous(diff))
    } else {
        Ok(())
    }
}
