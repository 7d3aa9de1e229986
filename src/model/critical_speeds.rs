//! Undamped natural frequencies and critical speeds of a rotor with its
//! weights locked, for any rotor model: what a user compares with the
//! resonances measured on a rig before trusting anything else.
//!
//! With the damping left out, the rotor coordinates obey
//! M_Σ q̈ + G(Ω) q̇ + K q = 0, with M_Σ the rotor's mass matrix plus the
//! weights' masses, K read off the rotor's elastic forces and G(Ω) its
//! gyroscopic matrix at spin Ω (the velocity matrix at Ω less the one at
//! rest, which is the damping alone). The natural frequencies at Ω are the
//! |Im λ| of the quadratic eigenproblem λ²M_Σ + λG + K = 0. A critical
//! speed is a spin at which one of them equals the spin itself: the
//! synchronous resonance an unbalance excites on a run-up.

use super::forced::stiffness_and_damping;
use super::rotor::{DofVec, MAX_DOF};
use super::system::RotorSystem;
use nalgebra::DMatrix;

/// Bisection steps on a bracketed critical speed (relative width 2⁻⁶⁰).
const BISECTIONS: usize = 60;

/// Points of the coarse scan of the spin range that brackets critical speeds.
const SCAN_POINTS: usize = 400;

/// Natural frequencies (rad/s, ascending, each once) of the undamped rotor
/// with its weights locked, spinning at `spin` rad/s; `None` when the mass
/// matrix is singular or the eigenvalues do not converge.
pub fn natural_frequencies(system: &RotorSystem, spin: f64) -> Option<Vec<f64>> {
    let k = system.rotor().dof();
    let (stiffness, velocity) = stiffness_and_damping(system, spin);
    let (_, damping) = stiffness_and_damping(system, 0.0);
    let mass = matrix(system.head_mass(), k);
    let mass_inv = mass.try_inverse()?;
    let gyro = matrix(&velocity, k) - matrix(&damping, k);
    // First-order form z = (q, q̇): ż = [[0, I], [−M⁻¹K, −M⁻¹G]] z.
    let mut a = DMatrix::zeros(2 * k, 2 * k);
    a.view_mut((0, k), (k, k)).fill_with_identity();
    a.view_mut((k, 0), (k, k))
        .copy_from(&(-&mass_inv * matrix(&stiffness, k)));
    a.view_mut((k, k), (k, k)).copy_from(&(-&mass_inv * gyro));
    let schur = nalgebra::linalg::Schur::try_new(a, f64::EPSILON, 10_000)?;
    let mut freqs: Vec<f64> = schur
        .complex_eigenvalues()
        .iter()
        .filter(|l| l.im > 0.0)
        .map(|l| l.im)
        .collect();
    freqs.sort_by(f64::total_cmp);
    Some(freqs)
}

/// Critical speeds (rad/s, ascending) in (0, `max_spin`]: the spins Ω at
/// which a natural frequency at Ω equals Ω. Without gyroscopic terms they
/// are the natural frequencies themselves.
pub fn critical_speeds(system: &RotorSystem, max_spin: f64) -> Option<Vec<f64>> {
    // f_i(Ω) − Ω changes sign at each critical speed; the i-th frequency is
    // continuous in Ω, so a bracket on a fine scan refines by bisection.
    let gap = |spin: f64, i: usize| -> Option<f64> {
        natural_frequencies(system, spin)?.get(i).map(|f| f - spin)
    };
    let count = natural_frequencies(system, 0.0)?.len();
    let mut speeds = Vec::new();
    for i in 0..count {
        let mut lo = 0.0;
        let mut g_lo = gap(lo, i)?;
        for step in 1..=SCAN_POINTS {
            let hi = max_spin * step as f64 / SCAN_POINTS as f64;
            let g_hi = gap(hi, i)?;
            if g_lo > 0.0 && g_hi <= 0.0 {
                let (mut a, mut b) = (lo, hi);
                for _ in 0..BISECTIONS {
                    let mid = 0.5 * (a + b);
                    if gap(mid, i)? > 0.0 {
                        a = mid;
                    } else {
                        b = mid;
                    }
                }
                speeds.push(0.5 * (a + b));
                break;
            }
            (lo, g_lo) = (hi, g_hi);
        }
    }
    speeds.sort_by(f64::total_cmp);
    Some(speeds)
}

/// The leading k × k block of a rotor matrix as a nalgebra matrix.
fn matrix(m: &[DofVec; MAX_DOF], k: usize) -> DMatrix<f64> {
    DMatrix::from_fn(k, k, |r, c| m[r][c])
}

/// Critical speeds (rad/s) up to three times the highest natural frequency
/// at rest (where gyroscopic stiffening has room to show): the list a user
/// compares with a rig's measured resonances.
pub fn critical_speeds_in_range(system: &RotorSystem) -> Option<Vec<f64>> {
    let rest = natural_frequencies(system, 0.0)?;
    let top = rest.last().copied().filter(|f| *f > 0.0)?;
    critical_speeds(system, 3.0 * top)
}
