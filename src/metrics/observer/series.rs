//! The series a run records: the sampled time history of the whirl, the
//! balancing error and the weights.

/// A sampled time history: t, x, y, r, ε and every ψ_j.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Rotor coordinate x (shaft centre, or centre of mass on two supports).
    pub x: Vec<f64>,
    /// Rotor coordinate y.
    pub y: Vec<f64>,
    /// Vibration r (sqrt(x² + y²) for the plane rotor; see `reference::vibration`).
    pub r: Vec<f64>,
    /// Balancing error ε.
    pub eps: Vec<f64>,
    /// Cargo angles relative to the rotor, one vector per cargo (rad).
    pub psi: Vec<Vec<f64>>,
}
