//! Ball balancer: solid spheres rolling without slip, J_C = 2/5 m r², κ = 7/5.

use super::{Geometry, WeightModel, rolling_cargo};
use crate::design::capacity::weight_mass;
use crate::design::{DesignError, Shape};
use crate::model::cargo::Cargo;

/// The ball kind.
pub struct Ball;

impl WeightModel for Ball {
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
        Ok(rolling_cargo(m, 2.0 / 5.0, g))
    }
}
