//! The flexible (Stodola–Green) rotor of seed 002: a disc of mass M, polar
//! and transverse moments of inertia J_z and J, at the free end of a
//! massless shaft of length L and bending stiffness EI clamped at the other
//! end, with a ball balancer in the disc's plane.
//!
//! Coordinates q = (x, y, α, β): the disc centre's deflection and its small
//! tilts about x and y (slopes dx/dz = β, dy/dz = −α). The shaft's strain
//! energy (eqs 15–16) for tip deflection D and slope Φ is
//! ½(12EI/L³ D² − 12EI/L² DΦ + 4EI/L Φ²) per bending plane, i.e.
//! V = ½k11(x² + y²) + ½k33(α² + β²) + k14(xβ − yα) with k11 = 12EI/L³,
//! k14 = −6EI/L², k33 = 4EI/L (the coefficients of eqs 20–23). Viscous
//! damping c_t on the deflection and c_r on the tilt (eq 17 with the factor
//! ½ that its dimensionless form eq 30 implies). Kinetic energy and
//! gyroscopic terms as for the rigid rotor (`two_support`): J_z φ̇ couples
//! α̇ and β̇ (eqs 22–23 in the rotating frame: (J_z − 2J)ω and (J_z − J)ω²).
//! The disc's eccentricity ε is its static unbalance M ε.
//!
//! As in `two_support`, the balls are point masses in the disc plane; the
//! m R² terms of eqs 22–23 (their motion with the tilting disc, about
//! m R²/J = 4 m/M of the tilt inertia) are added by `weights_tilt_inertia`.

use super::centre_unbalance::{CentreUnbalance, planar_size};
use super::{DofVec, MAX_DOF, Rotor, RotorParams};
use crate::model::validate::{SceneError, finite, non_negative, positive};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Parameters of the flexible rotor (SI or dimensionless).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FlexibleShaft {
    /// Disc mass M (kg).
    pub mass: f64,
    /// Transverse moment of inertia J = J_x = J_y of the disc (kg·m²).
    pub transverse_inertia: f64,
    /// Polar moment of inertia J_z of the disc (kg·m²).
    pub polar_inertia: f64,
    /// Bending stiffness EI of the shaft (N·m²).
    pub ei: f64,
    /// Shaft length L from the clamp to the disc (m).
    pub length: f64,
    /// Translational damping c_t (N·s/m).
    #[serde(default)]
    pub c_t: f64,
    /// Rotational damping c_r (N·m·s).
    #[serde(default)]
    pub c_r: f64,
    /// Eccentricity ε of the disc's centre of mass (m).
    #[serde(default)]
    pub eccentricity: f64,
    /// Direction of the eccentricity at φ = 0 (degrees in files;
    /// the field holds radians).
    #[serde(default, rename = "unbalance_angle_deg", with = "super::angle_deg")]
    #[schemars(rename = "unbalance_angle_deg", with = "f64")]
    pub unbalance_angle: f64,
    /// Model the weights' tilt inertia, the m R² terms of seed 002's eqs
    /// 22–23: a weight at radius l adds m l² (α̇ sin φ_j − β̇ cos φ_j)²/2 and
    /// m l² φ̇_j (α̇β − αβ̇)/2 to the kinetic energy (prescribed speed only).
    #[serde(default)]
    pub weights_tilt_inertia: bool,
}

impl FlexibleShaft {
    /// The shaft of seed 002's Section "Simulation" in units M = R = ω0 = 1:
    /// L/R = `l_over_r`, J = MR²/4, J_z = MR²/2 (eq 26), dampings ζ_t, ζ_r of
    /// eq 30 and eccentricity ε/R.
    pub fn dimensionless(l_over_r: f64, zeta_t: f64, zeta_r: f64, eps_over_r: f64) -> Self {
        let (m, r, w0) = (1.0, 1.0, 1.0);
        let length = l_over_r * r;
        let ei = m * length.powi(3) * w0 * w0 / 48.0;
        let j = m * r * r / 4.0;
        FlexibleShaft {
            mass: m,
            transverse_inertia: j,
            polar_inertia: m * r * r / 2.0,
            ei,
            length,
            c_t: 4.0 * zeta_t * (3.0 * m * ei / length.powi(3)).sqrt(),
            c_r: 4.0 * zeta_r * (j * ei / length).sqrt(),
            eccentricity: eps_over_r * r,
            unbalance_angle: 0.0,
            weights_tilt_inertia: false,
        }
    }

    /// Reference frequency ω0 = √(48EI/(ML³)) (eq 30).
    pub fn omega0(&self) -> f64 {
        (48.0 * self.ei / (self.mass * self.length.powi(3))).sqrt()
    }

    /// ζ_t = (c_t/4) √(L³/(3MEI)) (eq 30): the damping ratio of the deflection alone.
    pub fn zeta_t(&self) -> f64 {
        0.25 * self.c_t * (self.length.powi(3) / (3.0 * self.mass * self.ei)).sqrt()
    }

    /// ζ_r = (c_r/4) √(L/(J EI)) (eq 30): the damping ratio of the tilt alone.
    pub fn zeta_r(&self) -> f64 {
        0.25 * self.c_r * (self.length / (self.transverse_inertia * self.ei)).sqrt()
    }

    /// k11, k14, k33 of the clamped shaft at the disc.
    pub fn stiffness(&self) -> (f64, f64, f64) {
        let (ei, l) = (self.ei, self.length);
        (12.0 * ei / l.powi(3), -6.0 * ei / (l * l), 4.0 * ei / l)
    }
}

impl Rotor for FlexibleShaft {
    fn name(&self) -> &'static str {
        "flexible"
    }

    fn dof(&self) -> usize {
        4
    }

    fn planes(&self) -> usize {
        1
    }

    fn plane_map(&self, _plane: usize) -> [DofVec; 2] {
        [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]
    }

    fn tilt_map(&self, _plane: usize) -> Option<[DofVec; 2]> {
        self.weights_tilt_inertia
            .then_some([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    }

    fn mass_matrix(&self) -> [DofVec; MAX_DOF] {
        let mut m = [[0.0; MAX_DOF]; MAX_DOF];
        m[0][0] = self.mass;
        m[1][1] = self.mass;
        m[2][2] = self.transverse_inertia;
        m[3][3] = self.transverse_inertia;
        m
    }

    fn spin_inertia(&self) -> f64 {
        self.polar_inertia + self.mass * self.eccentricity * self.eccentricity
    }

    fn forces(&self, q: &[f64], qd: &[f64], spin_rate: f64, f: &mut DofVec) {
        let (k11, k14, k33) = self.stiffness();
        let (x, y, a, b) = (q[0], q[1], q[2], q[3]);
        let (xd, yd, ad, bd) = (qd[0], qd[1], qd[2], qd[3]);
        let gyro = self.polar_inertia * spin_rate;
        f[0] -= k11 * x + k14 * b + self.c_t * xd;
        f[1] -= k11 * y - k14 * a + self.c_t * yd;
        f[2] -= k33 * a - k14 * y + self.c_r * ad + gyro * bd;
        f[3] -= k33 * b + k14 * x + self.c_r * bd - gyro * ad;
    }

    fn spin_coupling(&self, phi: f64, q: &[f64]) -> DofVec {
        let [u, v] = self.centre().coupling(phi);
        let half = 0.5 * self.polar_inertia;
        [u, v, half * q[3], -half * q[2]]
    }

    fn unbalance_forces(&self, phi: f64, spin_rate: f64, f: &mut DofVec) {
        self.centre().add_forces(phi, spin_rate, f);
    }

    fn static_unbalance(&self) -> (f64, f64) {
        self.centre().static_unbalance()
    }

    fn own_unbalance(&self) -> f64 {
        self.centre().size()
    }

    fn unbalance_size(&self, f: &DofVec) -> f64 {
        planar_size(f)
    }
}

impl RotorParams for FlexibleShaft {
    fn validate(&self) -> Result<(), SceneError> {
        positive("rotor.mass", self.mass)?;
        positive("rotor.transverse_inertia", self.transverse_inertia)?;
        positive("rotor.polar_inertia", self.polar_inertia)?;
        positive("rotor.ei", self.ei)?;
        positive("rotor.length", self.length)?;
        non_negative("rotor.c_t", self.c_t)?;
        non_negative("rotor.c_r", self.c_r)?;
        non_negative("rotor.eccentricity", self.eccentricity)?;
        finite("rotor.unbalance_angle_deg", self.unbalance_angle)
    }

    fn set_unbalance(&mut self, unbalance: f64, direction: f64) {
        self.eccentricity = unbalance / self.mass;
        self.unbalance_angle = direction;
    }

    fn clear_unbalance(&mut self) {
        self.eccentricity = 0.0;
    }
}

impl FlexibleShaft {
    /// The rotor's own unbalance, as the mass centre's offset.
    fn centre(&self) -> CentreUnbalance {
        CentreUnbalance {
            mass: self.mass,
            eccentricity: self.eccentricity,
            angle: self.unbalance_angle,
        }
    }
}
