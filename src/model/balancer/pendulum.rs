//! Pendulum balancer: a bob on a light arm pivoting on the shaft.
//!
//! The design's weight (radius r = ρR, a solid sphere of density γ) is the bob,
//! its centre on the circle l = R − r like a ball's; the arm is massless. The
//! bob turns with the arm, so J_C = 2/5 m r² and κ = 1 + J_C/(m l²) (seed 004,
//! eq 9); there is no rolling coupling with the rotor's acceleration.

use super::{Geometry, WeightModel};
use crate::design::capacity::weight_mass;
use crate::design::{DesignError, Shape};
use crate::model::cargo::Cargo;

/// The pendulum kind.
pub struct Pendulum;

impl WeightModel for Pendulum {
    fn shape(&self) -> Shape {
        Shape::Ball
    }
    fn cargo(&self, g: &Geometry) -> Result<Cargo, DesignError> {
        let m = weight_mass(
            Shape::Ball,
            g.density,
            g.race_radius,
            g.rho,
            g.roller_height,
        )?;
        let (r, l) = (g.weight_radius(), g.track_radius());
        Ok(Cargo::point(m, l, g.drag, 1.0 + 0.4 * r * r / (l * l)))
    }
}
