//! One compensating cargo (ball, roller or pendulum) as the equations see it.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Physical parameters of one cargo, whatever its kind.
///
/// The cargo's centre of mass runs on a circle of radius `track_radius` (l)
/// about its plane's centre; `kappa` (κ) scales its inertia to κ m l² about
/// that centre; balls and rollers additionally couple with the rotor's
/// angular acceleration through rolling without slip (seed 004, eqs 15, 17).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Cargo {
    /// Mass m (kg).
    pub mass: f64,
    /// Radius l of the circle of the centre of mass (m).
    pub track_radius: f64,
    /// Viscous coefficient β of the resistance to motion relative to the race (N·s/m).
    pub drag: f64,
    /// Inertia factor κ: 7/5 ball, 3/2 roller, 1 + J_C/(m l²) pendulum.
    pub kappa: f64,
    /// Rolling coupling J_C (l/r)(l/r + 1) with the rotor's angular
    /// acceleration (kg·m²); zero for pendulums.
    #[serde(default)]
    pub rolling_coupling: f64,
    /// Extra rotor inertia J_C (l/r + 1)² from rolling (kg·m²); zero for pendulums.
    #[serde(default)]
    pub rolling_inertia: f64,
    /// Index of the balancer plane the cargo runs in.
    #[serde(default)]
    pub plane: usize,
    /// Radius r of the weight (m), for the optional contact effect; 0 for
    /// cargoes that can pass each other (pendulums on separate arms, points).
    #[serde(default)]
    pub radius: f64,
}

impl Cargo {
    /// Inertia κ m l² of the cargo about its plane's centre.
    pub fn inertia(&self) -> f64 {
        self.kappa * self.mass * self.track_radius * self.track_radius
    }

    /// Unbalance m l the cargo can contribute (kg·m).
    pub fn unbalance(&self) -> f64 {
        self.mass * self.track_radius
    }

    /// Half the smallest centre angle α = asin(r/l) at which this weight
    /// touches a neighbour of its own size (0 for a point mass).
    pub fn contact_half_angle(&self) -> f64 {
        if self.radius > 0.0 {
            (self.radius / self.track_radius).min(1.0).asin()
        } else {
            0.0
        }
    }

    /// A pendulum-like cargo with a given κ and no rolling coupling (for tests and custom designs).
    pub fn point(mass: f64, track_radius: f64, drag: f64, kappa: f64) -> Self {
        Cargo {
            mass,
            track_radius,
            drag,
            kappa,
            rolling_coupling: 0.0,
            rolling_inertia: 0.0,
            plane: 0,
            radius: 0.0,
        }
    }
}
