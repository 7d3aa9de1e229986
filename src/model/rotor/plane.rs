//! The plane rotor of seed 004: mass M with eccentricity e on anisotropic
//! viscoelastic supports (k_x, k_y, b_x, b_y); one balancer plane at the
//! shaft centre. Coordinates x, y of the shaft centre from static equilibrium.

use super::centre_unbalance::{CentreUnbalance, planar_size};
use super::{DofVec, IsotropicPlane, MAX_DOF, Rotor, RotorParams};
use crate::model::validate::{SceneError, invalid, non_negative, positive};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Parameters of the plane rotor (any consistent units, SI in study files).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlaneRotor {
    /// Rotor mass M (kg).
    pub mass: f64,
    /// Eccentricity e of the rotor's centre of mass (m); in studies the
    /// sampled unbalance sets it.
    #[serde(default)]
    pub eccentricity: f64,
    /// Direction ψ₀ of the unbalance relative to the rotor at φ = 0
    /// (degrees in files; the field holds radians).
    #[serde(default, rename = "unbalance_angle_deg", with = "super::angle_deg")]
    #[schemars(rename = "unbalance_angle_deg", with = "f64")]
    pub unbalance_angle: f64,
    /// Polar moment of inertia J_C about the rotor's centre of mass (kg·m²);
    /// J_P = J_C + M e² enters at variable speed only.
    #[serde(default = "default_inertia")]
    pub inertia: f64,
    /// Support stiffness along X (N/m).
    pub kx: f64,
    /// Support stiffness along Y (N/m).
    pub ky: f64,
    /// Support damping along X (N·s/m).
    pub bx: f64,
    /// Support damping along Y (N·s/m).
    pub by: f64,
}

fn default_inertia() -> f64 {
    1.0
}

impl PlaneRotor {
    /// An isotropic rotor (k_x = k_y = k, b_x = b_y = b).
    pub fn isotropic(mass: f64, eccentricity: f64, k: f64, b: f64) -> Self {
        PlaneRotor {
            mass,
            eccentricity,
            unbalance_angle: 0.0,
            inertia: 1.0,
            kx: k,
            ky: k,
            bx: b,
            by: b,
        }
    }
}

impl Rotor for PlaneRotor {
    fn name(&self) -> &'static str {
        "plane"
    }

    fn dof(&self) -> usize {
        2
    }

    fn planes(&self) -> usize {
        1
    }

    fn plane_map(&self, _plane: usize) -> [DofVec; 2] {
        [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]
    }

    fn mass_matrix(&self) -> [DofVec; MAX_DOF] {
        let mut m = [[0.0; MAX_DOF]; MAX_DOF];
        m[0][0] = self.mass;
        m[1][1] = self.mass;
        m
    }

    fn spin_inertia(&self) -> f64 {
        self.inertia + self.mass * self.eccentricity * self.eccentricity
    }

    fn forces(&self, q: &[f64], qd: &[f64], _spin_rate: f64, f: &mut DofVec) {
        f[0] -= self.kx * q[0] + self.bx * qd[0];
        f[1] -= self.ky * q[1] + self.by * qd[1];
    }

    fn spin_coupling(&self, phi: f64, _q: &[f64]) -> DofVec {
        let [u, v] = self.centre().coupling(phi);
        [u, v, 0.0, 0.0]
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

    fn isotropic_plane(&self) -> Result<IsotropicPlane, &'static str> {
        if self.kx != self.ky || self.bx != self.by {
            return Err("anisotropic supports make the rotating-frame equations time-dependent");
        }
        Ok(IsotropicPlane {
            mass: self.mass,
            stiffness: self.kx,
            damping: self.bx,
            unbalance: self.centre().size(),
            unbalance_angle: self.unbalance_angle,
        })
    }

    fn unbalance_size(&self, f: &DofVec) -> f64 {
        planar_size(f)
    }
}

impl RotorParams for PlaneRotor {
    fn validate(&self) -> Result<(), SceneError> {
        positive("rotor.mass", self.mass)?;
        non_negative("rotor.eccentricity", self.eccentricity)?;
        positive("rotor.inertia", self.inertia)?;
        positive("rotor.kx", self.kx)?;
        positive("rotor.ky", self.ky)?;
        non_negative("rotor.bx", self.bx)?;
        non_negative("rotor.by", self.by)?;
        if !self.unbalance_angle.is_finite() {
            return Err(invalid(
                "rotor.unbalance_angle_deg",
                self.unbalance_angle,
                "must be finite",
            ));
        }
        Ok(())
    }

    fn set_unbalance(&mut self, unbalance: f64, direction: f64) {
        self.eccentricity = unbalance / self.mass;
        self.unbalance_angle = direction;
    }

    fn clear_unbalance(&mut self) {
        self.eccentricity = 0.0;
    }
}

impl PlaneRotor {
    /// The rotor's own unbalance, as the mass centre's offset.
    fn centre(&self) -> CentreUnbalance {
        CentreUnbalance {
            mass: self.mass,
            eccentricity: self.eccentricity,
            angle: self.unbalance_angle,
        }
    }
}
