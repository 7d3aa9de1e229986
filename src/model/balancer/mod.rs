//! Balancer kinds: how a design (race radius R, radius ratio ρ, density,
//! roller height) becomes cargoes. One file per kind; register a new kind in
//! [`Kind`] and [`Kind::model`].

pub mod ball;
pub mod pendulum;
pub mod roller;

use super::cargo::Cargo;
use crate::design::{DesignError, Shape};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Geometry and material of one balancer's weights.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Geometry {
    /// Race radius R (m): the outer wall the weights roll on.
    pub race_radius: f64,
    /// Radius ratio ρ = r/R of the weights.
    pub rho: f64,
    /// Material density γ (kg/m³).
    pub density: f64,
    /// Roller height h (m); unused by balls and pendulums.
    pub roller_height: f64,
    /// Viscous coefficient β of each weight (N·s/m).
    pub drag: f64,
}

impl Geometry {
    /// Weight radius r = ρR.
    pub fn weight_radius(&self) -> f64 {
        self.rho * self.race_radius
    }
    /// Track radius l = R − r of the weight centres.
    pub fn track_radius(&self) -> f64 {
        self.race_radius - self.weight_radius()
    }
}

/// What a balancer kind must provide.
pub trait WeightModel {
    /// The shape whose capacity theory applies (pendulum bobs are balls).
    fn shape(&self) -> Shape;
    /// One cargo built from the geometry.
    fn cargo(&self, geometry: &Geometry) -> Result<Cargo, DesignError>;
}

/// The registered balancer kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// Balls rolling in a race ([`ball`]).
    Ball,
    /// Cylindrical rollers rolling in a race ([`roller`]).
    Roller,
    /// Pendulums pivoting on the shaft ([`pendulum`]).
    Pendulum,
}

impl Kind {
    /// Every registered kind.
    pub const ALL: [Kind; 3] = [Kind::Ball, Kind::Roller, Kind::Pendulum];

    /// The model that turns a geometry into cargoes for this kind.
    pub fn model(self) -> &'static dyn WeightModel {
        match self {
            Kind::Ball => &ball::Ball,
            Kind::Roller => &roller::Roller,
            Kind::Pendulum => &pendulum::Pendulum,
        }
    }

    /// Lower-case name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Ball => "ball",
            Kind::Roller => "roller",
            Kind::Pendulum => "pendulum",
        }
    }
}

impl std::fmt::Display for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// n identical cargoes of one kind and geometry.
pub fn cargoes(kind: Kind, n: u32, geometry: &Geometry) -> Result<Vec<Cargo>, DesignError> {
    crate::design::geometry::check_fits(n, geometry.rho)?;
    let one = kind.model().cargo(geometry)?;
    Ok(vec![one; n as usize])
}

/// A rolling weight (ball or roller) with inertia J_C = j·m r² about its centre.
pub(crate) fn rolling_cargo(mass: f64, j: f64, geometry: &Geometry) -> Cargo {
    let r = geometry.weight_radius();
    let l = geometry.track_radius();
    let jc = j * mass * r * r;
    let ratio = l / r;
    Cargo {
        mass,
        track_radius: l,
        drag: geometry.drag,
        kappa: 1.0 + j,
        rolling_coupling: jc * ratio * (ratio + 1.0),
        rolling_inertia: jc * (ratio + 1.0) * (ratio + 1.0),
        plane: 0,
        radius: r,
    }
}
