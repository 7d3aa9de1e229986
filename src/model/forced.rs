//! The steady forced response of the rotor coordinates to rotating
//! unbalances with the cargoes locked: q(t) = a cos ωt + b sin ωt solves
//! M_Σ q̈ + C q̇ + K q = ω² (f_c cos ωt + f_s sin ωt), i.e.
//! (K − ω²M_Σ) a + ωC b = ω² f_c and (K − ω²M_Σ) b − ωC a = ω² f_s,
//! with K and C (damping plus gyroscopic) read off the rotor's linear forces
//! and M_Σ including the cargoes' masses. Any rotor model, anisotropic
//! supports included.

use super::rotor::{DofVec, MAX_DOF};
use super::system::RotorSystem;

/// A harmonic motion of the rotor coordinates, q(t) = cos·cos ωt + sin·sin ωt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Harmonic {
    /// Coefficients of cos ωt.
    pub cos: DofVec,
    /// Coefficients of sin ωt.
    pub sin: DofVec,
}

/// Generalised unbalance force per ω² of the rotor's own unbalance and of
/// cargoes locked at angles `psi` (relative to the rotor), split into the
/// parts multiplying cos ωt and sin ωt when φ = ωt.
pub fn unbalance_forcing(system: &RotorSystem, psi: &[f64], with_rotor: bool) -> (DofVec, DofVec) {
    let rotor = system.rotor();
    let k = rotor.dof();
    let (mut fc, mut fs) = ([0.0; MAX_DOF], [0.0; MAX_DOF]);
    if with_rotor {
        // The unbalance force is cos φ·f(0) + sin φ·(coupling at φ = 0).
        rotor.unbalance_forces(0.0, 1.0, &mut fc);
        fs = rotor.spin_coupling(0.0, &[0.0; MAX_DOF]);
    }
    for (j, (c, &p)) in system.cargo().iter().zip(psi).enumerate() {
        let [gu, gv] = system.cargo_plane_map(j);
        let (s, co) = super::trig::sin_cos(p);
        let ml = c.unbalance();
        for i in 0..k {
            fc[i] += ml * (co * gu[i] + s * gv[i]);
            fs[i] += ml * (co * gv[i] - s * gu[i]);
        }
    }
    (fc, fs)
}

/// Stiffness K and velocity matrix C (damping plus gyroscopic at spin rate
/// ω) of the rotor, column by column from its linear forces.
pub fn stiffness_and_damping(
    system: &RotorSystem,
    omega: f64,
) -> ([DofVec; MAX_DOF], [DofVec; MAX_DOF]) {
    let rotor = system.rotor();
    let k = rotor.dof();
    let (mut km, mut cm) = ([[0.0; MAX_DOF]; MAX_DOF], [[0.0; MAX_DOF]; MAX_DOF]);
    for col in 0..k {
        let mut unit = [0.0; MAX_DOF];
        unit[col] = 1.0;
        let mut f = [0.0; MAX_DOF];
        rotor.forces(&unit, &[0.0; MAX_DOF], omega, &mut f);
        for row in 0..k {
            km[row][col] = -f[row];
        }
        let mut f = [0.0; MAX_DOF];
        rotor.forces(&[0.0; MAX_DOF], &unit, omega, &mut f);
        for row in 0..k {
            cm[row][col] = -f[row];
        }
    }
    (km, cm)
}

/// True when the rotor's supports look the same from every direction about
/// the spin axis at speed ω: its stiffness and velocity matrices commute with
/// the quarter turn J of each coordinate pair (x, y), (α, β), within a
/// relative 10⁻¹² of their size. Otherwise its equations in the rotating
/// frame depend on time, and no balanced state there is steady.
pub fn supports_isotropic(system: &RotorSystem, omega: f64) -> bool {
    let k = system.rotor().dof();
    let (km, cm) = stiffness_and_damping(system, omega);
    // (J A)[r][c] with J(a, b) = (−b, a) on each pair.
    let turn_rows = |a: &[DofVec; MAX_DOF], r: usize, c: usize| {
        if r.is_multiple_of(2) {
            -a[r + 1][c]
        } else {
            a[r - 1][c]
        }
    };
    let turn_cols = |a: &[DofVec; MAX_DOF], r: usize, c: usize| {
        if c.is_multiple_of(2) {
            a[r][c + 1]
        } else {
            -a[r][c - 1]
        }
    };
    [km, cm].iter().all(|a| {
        let size = (0..k)
            .flat_map(|r| (0..k).map(move |c| (r, c)))
            .map(|(r, c)| a[r][c].abs())
            .fold(0.0, f64::max);
        (0..k).all(|r| {
            (0..k).all(|c| (turn_rows(a, r, c) - turn_cols(a, r, c)).abs() <= 1e-12 * size)
        })
    })
}

/// The steady response to the unbalance forcing (f_c, f_s) at speed ω;
/// `None` when the dynamic stiffness is singular (undamped resonance).
pub fn harmonic_response(
    system: &RotorSystem,
    fc: &DofVec,
    fs: &DofVec,
    omega: f64,
) -> Option<Harmonic> {
    harmonic_response_with(system, system.head_mass(), fc, fs, omega)
}

/// [`harmonic_response`] with a given mass matrix (e.g. the rotor's alone).
pub fn harmonic_response_with(
    system: &RotorSystem,
    mass: &[DofVec; MAX_DOF],
    fc: &DofVec,
    fs: &DofVec,
    omega: f64,
) -> Option<Harmonic> {
    let k = system.rotor().dof();
    let (km, cm) = stiffness_and_damping(system, omega);
    let w2 = omega * omega;
    let n = 2 * k;
    let mut a = vec![vec![0.0; n + 1]; n];
    for r in 0..k {
        for c in 0..k {
            let d = km[r][c] - w2 * mass[r][c];
            a[r][c] = d;
            a[r][k + c] = omega * cm[r][c];
            a[k + r][c] = -omega * cm[r][c];
            a[k + r][k + c] = d;
        }
        a[r][n] = w2 * fc[r];
        a[k + r][n] = w2 * fs[r];
    }
    let x = solve_dense(a)?;
    let (mut cos, mut sin) = ([0.0; MAX_DOF], [0.0; MAX_DOF]);
    cos[..k].copy_from_slice(&x[..k]);
    sin[..k].copy_from_slice(&x[k..]);
    Some(Harmonic { cos, sin })
}

/// Largest radius of plane p's orbit (the larger singular value of the
/// 2 × 2 map from (cos ωt, sin ωt) to the plane's (u, v)).
pub fn plane_orbit_radius(h: &Harmonic, map: &[DofVec; 2]) -> f64 {
    plane_orbit_axes(h, map).0
}

/// Semi-axes (major, minor) of plane p's elliptic orbit: the singular
/// values of the 2 × 2 map from (cos ωt, sin ωt) to the plane's (u, v).
pub fn plane_orbit_axes(h: &Harmonic, map: &[DofVec; 2]) -> (f64, f64) {
    let dot = |g: &DofVec, v: &DofVec| g.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
    let (au, bu) = (dot(&map[0], &h.cos), dot(&map[0], &h.sin));
    let (av, bv) = (dot(&map[1], &h.cos), dot(&map[1], &h.sin));
    let t = au * au + bu * bu + av * av + bv * bv;
    let d = au * bv - bu * av;
    let root = (t * t - 4.0 * d * d).max(0.0).sqrt();
    (
        (0.5 * (t + root)).sqrt(),
        (0.5 * (t - root)).max(0.0).sqrt(),
    )
}

/// How far a unit unbalance (1 kg·m) turning with the rotor in balancer
/// plane `plane` moves that plane's centre at speed ω, the rotor alone (no
/// weights' mass): the orbit's minor semi-axis (m per kg·m), so that the
/// unbalance needed to hold the plane centre a distance e off its orbit is
/// at most e over it. On the plane rotor it is ω²/|k − Mω² + ibω| per axis.
/// `None` at an undamped resonance.
pub fn plane_compliance(system: &RotorSystem, plane: usize, omega: f64) -> Option<f64> {
    let rotor = system.rotor();
    let [gu, gv] = rotor.plane_map(plane);
    let h = harmonic_response_with(system, &rotor.mass_matrix(), &gu, &gv, omega)?;
    Some(plane_orbit_axes(&h, &[gu, gv]).1)
}

/// Gaussian elimination with partial pivoting on an augmented matrix.
fn solve_dense(mut a: Vec<Vec<f64>>) -> Option<Vec<f64>> {
    let n = a.len();
    for col in 0..n {
        let pivot = (col..n).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))?;
        if a[pivot][col] == 0.0 || !a[pivot][col].is_finite() {
            return None;
        }
        a.swap(col, pivot);
        for row in col + 1..n {
            let f = a[row][col] / a[col][col];
            if f != 0.0 {
                for c in col..=n {
                    a[row][c] -= f * a[col][c];
                }
            }
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let mut sum = a[row][n];
        for c in row + 1..n {
            sum -= a[row][c] * x[c];
        }
        x[row] = sum / a[row][row];
    }
    Some(x)
}
