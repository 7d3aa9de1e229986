//! The TOML file of `study simulate`: one scene plus start, solver and metric
//! settings. Every key is documented in `docs/scene-file.md`.

use crate::metrics::MetricOptions;
use crate::model::cargo::Cargo;
use crate::model::effect::Effects;
use crate::model::gap::start_clash;
use crate::model::rotor::RotorModel;
use crate::model::scene::{DesignSpec, Scene, SceneError};
use crate::model::speed::SpeedLaw;
use crate::model::start::StartMode;
use crate::simulation::{Simulation, SolverSettings, evenly_spaced};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A scene file as written by the user.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Rotor and supports (`model = "plane"` by default).
    pub rotor: RotorModel,
    /// The auto-balancer as a design (or give `cargo`).
    #[serde(default)]
    pub balancer: Option<DesignSpec>,
    /// Further auto-balancers, each in its own plane.
    #[serde(default)]
    pub balancers: Vec<DesignSpec>,
    /// The auto-balancer as explicit cargoes (or give `balancer`).
    #[serde(default)]
    pub cargo: Vec<Cargo>,
    /// Speed law.
    pub speed: SpeedLaw,
    /// Optional effects.
    #[serde(default)]
    pub effects: Effects,
    /// Initial state.
    #[serde(default)]
    pub start: StartSpec,
    /// Integrator settings.
    #[serde(default)]
    pub solver: SolverSettings,
    /// Metric definitions.
    #[serde(default)]
    pub metrics: MetricOptions,
    /// Keys of this scene nobody measured exactly, each with a distribution
    /// (`study stepped --draws`): see [`crate::uncertain`].
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub uncertain: crate::uncertain::UncertainSpec,
}

/// How a single run starts.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StartSpec {
    /// Start mode (default `locked_steady`).
    #[serde(default)]
    pub mode: StartMode,
    /// Cargo angles relative to the rotor in degrees; evenly spaced when omitted.
    #[serde(default)]
    pub angles_deg: Option<Vec<f64>>,
}

/// A scene file that could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SceneFileError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// TOML syntax or schema error (the message names line, column and key).
    #[error("{path}: {message}")]
    Parse {
        /// The path.
        path: String,
        /// The parser's message.
        message: String,
    },
    /// A value outside its domain.
    #[error("{path}: {source}")]
    Invalid {
        /// The path.
        path: String,
        /// The cause.
        source: SceneError,
    },
}

impl SceneFile {
    /// Parse TOML text; `path` is used in messages only.
    pub fn parse(text: &str, path: &str) -> Result<Self, SceneFileError> {
        toml::from_str(text).map_err(|e| SceneFileError::Parse {
            path: path.to_string(),
            message: crate::input_file::toml_message(text, &e),
        })
    }

    /// Read and parse a file.
    pub fn read(path: &std::path::Path) -> Result<Self, SceneFileError> {
        let shown = path.display().to_string();
        let text = crate::input_file::read_text(path).map_err(|source| SceneFileError::Io {
            path: shown.clone(),
            source,
        })?;
        Self::parse(&text, &shown)
    }

    /// The scene part.
    pub fn scene(&self) -> Scene {
        Scene {
            rotor: self.rotor.clone(),
            balancer: self.balancer.clone(),
            balancers: self.balancers.clone(),
            cargo: self.cargo.clone(),
            speed: self.speed.clone(),
            effects: self.effects.clone(),
        }
    }

    /// Validate and turn into a runnable simulation.
    pub fn simulation(&self, path: &str) -> Result<Simulation, SceneFileError> {
        let scene = self.scene();
        let invalid = |source| SceneFileError::Invalid {
            path: path.to_string(),
            source,
        };
        scene.validate().map_err(invalid)?;
        crate::uncertain::validate(&self.uncertain, &scene, |s| {
            s.validate().map_err(|e| match e {
                SceneError::Invalid {
                    field,
                    value,
                    reason,
                } => crate::invalid_key::InvalidKey::new(field, value, reason),
                other => crate::invalid_key::InvalidKey::new("scene", "", other.to_string()),
            })
        })
        .map_err(|e| {
            invalid(SceneError::Invalid {
                field: e.key,
                value: e.value,
                reason: e.reason,
            })
        })?;
        let cargo = scene.cargoes().map_err(invalid)?;
        let n = cargo.len();
        let initial_angles: Vec<f64> = match &self.start.angles_deg {
            Some(a) => a.iter().map(|d| d.to_radians()).collect(),
            None => evenly_spaced(n),
        };
        if initial_angles.len() == n
            && let Some(clash) = start_clash(&cargo, &initial_angles)
        {
            let reason = if clash.touching > 0.0 {
                format!(
                    "weights {} and {} start {:.3}° apart, closer than their touching angle 2α = {:.3}°: solid weights cannot overlap",
                    clash.first + 1,
                    clash.second + 1,
                    clash.apart.to_degrees(),
                    clash.touching.to_degrees()
                )
            } else {
                format!(
                    "weights {} and {} start at the same angle: that symmetric state is an equilibrium and they would never separate; start them apart",
                    clash.first + 1,
                    clash.second + 1
                )
            };
            return Err(invalid(SceneError::Invalid {
                field: "start.angles_deg".into(),
                value: format!("{:?}", self.start.angles_deg.as_deref().unwrap_or(&[])),
                reason,
            }));
        }
        if let Err(crate::invalid_key::InvalidKey {
            key: field,
            value,
            reason,
        }) = self.metrics.validate()
        {
            return Err(invalid(SceneError::Invalid {
                field,
                value,
                reason,
            }));
        }
        if let Err(crate::invalid_key::InvalidKey {
            key: field,
            value,
            reason,
        }) = self.solver.validate()
        {
            return Err(invalid(SceneError::Invalid {
                field,
                value,
                reason,
            }));
        }
        self.metrics.check_horizon(&scene.speed).map_err(invalid)?;
        Ok(Simulation {
            scene,
            start: self.start.mode,
            initial_angles,
            solver: self.solver.clone(),
            metrics: self.metrics.clone(),
        })
    }
}
