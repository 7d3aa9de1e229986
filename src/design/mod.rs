//! Analytic design theory of ball and roller auto-balancers (seed 000).
//!
//! Everything here is a pure function of the race radius ratio ρ = r/R, the
//! number of weights n and, for dimensional results, the material density γ,
//! the race radius R and the roller height h. Angles are in radians unless a
//! name says `_deg`.
//!
//! [`criterion`] holds seed 003's empirical criterion for the rigid rotor on
//! two elastic supports (resonances, extra speed, balancing speed ranges).
//!
//! Where to start: [`capacity::dimensionless_capacity`] (eq 9),
//! [`optimum::optimal_rho`] (Table 1) and [`transient`] (eqs 1, 2, 10–16).

pub mod capacity;
pub mod complete;
pub mod criterion;
pub mod error;
pub mod geometry;
pub mod optimum;
pub mod table;
pub mod transient;

pub use error::DesignError;

use serde::{Deserialize, Serialize};

/// Shape of the corrective weights covered by the capacity theory of seed 000.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// Solid spheres rolling in a race: m = 4/3 π r³ γ.
    Ball,
    /// Solid cylinders of height h rolling in a race: m = π r² h γ.
    Roller,
}

impl Shape {
    /// Both shapes, in the order the paper's Table 1 lists them.
    pub const ALL: [Shape; 2] = [Shape::Ball, Shape::Roller];

    /// Power of ρ in the dimensionless weight mass (ρ³ for balls, ρ² for rollers).
    pub fn mass_exponent(self) -> i32 {
        match self {
            Shape::Ball => 3,
            Shape::Roller => 2,
        }
    }

    /// Lower-case name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Shape::Ball => "ball",
            Shape::Roller => "roller",
        }
    }
}

impl std::fmt::Display for Shape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Shape {
    type Err = DesignError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "ball" => Ok(Shape::Ball),
            "roller" => Ok(Shape::Roller),
            other => Err(DesignError::UnknownShape(other.to_string())),
        }
    }
}
