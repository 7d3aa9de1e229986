//! A scene: the plain description of one simulation (rotor, balancer, speed
//! law, effects), deserialisable from TOML and validated before building.

use super::balancer::{self, Geometry, Kind};
use super::cargo::Cargo;
use super::effect::{BuildSetup, Effects, SceneFacts};
use super::rotor::RotorModel;
use super::speed::SpeedLaw;
use super::system::RotorSystem;
use super::validate::{
    DENSITY_RANGE, MAX_TOTAL_WEIGHTS, RACE_RADIUS_RANGE, invalid, non_negative, positive,
    spin_rate, within,
};
use crate::design::optimum::optimal_rho;
use crate::design::{DesignError, geometry::rho_half_race};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Re-exported where it was first defined: most of the crate names it here.
pub use super::validate::SceneError;

/// Everything that defines the physics of one simulation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// The rotor and its supports (`model = "plane"` by default).
    pub rotor: RotorModel,
    /// The auto-balancer as a design (give this and/or `balancers`, or `cargo`).
    #[serde(default)]
    pub balancer: Option<DesignSpec>,
    /// Further auto-balancers, each in its own plane (`[[balancers]]`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub balancers: Vec<DesignSpec>,
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
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
    /// Balancer plane the weights run in (index into the rotor's planes).
    #[serde(default)]
    pub plane: usize,
}

fn steel() -> f64 {
    7850.0
}

/// How the radius ratio is chosen: a number, or the name of a rule
/// (`"optimal"`: the capacity optimum of Table 1; `"half_race"`: the weights
/// fill exactly half the race).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(
    untagged,
    expecting = "expected a radius ratio: a number in (0, 1), \"optimal\" or \"half_race\""
)]
pub enum RhoChoice {
    /// A given ρ.
    Value(f64),
    /// A named rule, checked when the spec is resolved.
    Rule(#[schemars(schema_with = "rho_rules")] String),
}

/// The rules [`DesignSpec::resolved_rho`] knows, so that an editor flags a
/// misspelt one while it is typed rather than when the study starts.
fn rho_rules(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
    schemars::json_schema!({
        "type": "string",
        "enum": ["optimal", "half_race"]
    })
}

impl DesignSpec {
    /// The radius ratio this spec resolves to.
    pub fn resolved_rho(&self) -> Result<f64, DesignError> {
        // A new rule is also listed in `rho_rules`, the schema's list.
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

/// A balancer plane index must name one of the rotor's planes.
fn check_plane(field: &str, plane: usize, rotor: &RotorModel) -> Result<(), SceneError> {
    let planes = rotor.as_rotor().planes();
    if plane < planes {
        return Ok(());
    }
    let reason = if planes == 1 {
        format!("the {} rotor has one balancer plane (0)", rotor.name())
    } else {
        format!(
            "the {} rotor has {planes} balancer planes (0..{})",
            rotor.name(),
            planes - 1
        )
    };
    Err(SceneError::Invalid {
        field: field.to_string(),
        value: plane.to_string(),
        reason,
    })
}

impl Scene {
    /// Rigid contact holds weights of finite size apart; point masses
    /// never touch, so asking for it cannot take effect.
    fn check_rigid_contact_has_sizes(&self) -> Result<(), SceneError> {
        let rigid =
            self.effects.contact.as_ref().is_some_and(|c| {
                c.model == Some(crate::model::effect::contact::ContactModel::Rigid)
            });
        if rigid
            && self.balancer.is_none()
            && self.balancers.is_empty()
            && !self.cargo.is_empty()
            && self.cargo.iter().all(|c| c.radius <= 0.0)
        {
            return Err(SceneError::Invalid {
                field: "effects.contact.model".into(),
                value: "rigid".into(),
                reason: "every weight is a point mass ([[cargo]] without a radius): point masses never touch, so there is nothing to hold rigid; give the weights a radius or remove model".into(),
            });
        }
        Ok(())
    }

    /// Check every field; the first problem found is returned.
    pub fn validate(&self) -> Result<(), SceneError> {
        self.rotor.validate()?;
        self.validate_speed()?;
        if self.rotor.as_rotor().tilt_map(0).is_some() && !self.speed.is_prescribed() {
            return Err(SceneError::Invalid {
                field: "rotor.weights_tilt_inertia".into(),
                value: "true".into(),
                reason: "the weights' tilt inertia is modelled at a prescribed speed (constant or ramp) only: with a motor or a free rotor the spin equation's share is missing".into(),
            });
        }
        self.effects.validate(&SceneFacts {
            planes: self.rotor.as_rotor().planes(),
            prescribed_speed: self.speed.is_prescribed(),
        })?;
        self.check_rigid_contact_has_sizes()?;
        let designs: Vec<(String, &DesignSpec)> = self
            .balancer
            .iter()
            .map(|d| ("balancer".to_string(), d))
            .chain(
                self.balancers
                    .iter()
                    .enumerate()
                    .map(|(i, d)| (format!("balancers[{i}]"), d)),
            )
            .collect();
        match (designs.is_empty(), self.cargo.is_empty()) {
            (true, true) => Err(SceneError::Invalid {
                field: "balancer".into(),
                value: "missing".into(),
                reason: "give a [balancer] design or a [[cargo]] list".into(),
            }),
            (false, false) => Err(SceneError::Invalid {
                field: "balancer".into(),
                value: "both [balancer] and [[cargo]]".into(),
                reason: "give one of them, not both".into(),
            }),
            (false, true) => self.validate_designs(designs),
            (true, false) => self.validate_cargo(),
        }
    }

    /// The speed law's own values.
    fn validate_speed(&self) -> Result<(), SceneError> {
        match &self.speed {
            SpeedLaw::Constant { omega } => spin_rate("speed.omega", *omega, false)?,
            SpeedLaw::Ramp {
                omega_start,
                omega_end,
                duration,
            } => {
                spin_rate("speed.omega_start", *omega_start, true)?;
                spin_rate("speed.omega_end", *omega_end, false)?;
                positive("speed.duration", *duration)?;
            }
            SpeedLaw::Motor {
                stall_torque,
                omega_sync,
                omega_start,
            } => {
                positive("speed.stall_torque", *stall_torque)?;
                spin_rate("speed.omega_sync", *omega_sync, false)?;
                spin_rate("speed.omega_start", *omega_start, true)?;
            }
            // A free rotor coasts from its start: it must be spinning.
            SpeedLaw::Free { omega_start } => spin_rate("speed.omega_start", *omega_start, false)?,
        }
        Ok(())
    }

    /// The `[balancer]` / `[[balancers]]` designs (`designs`: each with
    /// its key).
    fn validate_designs(&self, designs: Vec<(String, &DesignSpec)>) -> Result<(), SceneError> {
        let weights: u64 = designs.iter().map(|(_, d)| u64::from(d.n)).sum();
        if weights > MAX_TOTAL_WEIGHTS as u64 {
            return Err(SceneError::Invalid {
                field: designs[0].0.clone() + ".n",
                value: format!("{weights} weights in all"),
                reason: format!(
                    "at most {MAX_TOTAL_WEIGHTS} weights over every balancer: the state and the implicit method's Jacobian grow with their number"
                ),
            });
        }
        for (key, d) in designs {
            if d.n == 0 {
                return Err(invalid(
                    &format!("{key}.n"),
                    0.0,
                    "needs at least one weight",
                ));
            }
            within(
                &format!("{key}.race_radius"),
                d.race_radius,
                RACE_RADIUS_RANGE,
                "m",
            )?;
            within(&format!("{key}.density"), d.density, DENSITY_RANGE, "kg/m³")?;
            non_negative(&format!("{key}.drag"), d.drag)?;
            if d.kind == Kind::Roller {
                positive(&format!("{key}.roller_height"), d.roller_height)?;
            }
            check_plane(&format!("{key}.plane"), d.plane, &self.rotor)?;
            let rho = d.resolved_rho()?;
            crate::design::geometry::check_fits(d.n, rho)?;
        }
        Ok(())
    }

    /// The `[[cargo]]` weights given one by one.
    fn validate_cargo(&self) -> Result<(), SceneError> {
        if self.cargo.len() > MAX_TOTAL_WEIGHTS {
            return Err(SceneError::Invalid {
                field: "cargo".into(),
                value: format!("{} cargoes", self.cargo.len()),
                reason: format!(
                    "at most {MAX_TOTAL_WEIGHTS} weights over every balancer: the state and the implicit method's Jacobian grow with their number"
                ),
            });
        }
        for (j, c) in self.cargo.iter().enumerate() {
            positive(&format!("cargo[{j}].mass"), c.mass)?;
            positive(&format!("cargo[{j}].track_radius"), c.track_radius)?;
            non_negative(&format!("cargo[{j}].drag"), c.drag)?;
            non_negative(&format!("cargo[{j}].rolling_coupling"), c.rolling_coupling)?;
            non_negative(&format!("cargo[{j}].rolling_inertia"), c.rolling_inertia)?;
            // As a race's radius: beyond it the weight's size is no
            // size (1e308 made every start a clash).
            if !(0.0..=RACE_RADIUS_RANGE.1).contains(&c.radius) {
                return Err(invalid(
                    &format!("cargo[{j}].radius"),
                    c.radius,
                    &format!("must be in [0, {}] m (0: no contact)", RACE_RADIUS_RANGE.1),
                ));
            }
            // The weight's centre runs at l from the axis: a radius
            // above l would put the weight across the shaft.
            if c.radius > c.track_radius {
                return Err(invalid(
                    &format!("cargo[{j}].radius"),
                    c.radius,
                    &format!(
                        "is larger than cargo[{j}].track_radius = {} m: the weight's centre runs at the track radius, so a larger weight would reach across the axis",
                        c.track_radius
                    ),
                ));
            }
            if !(c.kappa.is_finite() && c.kappa >= 1.0) {
                return Err(invalid(
                    &format!("cargo[{j}].kappa"),
                    c.kappa,
                    "must be ≥ 1",
                ));
            }
            check_plane(&format!("cargo[{j}].plane"), c.plane, &self.rotor)?;
        }
        Ok(())
    }

    /// The cargoes this scene's balancers resolve to, in file order, each
    /// tagged with its plane.
    pub fn cargoes(&self) -> Result<Vec<Cargo>, SceneError> {
        if self.balancer.is_none() && self.balancers.is_empty() {
            return Ok(self.cargo.clone());
        }
        let mut all = Vec::new();
        for d in self.balancer.iter().chain(&self.balancers) {
            let mut c = balancer::cargoes(d.kind, d.n, &d.geometry()?)?;
            for cargo in &mut c {
                cargo.plane = d.plane;
            }
            all.extend(c);
        }
        Ok(all)
    }

    /// Validate and assemble the ODE system.
    pub fn build(&self) -> Result<RotorSystem, SceneError> {
        self.validate()?;
        let cargo = self.cargoes()?;
        let rotor = self.rotor.build();
        let plane_maps: Vec<_> = (0..rotor.planes()).map(|p| rotor.plane_map(p)).collect();
        let omega = self.speed.nominal_speed();
        let rigid = self
            .effects
            .contact
            .as_ref()
            .and_then(|c| c.rigid(&cargo, omega));
        let effects = self.effects.build(&BuildSetup {
            cargo: &cargo,
            omega,
            plane_maps: &plane_maps,
            gravity: 0.0,
            rigid_contact: rigid.is_some(),
        });
        Ok(RotorSystem::new(rotor, cargo, self.speed.clone(), effects).with_rigid_contact(rigid))
    }
}
