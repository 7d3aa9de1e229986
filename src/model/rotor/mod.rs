//! Rotor models: the rigid-body (or elastic) coordinates that carry the
//! balancer planes. One file per model; each implements [`Rotor`].
//!
//! The equations of every model share one structure (MODEL-NOTES, seed 004):
//! the rotor's coordinates h (k ≤ [`MAX_DOF`]) and, when the speed is free,
//! the spin angle φ form a small "head" block; every cargo adds one diagonal
//! row coupled only to that block. [`crate::model::system`] eliminates the
//! cargo rows and solves the head block, so a rotor model only has to say
//! what its own mass, forces, unbalance and balancer planes are.

pub mod plane;

pub use plane::PlaneRotor;

/// Largest number of rotor coordinates a model may have (x, y and two tilts).
pub const MAX_DOF: usize = 4;

/// A fixed-size vector over the rotor coordinates (only the first `dof()` used).
pub type DofVec = [f64; MAX_DOF];

/// What a rotor model contributes to the equations of motion.
pub trait Rotor: Send + Sync + std::fmt::Debug {
    /// Short name used in output rows.
    fn name(&self) -> &'static str;
    /// Number of rotor coordinates k (2 for the plane rotor: x, y).
    fn dof(&self) -> usize;
    /// Number of balancer planes the rotor carries.
    fn planes(&self) -> usize;
    /// Rows G_u, G_v of the map from rotor coordinates to the displacement
    /// (u, v) of balancer plane `plane`'s centre.
    fn plane_map(&self, plane: usize) -> [DofVec; 2];
    /// Constant mass matrix of the rotor alone over its coordinates (k × k).
    fn mass_matrix(&self) -> [DofVec; MAX_DOF];
    /// Polar moment of inertia J_P of the rotor about its spin axis.
    fn spin_inertia(&self) -> f64;
    /// Elastic, damping and gyroscopic forces on the rotor coordinates,
    /// added into `f`, at spin speed `spin_rate`.
    fn forces(&self, q: &[f64], qd: &[f64], spin_rate: f64, f: &mut DofVec);
    /// Mass-matrix column coupling the rotor coordinates with φ̈ through the
    /// rotor's own unbalance, at spin angle φ (∂²T/∂q̇∂φ̇).
    fn spin_coupling(&self, phi: f64) -> DofVec;
    /// Centrifugal forces of the rotor's own unbalance at spin angle φ and
    /// rate φ̇ (the −d/dt of [`Rotor::spin_coupling`] times φ̇), added into `f`.
    fn unbalance_forces(&self, phi: f64, spin_rate: f64, f: &mut DofVec);
    /// Static unbalance of the rotor itself (kg·m) and its direction at φ = 0,
    /// for gravity torques and balancing-error metrics.
    fn static_unbalance(&self) -> (f64, f64);
}
