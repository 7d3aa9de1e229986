//! Roller balancer: solid cylinders rolling without slip, J_C = 1/2 m r², κ = 3/2.

use super::{Geometry, WeightModel, rolling_cargo};
use crate::design::capacity::weight_mass;
use crate::design::{DesignError, Shape};
use crate::model::cargo::Cargo;

/// The roller kind.
pub struct Roller;

impl WeightModel for Roller {
    fn shape(&self) -> Shape {
        Shape::Roller
    }
    fn cargo(&self, g: &Geometry) -> Result<Cargo, DesignError> {
        let m = weight_mass(
            Shape::Roller,
            g.density,
            g.race_radius,
            g.rho,
            g.roller_height,
        )?;
        Ok(rolling_cargo(m, 1.0 / 2.0, g))
    }
}
