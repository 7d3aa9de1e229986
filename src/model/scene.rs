//! A scene: the plain description of one simulation (rotor, balancer, speed
//! law, effects), deserialisable from TOML and validated before building.

use super::balancer::{self, Geometry, Kind};
use super::cargo::Cargo;
use super::effect::Effects;
use super::rotor::PlaneRotor;
use super::speed::SpeedLaw;
use super::system::RotorSystem;
use crate::design::optimum::optimal_rho;
use crate::design::{DesignError, geometry::rho_half_race};
use serde::{Deserialize, Serialize};

/// Everything that defines the physics of one simulation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// The rotor and its supports.
    pub rotor: PlaneRotor,
    /// The auto-balancer as a design (give this or `cargo`).
    #[serde(default)]
    pub balancer: Option<DesignSpec>,
    /// The auto-balancer as explicit cargoes (give this or `balancer`).
    #[serde(default)]
    pub cargo: Vec<Cargo>,
    /// How the spin evolves.
    pub speed: SpeedLaw,
    /// Optional effects (gravity …).
    #[serde(default)]
    pub effects: Effects,
}

/// n identical weights of one kind.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DesignSpec {
    /// Ball, roller or pendulum.
    pub kind: Kind,
    /// Number of weights.
    pub n: u32,
    /// Radius ratio ρ = r/R: a number, "optimal" (Table 1) or "half_race".
    pub rho: RhoChoice,
    /// Race radius R (m).
    pub race_radius: f64,
    /// Weight density γ (kg/m³).
    #[serde(default = "steel")]
    pub density: f64,
    /// Roller height h (m); rollers only.
    #[serde(default)]
    pub roller_height: f64,
    /// Viscous coefficient β of each weight (N·s/m).
    pub drag: f64,
}

fn steel() -> f64 {
    7850.0
}

/// How the radius ratio is chosen: a number, or the name of a rule
/// (`"optimal"`: the capacity optimum of Table 1; `"half_race"`: the weights
/// fill exactly half the race).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RhoChoice {
    /// A given ρ.
    Value(f64),
    /// A named rule, checked when the spec is resolved.
    Rule(String),
}

impl DesignSpec {
    /// The radius ratio this spec resolves to.
    pub fn resolved_rho(&self) -> Result<f64, DesignError> {
        match &self.rho {
            RhoChoice::Value(rho) => Ok(*rho),
            RhoChoice::Rule(rule) if rule == "optimal" => {
                Ok(optimal_rho(self.kind.model().shape(), self.n)?.rho)
            }
            RhoChoice::Rule(rule) if rule == "half_race" => rho_half_race(self.n),
            RhoChoice::Rule(rule) => Err(DesignError::UnknownRhoRule(rule.clone())),
        }
    }

    /// The geometry with ρ resolved.
    pub fn geometry(&self) -> Result<Geometry, DesignError> {
        Ok(Geometry {
            race_radius: self.race_radius,
            rho: self.resolved_rho()?,
            density: self.density,
            roller_height: self.roller_height,
            drag: self.drag,
        })
    }
}

/// A scene that cannot be built, naming the field and the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// A field has a value outside its domain.
    #[error("{field} = {value}: {reason}")]
    Invalid {
        /// Dotted path of the field, e.g. `rotor.kx`.
        field: String,
        /// The offending value.
        value: String,
        /// Why it is rejected.
        reason: String,
    },
    /// The balancer design is outside the design theory's domain.
    #[error("balancer: {0}")]
    Design(#[from] DesignError),
}

fn invalid(field: &str, value: f64, reason: &str) -> SceneError {
    SceneError::Invalid {
        field: field.to_string(),
        value: value.to_string(),
        reason: reason.to_string(),
    }
}

fn positive(field: &str, value: f64) -> Result<(), SceneError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be positive and finite"))
    }
}

fn non_negative(field: &str, value: f64) -> Result<(), SceneError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be zero or positive and finite"))
    }
}

impl Scene {
    /// Check every field; the first problem found is returned.
    pub fn validate(&self) -> Result<(), SceneError> {
        let r = &self.rotor;
        positive("rotor.mass", r.mass)?;
        non_negative("rotor.eccentricity", r.eccentricity)?;
        positive("rotor.inertia", r.inertia)?;
        positive("rotor.kx", r.kx)?;
        positive("rotor.ky", r.ky)?;
        non_negative("rotor.bx", r.bx)?;
        non_negative("rotor.by", r.by)?;
        if !r.unbalance_angle.is_finite() {
            return Err(invalid(
                "rotor.unbalance_angle",
                r.unbalance_angle,
                "must be finite",
            ));
        }
        match &self.speed {
            SpeedLaw::Constant { omega } => positive("speed.omega", *omega)?,
            SpeedLaw::Ramp {
                omega_start,
                omega_end,
                duration,
            } => {
                non_negative("speed.omega_start", *omega_start)?;
                positive("speed.omega_end", *omega_end)?;
                positive("speed.duration", *duration)?;
            }
            SpeedLaw::Motor {
                stall_torque,
                omega_sync,
                omega_start,
            } => {
                positive("speed.stall_torque", *stall_torque)?;
                positive("speed.omega_sync", *omega_sync)?;
                non_negative("speed.omega_start", *omega_start)?;
            }
            SpeedLaw::Free { omega_start } => non_negative("speed.omega_start", *omega_start)?,
        }
        if let Some(g) = &self.effects.gravity {
            non_negative("effects.gravity.g", g.g)?;
            if !(-90.0..=90.0).contains(&g.axis_inclination_deg) {
                return Err(invalid(
                    "effects.gravity.axis_inclination_deg",
                    g.axis_inclination_deg,
                    "must lie in [-90, 90] degrees",
                ));
            }
        }
        match (&self.balancer, self.cargo.is_empty()) {
            (None, true) => {
                return Err(SceneError::Invalid {
                    field: "balancer".into(),
                    value: "missing".into(),
                    reason: "give a [balancer] design or a [[cargo]] list".into(),
                });
            }
            (Some(_), false) => {
                return Err(SceneError::Invalid {
                    field: "balancer".into(),
                    value: "both [balancer] and [[cargo]]".into(),
                    reason: "give one of them, not both".into(),
                });
            }
            (Some(d), true) => {
                if d.n == 0 {
                    return Err(invalid("balancer.n", 0.0, "needs at least one weight"));
                }
                positive("balancer.race_radius", d.race_radius)?;
                positive("balancer.density", d.density)?;
                non_negative("balancer.drag", d.drag)?;
                if d.kind == Kind::Roller {
                    positive("balancer.roller_height", d.roller_height)?;
                }
                let rho = d.resolved_rho()?;
                crate::design::geometry::check_fits(d.n, rho)?;
            }
            (None, false) => {
                for (j, c) in self.cargo.iter().enumerate() {
                    positive(&format!("cargo[{j}].mass"), c.mass)?;
                    positive(&format!("cargo[{j}].track_radius"), c.track_radius)?;
                    non_negative(&format!("cargo[{j}].drag"), c.drag)?;
                    non_negative(&format!("cargo[{j}].rolling_coupling"), c.rolling_coupling)?;
                    non_negative(&format!("cargo[{j}].rolling_inertia"), c.rolling_inertia)?;
                    if !(c.kappa.is_finite() && c.kappa >= 1.0) {
                        return Err(invalid(
                            &format!("cargo[{j}].kappa"),
                            c.kappa,
                            "must be ≥ 1",
                        ));
                    }
                    if c.plane != 0 {
                        return Err(invalid(
                            &format!("cargo[{j}].plane"),
                            c.plane as f64,
                            "the plane rotor has one balancer plane (0)",
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The cargoes this scene's balancer resolves to.
    pub fn cargoes(&self) -> Result<Vec<Cargo>, SceneError> {
        Ok(match &self.balancer {
            Some(d) => balancer::cargoes(d.kind, d.n, &d.geometry()?)?,
            None => self.cargo.clone(),
        })
    }

    /// Validate and assemble the ODE system.
    pub fn build(&self) -> Result<RotorSystem, SceneError> {
        self.validate()?;
        let cargo = self.cargoes()?;
        let effects = self.effects.build(&cargo, self.speed.nominal_speed());
        Ok(RotorSystem::new(
            Box::new(self.rotor.clone()),
            cargo,
            self.speed.clone(),
            effects,
        ))
    }
}
