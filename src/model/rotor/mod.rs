//! Rotor models: the rigid-body (or elastic) coordinates that carry the
//! balancer planes. One file per model; each implements [`Rotor`].
//!
//! The equations of every model share one structure (seed 004; docs/model.md):
//! the rotor's coordinates h (k ≤ [`MAX_DOF`]) and, when the speed is free,
//! the spin angle φ form a small "head" block; every cargo adds one diagonal
//! row coupled only to that block. [`crate::model::system`] eliminates the
//! cargo rows and solves the head block, so a rotor model only has to say
//! what its own mass, forces, unbalance and balancer planes are.
//!
//! To add a model: write one file implementing [`Rotor`] and [`RotorParams`],
//! declare it (`pub mod …;`) and add one line
//! to the `rotor_registry!` call below.

mod angle_deg;
mod centre_unbalance;
pub mod flexible;
pub mod plane;
pub mod two_support;

pub use flexible::FlexibleShaft;
pub use plane::PlaneRotor;
pub use two_support::TwoSupportRotor;

use crate::design::criterion::TwoSupportParams;
use crate::model::validate::SceneError;
use serde::{Deserialize, Serialize};
use std::any::Any;

/// The model a `[rotor]` table without `model = "…"` gets.
const DEFAULT_MODEL: &str = "plane";

/// Largest number of rotor coordinates a model may have (x, y and two tilts).
pub const MAX_DOF: usize = 4;

/// A fixed-size vector over the rotor coordinates (only the first `dof()` used).
pub type DofVec = [f64; MAX_DOF];

/// A rotor that is one mass on isotropic supports in a single plane: what
/// the rotating-frame equations and the slow-mode closed form are written for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsotropicPlane {
    /// Rotor mass M (kg).
    pub mass: f64,
    /// Support stiffness k, the same along x and y (N/m).
    pub stiffness: f64,
    /// Support damping b, the same along x and y (N·s/m).
    pub damping: f64,
    /// The rotor's own unbalance M e (kg·m).
    pub unbalance: f64,
    /// Direction of that unbalance relative to the rotor at φ = 0 (rad).
    pub unbalance_angle: f64,
}

/// What seed 003's closed-form balancing criterion needs of a rotor.
#[derive(Debug, Clone, PartialEq)]
pub struct ClosedFormCriterion {
    /// Mass, inertias and supports in the criterion's terms.
    pub params: TwoSupportParams,
    /// Axial positions z_p of the balancer planes (m).
    pub planes: Vec<f64>,
}

/// What a rotor model contributes to the equations of motion.
///
/// Conventions every model keeps: coordinates come in pairs (q₀, q₁), (q₂, q₃)
/// that turn like the vector (x, y) under a rotation about the spin axis (the
/// rotating-frame linearisation in [`crate::model::linear`] relies on it), and
/// `forces` is linear in q and q̇ (the forced response relies on it).
pub trait Rotor: Any + Send + Sync + std::fmt::Debug {
    /// Short name used in output rows.
    fn name(&self) -> &'static str;
    /// Number of rotor coordinates k (2 for the plane rotor: x, y).
    fn dof(&self) -> usize;
    /// Number of balancer planes the rotor carries.
    fn planes(&self) -> usize;
    /// Rows G_u, G_v of the map from rotor coordinates to the displacement
    /// (u, v) of balancer plane `plane`'s centre.
    fn plane_map(&self, plane: usize) -> [DofVec; 2];
    /// Maps (G_u, G_v) of every place whose vibration counts in r and
    /// A_ref (docs/metrics.md): the balancer planes and, by default, no
    /// other. A rotor whose own unbalance may sit elsewhere adds those
    /// planes, so that a balancer that calms its own plane while the load's
    /// plane still whirls is not called settled.
    fn watch_maps(&self) -> Vec<[DofVec; 2]> {
        (0..self.planes()).map(|p| self.plane_map(p)).collect()
    }
    /// Maps (G_u, G_v) from rotor coordinates to the displacement of each
    /// bearing (support) of its own, in support order: where a rig measures
    /// vibration. None by default (a rotor whose support is the watched
    /// plane itself, or a clamped shaft).
    fn bearing_maps(&self) -> Vec<[DofVec; 2]> {
        Vec::new()
    }
    /// Rows T_α, T_β of the map from rotor coordinates to the tilt (α, β) of
    /// balancer plane `plane` (axis direction (β, −α, 1)), when the weights'
    /// tilt inertia (the m R² terms, `src/model/tilt_inertia.rs`) is
    /// modelled; `None` (the default) leaves the weights point masses that
    /// see only their plane's translation.
    fn tilt_map(&self, _plane: usize) -> Option<[DofVec; 2]> {
        None
    }
    /// Constant mass matrix of the rotor alone over its coordinates (k × k).
    fn mass_matrix(&self) -> [DofVec; MAX_DOF];
    /// Polar moment of inertia J_P of the rotor about its spin axis.
    fn spin_inertia(&self) -> f64;
    /// Elastic, damping and gyroscopic forces on the rotor coordinates,
    /// added into `f`, at spin speed `spin_rate`.
    fn forces(&self, q: &[f64], qd: &[f64], spin_rate: f64, f: &mut DofVec);
    /// Mass-matrix column coupling the rotor coordinates with φ̈ through the
    /// rotor's own unbalance (and gyroscopic terms), at spin angle φ and
    /// coordinates q (∂²T/∂q̇∂φ̇).
    fn spin_coupling(&self, phi: f64, q: &[f64]) -> DofVec;
    /// Centrifugal forces of the rotor's own unbalance at spin angle φ and
    /// rate φ̇ (the −d/dt of [`Rotor::spin_coupling`] times φ̇), added into `f`.
    fn unbalance_forces(&self, phi: f64, spin_rate: f64, f: &mut DofVec);
    /// Static unbalance of the rotor itself (kg·m) and its direction at φ = 0,
    /// for gravity torques and balancing-error metrics.
    fn static_unbalance(&self) -> (f64, f64);
    /// Size (kg·m) of the rotor's own unbalance as [`Rotor::unbalance_size`] measures it.
    fn own_unbalance(&self) -> f64;
    /// Size (kg·m) of a rotating unbalance given by its generalised force per
    /// φ̇² on the rotor coordinates at φ = 0: |U| for the plane rotor, the
    /// largest bearing-equivalent unbalance for a rotor on two supports.
    fn unbalance_size(&self, f: &DofVec) -> f64;
    /// The same unbalance as equivalent unbalances (kg·m) in each balancer
    /// plane, where its planes determine them (two planes on two supports:
    /// a static and a couple part fix one unbalance per plane); `None`
    /// elsewhere.
    fn plane_unbalance_sizes(&self, _f: &DofVec) -> Option<Vec<f64>> {
        None
    }
    /// The rotor as one mass on isotropic supports, or why it is not one.
    /// The rotating-frame formulation and the analytic slow mode are
    /// granted by this alone, so a new model that is such a plane gets them.
    fn isotropic_plane(&self) -> Result<IsotropicPlane, &'static str> {
        Err("only the plane rotor has a rotating-frame formulation")
    }
    /// The parameters of seed 003's closed-form balancing criterion, or why
    /// the criterion does not cover this rotor.
    fn closed_form_criterion(&self) -> Result<ClosedFormCriterion, &'static str> {
        Err(
            "seed 003's closed-form criterion is derived for the rigid rotor on two supports (`model = \"two_support\"`); `study sweep` finds where any rotor balances",
        )
    }
}

/// What a registered model adds to its equations: its parameters, as a file
/// gives them, can be checked and their unbalance replaced. (Separate from
/// [`Rotor`] so that a system can also be built from a rotor no file names,
/// such as a test's wrapper around a model.)
pub trait RotorParams: Rotor {
    /// Check every parameter (field names prefixed `rotor.`).
    fn validate(&self) -> Result<(), SceneError>;
    /// Replace the rotor's own unbalance by a sampled one of size U (kg·m) at
    /// direction θ: for one balancer plane the rotor's M e, for several a
    /// point unbalance U in every plane (what each plane's balancer must take).
    fn set_unbalance(&mut self, unbalance: f64, direction: f64);
    /// Remove the rotor's own unbalance (its direction kept where it is a field).
    fn clear_unbalance(&mut self);
}

/// Declares every rotor model once: its enum variant, its type and its name
/// in files (`model = "…"`, equal to the model's [`Rotor::name`]). Emits
/// [`RotorModel`] with every dispatch, the `From` impls and the serde names.
macro_rules! rotor_registry {
    ($( $(#[$doc:meta])* $variant:ident($model:ty) = $name:literal ),* $(,)?) => {
        /// The registered rotor models, chosen in files by `model = "…"` in the
        /// `[rotor]` table (`"plane"` when absent, so older files stay valid).
        #[derive(Debug, Clone, PartialEq)]
        pub enum RotorModel {
            $( $(#[$doc])* $variant($model), )*
        }

        /// The models' names as written in files, in registry order.
        const NAMES: &[&str] = &[$($name),*];

        impl RotorModel {
            /// The model behind the [`RotorParams`] (and so [`Rotor`]) interface.
            pub fn as_params(&self) -> &dyn RotorParams {
                match self {
                    $( RotorModel::$variant(r) => r, )*
                }
            }

            /// The model behind the [`RotorParams`] interface, to change its parameters.
            pub fn as_params_mut(&mut self) -> &mut dyn RotorParams {
                match self {
                    $( RotorModel::$variant(r) => r, )*
                }
            }

            /// A boxed copy for the ODE system.
            pub fn build(&self) -> Box<dyn Rotor> {
                match self {
                    $(
                        RotorModel::$variant(r) => {
                            debug_assert_eq!(r.name(), $name, "registry name of {}", stringify!($model));
                            Box::new(r.clone())
                        }
                    )*
                }
            }

            /// The model called `name` read from its table's `text`; `None`
            /// for an unknown name. Read from text, not from a value, so that
            /// an error carries a position and the key can be named.
            fn from_toml(name: &str, text: &str) -> Option<Result<Self, toml::de::Error>> {
                match name {
                    $( $name => Some(toml::from_str(text).map(RotorModel::$variant)), )*
                    _ => None,
                }
            }
        }

        $(
            impl From<$model> for RotorModel {
                fn from(r: $model) -> Self {
                    RotorModel::$variant(r)
                }
            }
        )*

        /// How a model is written: its fields plus `model = "name"`.
        #[derive(Serialize)]
        #[serde(tag = "model")]
        enum Tagged<'a> {
            $( #[serde(rename = $name)] $variant(&'a $model), )*
        }

        /// Written by hand as the `Deserialize` impl is: one alternative per
        /// model, its parameters plus `model = "name"`.
        impl schemars::JsonSchema for RotorModel {
            fn schema_name() -> std::borrow::Cow<'static, str> {
                "RotorModel".into()
            }

            fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
                let models = vec![$( model_schema::<$model>(generator, $name) ),*];
                schemars::json_schema!({
                    "description": format!(
                        "Rotor and supports: one of the models {}, chosen by `model` (\"{DEFAULT_MODEL}\" when absent).",
                        names_list()
                    ),
                    "oneOf": models,
                })
            }
        }

        impl Serialize for RotorModel {
            fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                match self {
                    $( RotorModel::$variant(r) => Tagged::$variant(r), )*
                }
                .serialize(serializer)
            }
        }
    };
}

rotor_registry! {
    /// The plane rotor of seed 004 ([`plane`]).
    Plane(PlaneRotor) = "plane",
    /// The rigid rotor on two elastic supports of seed 003 ([`two_support`]).
    TwoSupport(TwoSupportRotor) = "two_support",
    /// The flexible (Stodola–Green) shaft of seed 002 ([`flexible`]).
    Flexible(FlexibleShaft) = "flexible",
}

impl RotorModel {
    /// The model behind the [`Rotor`] interface.
    pub fn as_rotor(&self) -> &dyn Rotor {
        self.as_params()
    }

    /// The model's name as written in files.
    pub fn name(&self) -> &'static str {
        self.as_rotor().name()
    }

    /// Check every parameter (field names prefixed `rotor.`).
    pub fn validate(&self) -> Result<(), SceneError> {
        self.as_params().validate()
    }

    /// Replace the rotor's own unbalance by a sampled one of size U (kg·m) at
    /// direction θ (see [`RotorParams::set_unbalance`]).
    pub fn set_unbalance(&mut self, unbalance: f64, direction: f64) {
        self.as_params_mut().set_unbalance(unbalance, direction);
    }

    /// The same rotor without its own unbalance (direction kept where it is a field).
    pub fn without_unbalance(&self) -> Self {
        let mut r = self.clone();
        r.as_params_mut().clear_unbalance();
        r
    }
}

/// The schema of one model's table: its parameters plus the `model` key,
/// which only the default model may leave out.
fn model_schema<T: schemars::JsonSchema>(
    generator: &mut schemars::SchemaGenerator,
    name: &str,
) -> schemars::Schema {
    let mut schema = T::json_schema(generator);
    let object = schema.ensure_object();
    let default = name == DEFAULT_MODEL;
    let key = serde_json::json!({
        "description": if default {
            format!("The rotor model (\"{name}\" when absent).")
        } else {
            "The rotor model.".to_string()
        },
        "type": "string",
        "enum": [name],
    });
    if let Some(properties) = object
        .entry("properties")
        .or_insert_with(|| serde_json::json!({}))
        .as_object_mut()
    {
        properties.insert("model".into(), key);
    }
    if !default
        && let Some(required) = object
            .entry("required")
            .or_insert_with(|| serde_json::json!([]))
            .as_array_mut()
    {
        required.insert(0, "model".into());
    }
    schema
}

/// `"a", "b" or "c"`: the registered names for error messages.
fn names_list() -> String {
    let quoted: Vec<String> = NAMES.iter().map(|n| format!("\"{n}\"")).collect();
    match quoted.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        Some((last, _)) => last.clone(),
        None => String::new(),
    }
}

impl<'de> Deserialize<'de> for RotorModel {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        // serde has no default tag: read the table, take `model` out, then
        // deserialize the rest as the chosen model (unknown keys still named).
        let mut table = toml::Table::deserialize(deserializer)?;
        let model = match table.remove("model") {
            None => DEFAULT_MODEL.to_string(),
            Some(toml::Value::String(s)) => s,
            Some(other) => {
                return Err(D::Error::custom(format!(
                    "rotor.model = {other}: expected a name such as {}",
                    names_list()
                )));
            }
        };
        angle_deg::refuse_radian_keys(&table).map_err(D::Error::custom)?;
        let text = table.to_string();
        let Some(result) = RotorModel::from_toml(&model, &text) else {
            return Err(D::Error::custom(format!(
                "rotor.model = \"{model}\": expected {}",
                names_list()
            )));
        };
        result.map_err(|e| {
            // The key on the line the error points at, e.g. `mass = "heavy"`.
            let key = e
                .span()
                .and_then(|span| text[..span.start].rsplit('\n').next())
                .and_then(|line| line.split('=').next())
                .map(str::trim)
                .filter(|k| !k.is_empty() && !k.starts_with('['));
            match key {
                Some(key) => D::Error::custom(format!("rotor.{key} ({model}): {}", e.message())),
                None => D::Error::custom(format!("rotor ({model}): {}", e.message())),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<RotorModel, String> {
        toml::from_str::<RotorModel>(text).map_err(|e| e.message().to_string())
    }

    #[test]
    fn angles_are_degrees_and_the_radian_keys_are_refused_by_their_new_names() {
        let plane =
            parse("mass = 1.0\nkx = 1.0\nky = 1.0\nbx = 0.0\nby = 0.0\nunbalance_angle_deg = 90.0")
                .unwrap();
        let r = plane.as_rotor().isotropic_plane().unwrap();
        assert_eq!(r.unbalance_angle, std::f64::consts::FRAC_PI_2);
        let two = "model = \"two_support\"\nmass = 1.0\ntransverse_inertia = 0.5\npolar_inertia = 0.3\nk1 = 1.0\nk2 = 1.0\nl1 = 0.5\nl2 = 0.5\nplanes = [0.0]\n";
        for (old, new) in [
            (
                "mass = 1.0\nkx = 1.0\nky = 1.0\nbx = 0.0\nby = 0.0\nunbalance_angle = 1.0"
                    .to_string(),
                "`unbalance_angle_deg`",
            ),
            (format!("{two}static_angle = 1.0"), "`static_angle_deg`"),
            (format!("{two}moment_angle = 1.0"), "`moment_angle_deg`"),
            (
                format!("{two}[[unbalances]]\ns = 0.1\nangle = 1.0"),
                "`angle_deg`",
            ),
            (
                "model = \"flexible\"\nunbalance_angle = 1.0".to_string(),
                "`unbalance_angle_deg`",
            ),
        ] {
            let err = parse(&old).expect_err(new);
            assert!(err.contains(new) && err.contains("degrees"), "{new}: {err}");
        }
    }

    #[test]
    fn registry_names_are_the_models_names_and_survive_a_round_trip() {
        let plane = RotorModel::from(PlaneRotor::isotropic(1.0, 0.01, 1.0, 0.1));
        let flexible = RotorModel::from(FlexibleShaft::dimensionless(2.0, 0.1, 0.1, 0.01));
        for model in [plane, flexible] {
            let text = toml::to_string(&model).unwrap();
            assert!(text.starts_with(&format!("model = \"{}\"", model.name())));
            assert!(NAMES.contains(&model.name()));
            assert_eq!(parse(&text).unwrap(), model);
        }
        assert_eq!(
            parse("mass = 1.0\nkx = 1.0\nky = 1.0\nbx = 0.0\nby = 0.0")
                .unwrap()
                .name(),
            "plane"
        );
    }

    #[test]
    fn unknown_models_are_named_with_the_registered_ones() {
        assert_eq!(
            parse("model = \"gyro\"").unwrap_err(),
            "rotor.model = \"gyro\": expected \"plane\", \"two_support\" or \"flexible\""
        );
        assert_eq!(
            parse("model = 3").unwrap_err(),
            "rotor.model = 3: expected a name such as \"plane\", \"two_support\" or \"flexible\""
        );
        assert!(
            parse("model = \"plane\"\nmass = 1.0")
                .unwrap_err()
                .starts_with("rotor (plane): ")
        );
    }
}
