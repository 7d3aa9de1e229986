//! The rigid axisymmetric rotor on two elastic supports of seed 003
//! (eqs 2–3), carrying auto-balancers in any number of planes z_p. Seed 003's
//! supports are isotropic; each support may also be stiffer (or more damped)
//! along x than along y, as real bearing pedestals are: the x–β and y–α
//! planes then have their own k11, k14, k33 (below).
//!
//! Coordinates q = (x, y, α, β): the centre of mass G's displacement and the
//! small Resal angles of the axis about x and y, so that the axis point at z
//! moves by (x + zβ, y − zα) (eq 24). Supports of stiffness k1 at z = −l1
//! and k2 at z = +l2, viscous dampers b1, b2 beside them; `k1y`, `k2y`,
//! `b1y`, `b2y`, when given, are the y values and k1, k2, b1, b2 the x ones.
//!
//! Kinetic energy (derived, small tilts):
//! T = ½M(ẋ² + ẏ²) + ½A(α̇² + β̇²) + ½Cφ̇² + ½Cφ̇(α̇β − αβ̇),
//! the last term being the spin's share of the Resal angular velocity
//! φ̇ + α̇ sin β written in its rotation-invariant form (it differs from
//! Cφ̇α̇β by d/dt(½Cφ̇αβ) and a term φ̈αβ of third order). Lagrange gives eq 2
//! at constant speed (gyroscopic terms ±Cφ̇β̇, ∓Cφ̇α̇), a φ̈ coupling
//! ½C(β, −α) at variable speed, and conserves the angular momentum about the
//! axis. Potential: ½k11(x² + y²) + ½k33(α² + β²) + k14(xβ − yα), or with
//! anisotropic supports ½Σ_s k_sx (x + z_s β)² + ½Σ_s k_sy (y − z_s α)² over
//! the supports at z_s, i.e. the x and y coefficient sets of eq 3 apart.
//!
//! Cargoes are point masses in their plane: by default they see the plane
//! centre's displacement only. With `weights_tilt_inertia` their motion
//! with the tilting plane (the m R² terms, second order in the tilt in T)
//! is added by `src/model/tilt_inertia.rs`; docs/rotors.md measures when it
//! matters.
//!
//! The rotor's own unbalance: static S and moment I (eq 6) as point
//! unbalances s at z and angle θ, or directly as |S|, arg S, |I|, arg I.

use super::{ClosedFormCriterion, DofVec, MAX_DOF, Rotor, RotorParams};
use crate::model::validate::{SceneError, finite, invalid, non_negative, positive};
use num_complex::Complex64;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// One point unbalance of the rotor: s = m e (kg·m) at axial position z, angle θ.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointUnbalance {
    /// Size s = m e (kg·m).
    pub s: f64,
    /// Axial position z from the centre of mass (m).
    #[serde(default)]
    pub z: f64,
    /// Direction relative to the rotor at φ = 0 (degrees in files;
    /// the field holds radians).
    #[serde(default, rename = "angle_deg", with = "super::angle_deg")]
    #[schemars(rename = "angle_deg", with = "f64")]
    pub angle: f64,
}

/// Parameters of the two-support rotor (SI or dimensionless).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TwoSupportRotor {
    /// Rotor mass M (kg).
    pub mass: f64,
    /// Transverse moment of inertia A about the centre of mass (kg·m²).
    pub transverse_inertia: f64,
    /// Polar moment of inertia C (kg·m²).
    pub polar_inertia: f64,
    /// Stiffness of support 1 at z = −l1 (N/m).
    pub k1: f64,
    /// Distance of support 1 from the centre of mass (m).
    pub l1: f64,
    /// Stiffness of support 2 at z = +l2 (N/m).
    pub k2: f64,
    /// Distance of support 2 from the centre of mass (m).
    pub l2: f64,
    /// Damping at support 1 (N·s/m).
    #[serde(default)]
    pub b1: f64,
    /// Damping at support 2 (N·s/m).
    #[serde(default)]
    pub b2: f64,
    /// Stiffness of support 1 along y (N/m); absent: `k1` (isotropic).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k1y: Option<f64>,
    /// Stiffness of support 2 along y (N/m); absent: `k2` (isotropic).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k2y: Option<f64>,
    /// Damping at support 1 along y (N·s/m); absent: `b1`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b1y: Option<f64>,
    /// Damping at support 2 along y (N·s/m); absent: `b2`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b2y: Option<f64>,
    /// Axial positions z_p of the balancer planes (m), plane p = index.
    pub planes: Vec<f64>,
    /// Static unbalance |S| (kg·m), added to the point unbalances.
    #[serde(default)]
    pub static_unbalance: f64,
    /// Direction of the static unbalance at φ = 0 (degrees in files;
    /// the field holds radians).
    #[serde(default, rename = "static_angle_deg", with = "super::angle_deg")]
    #[schemars(rename = "static_angle_deg", with = "f64")]
    pub static_angle: f64,
    /// Moment unbalance |I| (kg·m²), added to the point unbalances.
    #[serde(default)]
    pub moment_unbalance: f64,
    /// Direction of the moment unbalance at φ = 0 (degrees in files;
    /// the field holds radians).
    #[serde(default, rename = "moment_angle_deg", with = "super::angle_deg")]
    #[schemars(rename = "moment_angle_deg", with = "f64")]
    pub moment_angle: f64,
    /// Point unbalances.
    #[serde(default)]
    pub unbalances: Vec<PointUnbalance>,
    /// Model the weights' tilt inertia, the m R² terms of seed 002's eqs
    /// 22–23: a weight at radius l adds m l² (α̇ sin φ_j − β̇ cos φ_j)²/2 and
    /// m l² φ̇_j (α̇β − αβ̇)/2 to the kinetic energy (prescribed speed only).
    #[serde(default)]
    pub weights_tilt_inertia: bool,
}

impl TwoSupportRotor {
    /// k11, k14, k33 of eq 3 for stiffnesses (a1, a2) at the supports.
    fn combine(&self, a1: f64, a2: f64) -> (f64, f64, f64) {
        (
            a1 + a2,
            a2 * self.l2 - a1 * self.l1,
            a1 * self.l1 * self.l1 + a2 * self.l2 * self.l2,
        )
    }

    /// Total static unbalance S and moment unbalance I (eq 6) at φ = 0.
    pub fn unbalance(&self) -> (Complex64, Complex64) {
        let mut s = Complex64::from_polar(self.static_unbalance, self.static_angle);
        let mut i = Complex64::from_polar(self.moment_unbalance, self.moment_angle);
        for u in &self.unbalances {
            let e = Complex64::from_polar(u.s, u.angle);
            s += e;
            i += e * u.z;
        }
        (s, i)
    }

    /// Bearing-equivalent unbalances (U1, U2) at z = −l1 and z = +l2 of (S, I):
    /// U1 + U2 = S, −l1 U1 + l2 U2 = I.
    pub fn bearing_unbalances(&self, s: Complex64, i: Complex64) -> (Complex64, Complex64) {
        let span = self.l1 + self.l2;
        ((self.l2 * s - i) / span, (self.l1 * s + i) / span)
    }

    /// Stiffnesses (k1, k2) and dampings (b1, b2) of the supports along y.
    fn y_supports(&self) -> ((f64, f64), (f64, f64)) {
        (
            (self.k1y.unwrap_or(self.k1), self.k2y.unwrap_or(self.k2)),
            (self.b1y.unwrap_or(self.b1), self.b2y.unwrap_or(self.b2)),
        )
    }

    /// True when both supports are the same along x and y (seed 003's
    /// rotor, whose criterion and rotating frame assume it).
    pub fn is_isotropic(&self) -> bool {
        self.y_supports() == ((self.k1, self.k2), (self.b1, self.b2))
    }

    /// The parameters of seed 003's criterion for this rotor (isotropic
    /// supports: the x values).
    pub fn criterion_params(&self) -> crate::design::criterion::TwoSupportParams {
        crate::design::criterion::TwoSupportParams {
            mass: self.mass,
            transverse_inertia: self.transverse_inertia,
            polar_inertia: self.polar_inertia,
            k1: self.k1,
            l1: self.l1,
            k2: self.k2,
            l2: self.l2,
        }
    }
}

impl Rotor for TwoSupportRotor {
    fn name(&self) -> &'static str {
        "two_support"
    }

    /// The axis at z moves by (x + zβ, y − zα): supports at z = −l1, +l2.
    fn bearing_maps(&self) -> Vec<[DofVec; 2]> {
        [-self.l1, self.l2]
            .map(|z| [[1.0, 0.0, 0.0, z], [0.0, 1.0, -z, 0.0]])
            .to_vec()
    }

    fn closed_form_criterion(&self) -> Result<ClosedFormCriterion, &'static str> {
        if !self.is_isotropic() {
            return Err(
                "rotor.k1y, k2y, b1y, b2y: seed 003's closed-form criterion is derived for isotropic supports; `study sweep` simulates an anisotropic rotor",
            );
        }
        Ok(ClosedFormCriterion {
            params: self.criterion_params(),
            planes: self.planes.clone(),
        })
    }

    fn dof(&self) -> usize {
        4
    }

    fn planes(&self) -> usize {
        self.planes.len()
    }

    fn plane_map(&self, plane: usize) -> [DofVec; 2] {
        let z = self.planes[plane];
        [[1.0, 0.0, 0.0, z], [0.0, 1.0, -z, 0.0]]
    }

    /// The balancer planes, then every point unbalance's plane that is not
    /// one of them (a load between or beyond the balancers).
    fn watch_maps(&self) -> Vec<[DofVec; 2]> {
        let mut places = self.planes.clone();
        for u in &self.unbalances {
            if !places.contains(&u.z) {
                places.push(u.z);
            }
        }
        places
            .into_iter()
            .map(|z| [[1.0, 0.0, 0.0, z], [0.0, 1.0, -z, 0.0]])
            .collect()
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
        self.polar_inertia
    }

    fn forces(&self, q: &[f64], qd: &[f64], spin_rate: f64, f: &mut DofVec) {
        // x–β plane with the x supports, y–α plane with the y supports.
        let (k11, k14, k33) = self.combine(self.k1, self.k2);
        let (c11, c14, c33) = self.combine(self.b1, self.b2);
        let ((k1y, k2y), (b1y, b2y)) = self.y_supports();
        let (k11y, k14y, k33y) = self.combine(k1y, k2y);
        let (c11y, c14y, c33y) = self.combine(b1y, b2y);
        let (x, y, a, b) = (q[0], q[1], q[2], q[3]);
        let (xd, yd, ad, bd) = (qd[0], qd[1], qd[2], qd[3]);
        let gyro = self.polar_inertia * spin_rate;
        f[0] -= k11 * x + k14 * b + c11 * xd + c14 * bd;
        f[1] -= k11y * y - k14y * a + c11y * yd - c14y * ad;
        f[2] -= k33y * a - k14y * y + c33y * ad - c14y * yd + gyro * bd;
        f[3] -= k33 * b + k14 * x + c33 * bd + c14 * xd - gyro * ad;
    }

    fn spin_coupling(&self, phi: f64, q: &[f64]) -> DofVec {
        let (s, i) = self.unbalance();
        let rot = Complex64::from_polar(1.0, phi);
        let (s, i) = (s * rot, i * rot);
        let half_c = 0.5 * self.polar_inertia;
        // ∂/∂q̇ of φ̇ Σ s_j (−sin(φ+θ_j) u̇ + cos(φ+θ_j) v̇) with u = x + zβ, v = y − zα,
        // plus the gyroscopic ½C(β, −α).
        [-s.im, s.re, -i.re + half_c * q[3], -i.im - half_c * q[2]]
    }

    fn unbalance_forces(&self, phi: f64, spin_rate: f64, f: &mut DofVec) {
        let (s, i) = self.unbalance();
        let rot = Complex64::from_polar(spin_rate * spin_rate, phi);
        let (s, i) = (s * rot, i * rot);
        // Eq 2's right-hand sides.
        f[0] += s.re;
        f[1] += s.im;
        f[2] -= i.im;
        f[3] += i.re;
    }

    fn static_unbalance(&self) -> (f64, f64) {
        let (s, _) = self.unbalance();
        (s.norm(), s.arg())
    }

    fn own_unbalance(&self) -> f64 {
        let (s, i) = self.unbalance();
        let (u1, u2) = self.bearing_unbalances(s, i);
        u1.norm().max(u2.norm())
    }

    fn unbalance_size(&self, f: &DofVec) -> f64 {
        // f = (Re S, Im S, −Im I, Re I) of an unbalance at φ = 0.
        let s = Complex64::new(f[0], f[1]);
        let i = Complex64::new(f[3], -f[2]);
        let (u1, u2) = self.bearing_unbalances(s, i);
        u1.norm().max(u2.norm())
    }

    fn plane_unbalance_sizes(&self, f: &DofVec) -> Option<Vec<f64>> {
        let &[z1, z2] = self.planes.as_slice() else {
            return None;
        };
        // U1 + U2 = S and z1 U1 + z2 U2 = I, as for the bearings.
        let s = Complex64::new(f[0], f[1]);
        let i = Complex64::new(f[3], -f[2]);
        let span = z2 - z1;
        Some(vec![
            ((z2 * s - i) / span).norm(),
            ((i - z1 * s) / span).norm(),
        ])
    }
}

impl RotorParams for TwoSupportRotor {
    fn validate(&self) -> Result<(), SceneError> {
        positive("rotor.mass", self.mass)?;
        positive("rotor.transverse_inertia", self.transverse_inertia)?;
        positive("rotor.polar_inertia", self.polar_inertia)?;
        positive("rotor.k1", self.k1)?;
        positive("rotor.k2", self.k2)?;
        non_negative("rotor.b1", self.b1)?;
        non_negative("rotor.b2", self.b2)?;
        for (name, k) in [("rotor.k1y", self.k1y), ("rotor.k2y", self.k2y)] {
            k.map_or(Ok(()), |k| positive(name, k))?;
        }
        for (name, b) in [("rotor.b1y", self.b1y), ("rotor.b2y", self.b2y)] {
            b.map_or(Ok(()), |b| non_negative(name, b))?;
        }
        non_negative("rotor.static_unbalance", self.static_unbalance)?;
        non_negative("rotor.moment_unbalance", self.moment_unbalance)?;
        for (name, v) in [
            ("rotor.l1", self.l1),
            ("rotor.l2", self.l2),
            ("rotor.static_angle_deg", self.static_angle),
            ("rotor.moment_angle_deg", self.moment_angle),
        ] {
            finite(name, v)?;
        }
        if self.l1 + self.l2 <= 0.0 {
            return Err(invalid(
                "rotor.l2",
                self.l2,
                "the supports must be apart: l1 + l2 > 0",
            ));
        }
        if self.planes.is_empty() {
            return Err(SceneError::Invalid {
                field: "rotor.planes".into(),
                value: "[]".into(),
                reason: "give the axial position of at least one balancer plane".into(),
            });
        }
        if self.planes.len() > crate::model::validate::MAX_PLANES {
            return Err(SceneError::Invalid {
                field: "rotor.planes".into(),
                value: format!("{} planes", self.planes.len()),
                reason: format!(
                    "at most {} balancer planes: each plane adds a balancer's equations, and no machine carries more",
                    crate::model::validate::MAX_PLANES
                ),
            });
        }
        for (p, &z) in self.planes.iter().enumerate() {
            finite(&format!("rotor.planes[{p}]"), z)?;
        }
        for (j, u) in self.unbalances.iter().enumerate() {
            non_negative(&format!("rotor.unbalances[{j}].s"), u.s)?;
            finite(&format!("rotor.unbalances[{j}].z"), u.z)?;
            finite(&format!("rotor.unbalances[{j}].angle_deg"), u.angle)?;
        }
        Ok(())
    }

    /// A point unbalance U in every balancer plane: what each plane's
    /// balancer must take.
    fn set_unbalance(&mut self, unbalance: f64, direction: f64) {
        self.static_unbalance = 0.0;
        self.moment_unbalance = 0.0;
        self.unbalances = self
            .planes
            .iter()
            .map(|&z| PointUnbalance {
                s: unbalance,
                z,
                angle: direction,
            })
            .collect();
    }

    fn clear_unbalance(&mut self) {
        self.static_unbalance = 0.0;
        self.moment_unbalance = 0.0;
        self.unbalances.clear();
    }
}
