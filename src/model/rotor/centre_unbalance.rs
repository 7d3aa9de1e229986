//! The unbalance of a rotor whose mass centre sits at eccentricity e from
//! the shaft centre, at angle α to the rotor's x axis: the plane rotor and
//! the flexible shaft carry it alike, so it is written here once.

use super::DofVec;

/// Mass M, eccentricity e and angle α of a rotor's own unbalance M e.
#[derive(Debug, Clone, Copy)]
pub(super) struct CentreUnbalance {
    /// Rotor mass M (kg).
    pub mass: f64,
    /// Eccentricity e of the mass centre (m).
    pub eccentricity: f64,
    /// Its direction relative to the rotor at φ = 0 (rad).
    pub angle: f64,
}

impl CentreUnbalance {
    /// M e (kg·m).
    pub fn size(&self) -> f64 {
        self.mass * self.eccentricity
    }

    /// (M e, α): the static unbalance and its direction at φ = 0.
    pub fn static_unbalance(&self) -> (f64, f64) {
        (self.mass * self.eccentricity, self.angle)
    }

    /// The spin coupling of the translation: ∂(centre position)/∂φ times M,
    /// (−M e sin(φ + α), M e cos(φ + α)).
    pub fn coupling(&self, phi: f64) -> [f64; 2] {
        let me = self.mass * self.eccentricity;
        let (s, c) = crate::model::trig::sin_cos(phi + self.angle);
        [-me * s, me * c]
    }

    /// Adds the centrifugal force M e φ̇² (cos, sin)(φ + α) to the translation.
    pub fn add_forces(&self, phi: f64, spin_rate: f64, f: &mut DofVec) {
        let me = self.mass * self.eccentricity * spin_rate * spin_rate;
        let (s, c) = crate::model::trig::sin_cos(phi + self.angle);
        f[0] += me * c;
        f[1] += me * s;
    }
}

/// The size of an unbalance force per φ̇² on the translation: |(f_x, f_y)|.
pub(super) fn planar_size(f: &DofVec) -> f64 {
    f[0].hypot(f[1])
}
