//! The weights' tilt inertia: the m R² terms of seed 002 (eqs 22–23) that a
//! point mass in a tilting balancer plane adds to the equations.
//!
//! A weight at radius l and angle φ_j = φ + ψ_j in a plane tilted by the small
//! rotation vector (α, β, 0) (axis direction (β, −α, 1), the convention of
//! the `two_support` and `flexible` rotors) sits at R_tilt·l e(φ_j) from the
//! plane's centre. With the tilt's angular velocity
//! (α̇, β̇, ½(αβ̇ − βα̇)) to second order, its speed relative to that centre is
//! exactly, to second order in the tilt,
//!
//!   |v|² = l² [φ̇_j² + (α̇ sin φ_j − β̇ cos φ_j)² + φ̇_j (α̇β − αβ̇)].
//!
//! The first term is the weight's motion along the race, already in the
//! model; the in-plane shrinking of the tilted position cancels the
//! φ̇_j²(α cos φ_j + β sin φ_j)² that the axial velocity alone would give.
//! The two others, with μ = m l², D = α̇ sin φ_j − β̇ cos φ_j and
//! G = α̇β − αβ̇, are T_tilt = ½ μ D² + ½ μ φ̇_j G. Averaged over three or more
//! evenly spread weights they are exactly a rigid disc's ½(n μ/2)(α̇² + β̇²)
//! and ½(n μ) φ̇ G: transverse inertia n m l²/2 and polar n m l², the terms
//! of the rotor's own kinetic energy. Lagrange's equations give
//!
//!   α row:  μ [sin² α̈ − sin cos β̈ + 2 φ̇_j sin (α̇ cos + β̇ sin) + ½ β φ̈_j]
//!   β row: −μ [sin cos α̈ − cos² β̈ + 2 φ̇_j cos (α̇ cos + β̇ sin) + ½ α φ̈_j]
//!   ψ_j row: ½ μ (β α̈ − α β̈) − μ D (α̇ cos + β̇ sin),
//!
//! a symmetric mass matrix (μ J Jᵀ on the tilt, ½ μ K between tilt and ψ_j
//! with J = sin T_α − cos T_β and K = β T_α − α T_β) plus velocity forces:
//! the weights' arrowhead stays an arrowhead. At variable speed the spin row
//! would gain the ψ_j row's terms; that is not modelled, so scenes with a
//! motor or a free rotor refuse the option.

use super::rotor::{DofVec, MAX_DOF};

/// One weight's tilt-inertia terms at the current state, over the rotor
/// coordinates (k of them).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TiltTerms {
    /// μ = m l².
    pub mu: f64,
    /// J = sin φ_j T_α − cos φ_j T_β (D = J·q̇).
    pub jac: DofVec,
    /// ½ μ K = ½ μ (β T_α − α T_β): couples ψ̈_j and φ̈ with the rotor rows.
    pub coupling: DofVec,
    /// 2 μ φ̇_j (α̇ cos φ_j + β̇ sin φ_j): the rotor rows' velocity force is −this·J.
    pub rotor_force: f64,
    /// μ D (α̇ cos φ_j + β̇ sin φ_j): the velocity force on ψ_j.
    pub cargo_force: f64,
}

impl TiltTerms {
    /// The terms of a weight of mass `mass` on track radius `l` at angle φ_j
    /// (sin, cos), moving at φ̇_j = `rate`, in a plane with tilt map `tilt`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn at(
        tilt: &[DofVec; 2],
        k: usize,
        mass: f64,
        l: f64,
        (s, c): (f64, f64),
        rate: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Self {
        let [ta, tb] = tilt;
        let dot = |t: &DofVec, v: &[f64]| (0..k).map(|i| t[i] * v[i]).sum::<f64>();
        let (alpha, beta) = (dot(ta, q), dot(tb, q));
        let (alpha_dot, beta_dot) = (dot(ta, qd), dot(tb, qd));
        let mu = mass * l * l;
        let mut jac = [0.0; MAX_DOF];
        let mut coupling = [0.0; MAX_DOF];
        for i in 0..k {
            jac[i] = s * ta[i] - c * tb[i];
            coupling[i] = 0.5 * mu * (beta * ta[i] - alpha * tb[i]);
        }
        let d = alpha_dot * s - beta_dot * c;
        let turning = alpha_dot * c + beta_dot * s;
        TiltTerms {
            mu,
            jac,
            coupling,
            rotor_force: 2.0 * mu * rate * turning,
            cargo_force: mu * d * turning,
        }
    }
}
