//! The study file: scene template, design grid, sampling, solver, metrics,
//! output and seed (TOML, every key documented in `docs/study-file.md`).
//!
//! Parsing rejects unknown keys and wrong types with the line and column of
//! the problem; [`StudyFile::plan`] then checks every value against its domain
//! and resolves the design grid, so that a study either starts with a fully
//! valid plan or fails before anything is written.

pub use super::design::{Design, MAX_WEIGHTS, OneOrMany};
pub use super::distribution::{DirectionSpec, Distribution, InitialSpec, Scale, UnbalanceSpec};
use crate::design::geometry::check_fits;
use crate::invalid_key::InvalidKey;
use crate::metrics::MetricOptions;
use crate::model::balancer::Kind;
use crate::model::effect::Effects;
use crate::model::rotor::RotorModel;
use crate::model::scene::{DesignSpec, RhoChoice, Scene, SceneError};
use crate::model::speed::SpeedLaw;
use crate::model::start::StartMode;
use crate::simulation::SolverSettings;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Seed used when a study file gives none (documented in `docs/study-file.md`).
pub const DEFAULT_SEED: u64 = 20_261_122;

/// A study file as written by the user.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StudyFile {
    /// Name of the output folder under `output`; defaults to the file's stem.
    #[serde(default)]
    pub name: Option<String>,
    /// Master seed of every random stream in the study.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Root folder of the outputs.
    #[serde(default = "default_output")]
    pub output: String,
    /// The physics shared by every run.
    pub scene: SceneTemplate,
    /// The designs to compare (a Cartesian grid).
    pub designs: DesignGrid,
    /// What is sampled for each design.
    pub sampling: Sampling,
    /// Integrator settings.
    #[serde(default)]
    pub solver: SolverSettings,
    /// Metric definitions.
    #[serde(default)]
    pub metrics: MetricOptions,
    /// Settings of `study optimize` (ignored by `study run`).
    #[serde(default)]
    pub optimize: Option<super::optimize_spec::OptimizeSpec>,
    /// How designs are compared (significance level of the verdicts).
    #[serde(default)]
    pub statistics: StatisticsSpec,
    /// What "best" means: the ranking criterion and the measures of the
    /// Pareto set.
    #[serde(default)]
    pub summary: SummarySpec,
}

/// What the ranking and the recommendation rest on (`[summary]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SummarySpec {
    /// The criterion designs are ranked by; `study run/compare/claims
    /// --rank-by` overrides it. Default: the restricted mean settling time
    /// (it counts the slow tail; docs/statistics.md).
    #[serde(default)]
    pub rank_by: super::criterion::Criterion,
    /// The measures a design must not be dominated on to be in the Pareto
    /// set (`pareto` column of summary.parquet).
    #[serde(default = "default_pareto")]
    pub pareto: Vec<super::criterion::Criterion>,
}

impl Default for SummarySpec {
    fn default() -> Self {
        SummarySpec {
            rank_by: super::criterion::Criterion::default(),
            pareto: default_pareto(),
        }
    }
}

fn default_pareto() -> Vec<super::criterion::Criterion> {
    super::criterion::Criterion::REPORTED.to_vec()
}

/// How verdicts between designs are reached.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StatisticsSpec {
    /// Family-wise error rate of the "settles sooner than" verdicts
    /// (Holm-adjusted over every comparison of the best design with another).
    #[serde(default = "default_alpha")]
    pub alpha: f64,
}

impl Default for StatisticsSpec {
    fn default() -> Self {
        StatisticsSpec {
            alpha: default_alpha(),
        }
    }
}

fn default_alpha() -> f64 {
    0.05
}

fn default_seed() -> u64 {
    DEFAULT_SEED
}

fn default_output() -> String {
    "results".into()
}

/// The rotor, speed law, effects and start mode shared by every run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneTemplate {
    /// Rotor and supports; each run replaces the rotor's own unbalance by the
    /// sampled one, so the file need not give it.
    pub rotor: RotorModel,
    /// Speed law.
    pub speed: SpeedLaw,
    /// Optional effects.
    #[serde(default)]
    pub effects: Effects,
    /// How each run starts.
    #[serde(default)]
    pub start: StartMode,
}

/// Most runs one study may hold. The runner streams runs to disk but keeps
/// about 80 bytes a run (run ids and the columns the summary reads): about
/// 60 MB + 80 B per run resident, measured in docs/running-at-scale.md, so
/// this limit keeps a study under 2 GB of memory and of `runs.parquet`.
pub const MAX_TOTAL_RUNS: u64 = 20_000_000;

/// The design grid: every combination of kind × n × ρ × drag.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DesignGrid {
    /// Balancer kinds: "ball", "roller", "pendulum".
    pub kind: OneOrMany<Kind>,
    /// Weight counts.
    pub n: OneOrMany<u32>,
    /// Radius ratios: numbers, "optimal" (Table 1) or "half_race".
    pub rho: OneOrMany<RhoChoice>,
    /// Race radius R (m).
    pub race_radius: f64,
    /// Weight density γ (kg/m³).
    #[serde(default = "steel")]
    pub density: f64,
    /// Roller height h (m), required when rollers are in the grid.
    #[serde(default)]
    pub roller_height: f64,
    /// Viscous coefficients β (N·s/m).
    pub drag: OneOrMany<f64>,
    /// Motor stall torques M_s (N·m), one more axis of the grid; each
    /// replaces `scene.speed.stall_torque` (needs `mode = "motor"`).
    #[serde(default)]
    pub stall_torque: Option<OneOrMany<f64>>,
    /// Balancer planes 1, 2, … with axes of their own (rotors with several
    /// balancer planes; docs/study-file.md, "A design per plane").
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub per_plane: Vec<super::plane_designs::PlaneAxes>,
}

fn steel() -> f64 {
    7850.0
}

/// What is drawn for each run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sampling {
    /// Runs per design.
    pub samples: u32,
    /// Unbalance magnitude.
    pub unbalance: UnbalanceSpec,
    /// Unbalance direction relative to the rotor.
    #[serde(default)]
    pub direction: DirectionSpec,
    /// Initial cargo positions relative to the rotor.
    #[serde(default)]
    pub initial: InitialSpec,
    /// Reject (true) or only flag (false) absolute unbalances above a design's capacity.
    #[serde(default = "yes")]
    pub require_balanceable: bool,
    /// Draw unbalances, directions and initial positions from streams shared
    /// by every design (common random numbers), so design differences are not noise.
    #[serde(default = "yes")]
    pub common_random_numbers: bool,
    /// Sample until this precision is reached (`samples` is then the cap),
    /// in batches of `batch` samples per design (docs/statistics.md).
    #[serde(default)]
    pub stop_when: Option<StopWhen>,
    /// Samples per design in each batch of adaptive sampling.
    #[serde(default = "default_batch")]
    pub batch: u32,
    /// Manufacturing tolerances of the weights, sampled per run (off unless given).
    #[serde(default)]
    pub tolerances: Option<super::tolerance::Tolerances>,
    /// The couple unbalance of a rotor on two supports (off unless given;
    /// `sampling.unbalance` is then the static part).
    #[serde(default)]
    pub couple: Option<super::couple::CoupleSpec>,
}

fn default_batch() -> u32 {
    100
}

/// The precision adaptive sampling stops at: every key given must hold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(transform = accept_old_win_share_name)]
pub struct StopWhen {
    /// Half-width of every design's 95 % interval of the Kaplan–Meier median
    /// settling time, relative to the median (e.g. 0.05 for ±5 %).
    #[serde(default)]
    pub median_halfwidth_rel: Option<f64>,
    /// Half-width of every 95 % interval of the share of paired runs in
    /// which the best design settles sooner than another (e.g. 0.03).
    #[serde(default, alias = "win_probability_halfwidth")]
    pub win_share_halfwidth: Option<f64>,
}

fn yes() -> bool {
    true
}

/// schemars does not list serde aliases, and the schema forbids unknown
/// keys: without this, a file using the old name would validate as wrong
/// while the parser reads it.
fn accept_old_win_share_name(schema: &mut schemars::Schema) {
    let Some(properties) = schema
        .get_mut("properties")
        .and_then(serde_json::Value::as_object_mut)
    else {
        return;
    };
    if let Some(current) = properties.get("win_share_halfwidth").cloned() {
        let mut old = current;
        if let Some(old) = old.as_object_mut() {
            old.insert(
                "description".into(),
                "Old name of `win_share_halfwidth`.".into(),
            );
            old.insert("deprecated".into(), true.into());
        }
        properties.insert("win_probability_halfwidth".into(), old);
    }
}

/// A validated study: the file plus its resolved designs.
#[derive(Debug, Clone)]
pub struct StudyPlan {
    /// The study name (output folder).
    pub name: String,
    /// The parsed file.
    pub file: StudyFile,
    /// The resolved designs in grid order.
    pub designs: Vec<Design>,
    /// The study file's text, kept for provenance and resume checks.
    pub text: String,
}

impl StudyPlan {
    /// Total number of runs (designs × samples).
    pub fn total_runs(&self) -> u64 {
        self.designs.len() as u64 * u64::from(self.file.sampling.samples)
    }

    /// The scene of one design with rotor unbalance (U, direction) applied;
    /// a rotor with several balancer planes gets the design in every plane.
    pub fn scene(&self, design: &Design, unbalance: f64, direction: f64) -> Scene {
        let t = &self.file.scene;
        let mut rotor = t.rotor.clone();
        rotor.set_unbalance(unbalance, direction);
        let planes = rotor.as_rotor().planes();
        let balancers = if design.plane_designs.is_empty() {
            (1..planes)
                .map(|plane| DesignSpec {
                    plane,
                    ..design.spec.clone()
                })
                .collect()
        } else {
            design
                .plane_designs
                .iter()
                .map(|p| p.spec.clone())
                .collect()
        };
        Scene {
            rotor,
            balancer: Some(design.spec.clone()),
            balancers,
            cargo: Vec::new(),
            speed: design.speed(&t.speed),
            effects: t.effects.clone(),
        }
    }
}

/// A study file that cannot be used, naming the key and the reason.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// TOML syntax or schema error (with line and column).
    #[error("{path}: {message}")]
    Parse {
        /// The path.
        path: String,
        /// The parser's message.
        message: String,
    },
    /// A value outside its domain.
    #[error("{path}: {key} = {value}: {reason}")]
    Invalid {
        /// The path.
        path: String,
        /// Dotted key.
        key: String,
        /// Offending value.
        value: String,
        /// Why.
        reason: String,
    },
}

impl StudyFile {
    /// Parse TOML text (`path` is used in messages only).
    pub fn parse(text: &str, path: &str) -> Result<Self, StudyError> {
        toml::from_str(text).map_err(|e| StudyError::Parse {
            path: path.to_string(),
            message: crate::input_file::in_user_words(&e.to_string()),
        })
    }

    /// Validate every value and resolve the design grid.
    pub fn plan(self, text: &str, path: &str) -> Result<StudyPlan, StudyError> {
        let invalid = |key: &str, value: String, reason: &str| StudyError::Invalid {
            path: path.to_string(),
            key: key.to_string(),
            value,
            reason: reason.to_string(),
        };
        let refused = |e: InvalidKey| StudyError::Invalid {
            path: path.to_string(),
            key: e.key,
            value: e.value,
            reason: e.reason,
        };
        let name = match &self.name {
            Some(n) => n.clone(),
            None => std::path::Path::new(path)
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("study")
                .to_string(),
        };
        if name.is_empty() || name.contains(['/', '\\']) || name == ".." || name == "." {
            return Err(invalid(
                "name",
                format!("{name:?}"),
                "must be a plain folder name",
            ));
        }
        let alpha = self.statistics.alpha;
        if !(alpha > 0.0 && alpha <= 0.5) {
            return Err(invalid(
                "statistics.alpha",
                alpha.to_string(),
                "a significance level in (0, 0.5], e.g. 0.05",
            ));
        }
        if self.summary.pareto.is_empty() {
            return Err(invalid(
                "summary.pareto",
                "[]".into(),
                "name at least one measure (median, mean, p90, residual_p95, …), or leave the key out for all four",
            ));
        }
        let s = &self.sampling;
        if s.unbalance.relative_to.is_none() {
            return Err(invalid(
                "sampling.unbalance.relative_to",
                "(missing)".into(),
                "required: \"capacity\" (the values are fractions of each design's balancing capacity, no unit) or \"absolute\" (the values are unbalances in kg·m)",
            ));
        }
        if s.samples == 0 {
            return Err(invalid(
                "sampling.samples",
                "0".into(),
                "need at least one sample per design",
            ));
        }
        if s.batch == 0 {
            return Err(invalid(
                "sampling.batch",
                "0".into(),
                "a batch holds at least one sample per design",
            ));
        }
        if let Some(stop) = &s.stop_when {
            let keys = [
                ("median_halfwidth_rel", stop.median_halfwidth_rel),
                ("win_share_halfwidth", stop.win_share_halfwidth),
            ];
            if keys.iter().all(|(_, v)| v.is_none()) {
                return Err(invalid(
                    "sampling.stop_when",
                    "{}".into(),
                    "name a precision: median_halfwidth_rel or win_share_halfwidth",
                ));
            }
            for (key, value) in keys {
                if let Some(v) = value
                    && !(v > 0.0 && v < 1.0)
                {
                    return Err(invalid(
                        &format!("sampling.stop_when.{key}"),
                        v.to_string(),
                        "a half-width in (0, 1), e.g. 0.05",
                    ));
                }
            }
        }
        super::distribution::check(&s.unbalance.distribution).map_err(|e| {
            refused(InvalidKey::new(
                format!("sampling.unbalance.{}", e.key),
                e.value,
                e.reason,
            ))
        })?;
        if let Some(couple) = &s.couple {
            super::couple::validate(couple, &self.scene.rotor, |u| {
                super::distribution::check(&u.distribution).map_err(|e| {
                    InvalidKey::new(
                        format!("sampling.couple.unbalance.{}", e.key),
                        e.value,
                        e.reason,
                    )
                })
            })
            .map_err(refused)?;
        }
        if let DirectionSpec::Fixed(d) = s.direction
            && !d.is_finite()
        {
            return Err(invalid(
                "sampling.direction.fixed",
                d.to_string(),
                "must be finite",
            ));
        }
        if let InitialSpec::BalancedForShift(d) = s.initial
            && !d.is_finite()
        {
            return Err(invalid(
                "sampling.initial.balanced_for_shift",
                d.to_string(),
                "must be finite",
            ));
        }
        self.metrics.validate().map_err(refused)?;
        self.solver.validate().map_err(refused)?;
        if let Err(crate::model::validate::SceneError::Invalid {
            field,
            value,
            reason,
        }) = self.metrics.check_horizon(&self.scene.speed)
        {
            return Err(invalid(&field, value, &reason));
        }
        if let Some(n) = self
            .designs
            .n
            .values()
            .into_iter()
            .find(|&n| n > MAX_WEIGHTS)
        {
            return Err(invalid(
                "designs.n",
                n.to_string(),
                &format!(
                    "at most {MAX_WEIGHTS} weights per balancer: the state and the implicit method's Jacobian grow with n (n² entries), and no race holds more weights of a useful size"
                ),
            ));
        }
        super::plane_designs::validate(
            &self.designs.per_plane,
            self.scene.rotor.as_rotor().planes(),
        )
        .map_err(
            |InvalidKey {
                 key: k,
                 value: v,
                 reason: r,
             }| invalid(&k, v, &r),
        )?;
        let planes = self.scene.rotor.as_rotor().planes();
        if !self.designs.per_plane.is_empty() && self.optimize.is_some() && planes != 2 {
            // The optimiser searches plane 0's and plane 1's radius ratios.
            return Err(invalid(
                "optimize",
                format!("{planes} balancer planes"),
                "with designs.per_plane the optimiser searches two balancer planes' radius ratios; this rotor has another number: run the planes' designs as a grid",
            ));
        }
        // The grid's size from its axes alone, before a design is built.
        let g = &self.designs;
        let mut grid = [
            g.kind.values().len(),
            g.n.values().len(),
            g.rho.values().len(),
            g.drag.values().len(),
            g.stall_torque.as_ref().map_or(1, |t| t.values().len()),
        ]
        .iter()
        .fold(1u64, |acc, &k| acc.saturating_mul(k as u64));
        for a in &g.per_plane {
            let axis = |len: Option<usize>| len.unwrap_or(1) as u64;
            grid = grid
                .saturating_mul(axis(a.kind.as_ref().map(|v| v.values().len())))
                .saturating_mul(axis(a.n.as_ref().map(|v| v.values().len())))
                .saturating_mul(axis(a.rho.as_ref().map(|v| v.values().len())))
                .saturating_mul(axis(a.drag.as_ref().map(|v| v.values().len())));
        }
        if grid.saturating_mul(u64::from(s.samples)) > MAX_TOTAL_RUNS {
            // The grid alone too large, or the samples on top of it.
            let (key, value) = if grid > MAX_TOTAL_RUNS {
                ("designs", format!("{grid} designs"))
            } else {
                ("sampling.samples", s.samples.to_string())
            };
            return Err(invalid(
                key,
                value,
                &format!(
                    "{grid} designs × {} samples is more than the {MAX_TOTAL_RUNS} runs one study may hold; split the grid into several studies or use fewer samples",
                    s.samples
                ),
            ));
        }
        let designs = self.resolve_designs().map_err(
            |InvalidKey {
                 key: k,
                 value: v,
                 reason: r,
             }| invalid(&k, v, &r),
        )?;
        if let Some(t) = &s.tolerances {
            let facts = crate::model::effect::SceneFacts {
                planes: self.scene.rotor.as_rotor().planes(),
                prescribed_speed: self.scene.speed.is_prescribed(),
            };
            super::tolerance::validate(t, &designs, &facts).map_err(
                |InvalidKey {
                     key: k,
                     value: v,
                     reason: r,
                 }| invalid(&format!("sampling.tolerances.{k}"), v, &r),
            )?;
        }
        let demand = self.effects_capacity_demand();
        if demand > 0.0 && s.require_balanceable {
            // The weights must also hold the race centred: the unbalance they
            // supply grows by up to e_r·|M − (k + ibω)/ω²| (docs/model.md).
            let upper = s.unbalance.distribution.upper();
            let drawn = |d: &Design| match s.unbalance.scale() {
                Scale::Absolute => upper,
                Scale::Capacity => upper * d.capacity,
            };
            if let Some(d) = designs.iter().find(|d| d.capacity < drawn(d) + demand) {
                return Err(invalid(
                    &format!(
                        "sampling.unbalance.{}",
                        s.unbalance.distribution.upper_key()
                    ),
                    upper.to_string(),
                    &format!(
                        "the largest unbalance drawn, {:.4e} kg·m, plus the {demand:.4e} kg·m the weights must add to centre the off-centre race (effects.race_eccentricity: e_r over the plane's compliance, e_r·|M − (k + ibω)/ω²| on the plane rotor) exceeds the capacity {:.4e} kg·m of design {} ({}); lower it or set require_balanceable = false",
                        drawn(d),
                        d.capacity,
                        d.id,
                        super::plane_designs::describe(d)
                    ),
                ));
            }
        }
        if let Some(couple) = &s.couple
            && s.require_balanceable
        {
            // Either part in kg·m: the worst plane takes both at full size.
            let static_upper = s.unbalance.distribution.upper();
            let absolute = s.unbalance.scale() == Scale::Absolute
                || couple
                    .unbalance
                    .as_ref()
                    .is_some_and(|u| u.scale() == Scale::Absolute);
            let in_kgm = |v: f64, scale: Scale, d: &Design| match scale {
                Scale::Absolute => v,
                Scale::Capacity => v * d.capacity,
            };
            let worst = |d: &Design| {
                let u_s = in_kgm(static_upper, s.unbalance.scale(), d);
                match (&couple.unbalance, couple.follows_static) {
                    (Some(u), _) => u_s + in_kgm(u.distribution.upper(), u.scale(), d),
                    (None, Some(c)) => u_s * (1.0 + c.abs()),
                    (None, None) => u_s,
                }
            };
            if absolute && let Some(d) = designs.iter().find(|d| d.capacity < worst(d)) {
                let key = match &couple.unbalance {
                    Some(u) => format!("sampling.couple.unbalance.{}", u.distribution.upper_key()),
                    None => "sampling.couple.follows_static".to_string(),
                };
                return Err(invalid(
                    &key,
                    format!("{:.4e} kg·m in the worse plane", worst(d)),
                    &format!(
                        "the largest static plus couple unbalance a plane can take exceeds the capacity {:.4e} kg·m of design {} ({}); lower them or set require_balanceable = false",
                        d.capacity,
                        d.id,
                        super::plane_designs::describe(d)
                    ),
                ));
            }
        }
        if s.unbalance.scale() == Scale::Absolute && s.require_balanceable {
            let upper = s.unbalance.distribution.upper();
            if let Some(d) = designs.iter().find(|d| d.capacity < upper) {
                return Err(invalid(
                    &format!(
                        "sampling.unbalance.{}",
                        s.unbalance.distribution.upper_key()
                    ),
                    upper.to_string(),
                    &format!(
                        "exceeds the capacity {:.4e} kg·m of design {} ({}); lower it or set require_balanceable = false",
                        d.capacity,
                        d.id,
                        super::plane_designs::describe(d)
                    ),
                ));
            }
        }
        let total = designs.len() as u64 * u64::from(s.samples);
        if total > MAX_TOTAL_RUNS {
            return Err(invalid(
                "sampling.samples",
                s.samples.to_string(),
                &format!(
                    "{} designs × {} samples = {total} runs, more than the {MAX_TOTAL_RUNS} one study may hold (the runner keeps about 80 bytes of each run in memory, and runs.parquet takes about as much on disk); split the grid into several studies or use fewer samples",
                    designs.len(),
                    s.samples
                ),
            ));
        }
        Ok(StudyPlan {
            name,
            file: self,
            designs,
            text: text.to_string(),
        })
    }

    /// The unbalance (kg·m) the weights must add, besides cancelling the
    /// rotor's, for the scene's effects (an off-centre race held on the
    /// axis) at the nominal speed, on any rotor: each effect says what it
    /// asks, given the planes' compliance ([`crate::model::forced::plane_compliance`]).
    pub fn effects_capacity_demand(&self) -> f64 {
        let system = crate::model::system::RotorSystem::new(
            self.scene.rotor.build(),
            Vec::new(),
            self.scene.speed.clone(),
            Vec::new(),
        );
        let omega = self.scene.speed.nominal_speed();
        let compliance = |p: usize| crate::model::forced::plane_compliance(&system, p, omega);
        self.scene
            .effects
            .capacity_demand(system.rotor().planes(), &compliance)
    }

    /// Validate one design of this study's scene and compute its mass and capacity.
    ///
    /// Errors are (key, value, reason) in the study file's terms.
    pub fn resolve_design(&self, id: u32, spec: DesignSpec) -> Result<Design, InvalidKey> {
        let (kind, n) = (spec.kind, spec.n);
        let scene = Scene {
            rotor: self.scene.rotor.without_unbalance(),
            balancer: Some(spec.clone()),
            balancers: Vec::new(),
            cargo: Vec::new(),
            speed: self.scene.speed.clone(),
            effects: self.scene.effects.clone(),
        };
        scene.validate().map_err(|e| scene_error_key(e, kind, n))?;
        let geometry = spec.geometry().map_err(|e| {
            InvalidKey::new(
                "designs.rho".to_string(),
                format!("{:?}", spec.rho),
                e.to_string(),
            )
        })?;
        check_fits(n, geometry.rho).map_err(|e| {
            InvalidKey::new(
                "designs.rho".to_string(),
                geometry.rho.to_string(),
                e.to_string(),
            )
        })?;
        let cargo = kind
            .model()
            .cargo(&geometry)
            .map_err(|e| InvalidKey::new("designs", kind.to_string(), e.to_string()))?;
        let capacity = match kind {
            Kind::Pendulum => f64::from(n) * cargo.unbalance(),
            _ => crate::design::capacity::capacity_from_mass(
                n,
                geometry.rho,
                cargo.mass,
                spec.race_radius,
            )
            .map_err(|e| InvalidKey::new("designs", kind.to_string(), e.to_string()))?,
        };
        Ok(Design {
            id,
            spec,
            rho: geometry.rho,
            weight_mass: cargo.mass,
            track_radius: cargo.track_radius,
            capacity,
            plane_zero_capacity: capacity,
            plane_designs: Vec::new(),
            stall_torque: None,
        })
    }

    /// A balancer of plane 1, 2, … checked as plane 0's are, its errors named
    /// by its `[[designs.per_plane]]` entry.
    fn resolve_plane_design(&self, spec: DesignSpec) -> Result<Design, InvalidKey> {
        let plane = spec.plane;
        self.resolve_design(0, spec)
            .map_err(|InvalidKey { key, value, reason }| {
                let entry = self.designs.per_plane.iter().position(|a| a.plane == plane);
                let key = match (entry, key.strip_prefix("designs.")) {
                    (Some(i), Some(rest)) if ["n", "rho", "kind", "drag"].contains(&rest) => {
                        format!("designs.per_plane[{i}].{rest}")
                    }
                    _ => key,
                };
                InvalidKey::new(key, value, format!("{reason} (plane {plane})"))
            })
    }

    fn resolve_designs(&self) -> Result<Vec<Design>, InvalidKey> {
        let g = &self.designs;
        let mut designs = Vec::new();
        let (kinds, ns, rhos, drags) = (
            g.kind.values(),
            g.n.values(),
            g.rho.values(),
            g.drag.values(),
        );
        let torques = self.stall_torques()?;
        for (key, empty) in [
            ("designs.kind", kinds.is_empty()),
            ("designs.n", ns.is_empty()),
            ("designs.rho", rhos.is_empty()),
            ("designs.drag", drags.is_empty()),
        ] {
            if empty {
                return Err(InvalidKey::new(key, "[]", "needs at least one value"));
            }
        }
        for kind in &kinds {
            for &n in &ns {
                for rho in &rhos {
                    for &drag in &drags {
                        for &stall_torque in &torques {
                            let spec = DesignSpec {
                                kind: *kind,
                                n,
                                rho: rho.clone(),
                                race_radius: g.race_radius,
                                density: g.density,
                                roller_height: g.roller_height,
                                drag,
                                plane: 0,
                            };
                            let planes = self.scene.rotor.as_rotor().planes();
                            let others = if g.per_plane.is_empty() {
                                vec![Vec::new()]
                            } else {
                                super::plane_designs::combinations(&g.per_plane, planes, &spec)
                            };
                            for other in others {
                                let design =
                                    self.resolve_design(designs.len() as u32, spec.clone())?;
                                let plane_designs = other
                                    .into_iter()
                                    .map(|s| {
                                        self.resolve_plane_design(s)
                                            .map(|p| Design { id: design.id, ..p })
                                    })
                                    .collect::<Result<Vec<_>, _>>()?;
                                let capacity = plane_designs
                                    .iter()
                                    .map(|p| p.capacity)
                                    .fold(design.capacity, f64::min);
                                designs.push(Design {
                                    stall_torque,
                                    capacity,
                                    plane_designs,
                                    ..design
                                });
                            }
                        }
                    }
                }
            }
        }
        Ok(designs)
    }
}

impl StudyFile {
    /// The grid's stall torques: `[None]` when it sweeps none, else each
    /// value checked (positive, finite, a motor to apply it to).
    fn stall_torques(&self) -> Result<Vec<Option<f64>>, InvalidKey> {
        let Some(list) = &self.designs.stall_torque else {
            return Ok(vec![None]);
        };
        let key = "designs.stall_torque".to_string();
        let values = list.values();
        if !matches!(self.scene.speed, SpeedLaw::Motor { .. }) {
            return Err(InvalidKey::new(
                key,
                format!("{values:?}"),
                "a stall torque needs a motor: set scene.speed.mode = \"motor\"",
            ));
        }
        if values.is_empty() {
            return Err(InvalidKey::new(key, "[]", "needs at least one value"));
        }
        if let Some(bad) = values.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            return Err(InvalidKey::new(
                key,
                bad.to_string(),
                "a stall torque (N·m) must be positive and finite",
            ));
        }
        Ok(values.into_iter().map(Some).collect())
    }
}

/// Map a scene validation error onto the study file's keys.
fn scene_error_key(e: SceneError, kind: Kind, n: u32) -> InvalidKey {
    match e {
        SceneError::Invalid {
            field,
            value,
            reason,
        } => {
            let key = if let Some(rest) = field.strip_prefix("balancer.") {
                format!("designs.{rest}")
            } else {
                format!("scene.{field}")
            };
            InvalidKey::new(key, value, reason)
        }
        SceneError::Design(d) => {
            let key = match d.key() {
                "" => "designs".to_string(),
                k => format!("designs.{k}"),
            };
            // "rho = \"opt\": expected …" reads as the key's value and the
            // reason, with the design it was met in after them.
            let message = d.to_string();
            match message.split_once(": ") {
                Some((lhs, reason)) if lhs.contains(" = ") => {
                    let value = lhs.split_once(" = ").map_or(lhs, |(_, v)| v).to_string();
                    InvalidKey::new(
                        key,
                        value,
                        format!("{reason} (in the design {kind} n = {n})"),
                    )
                }
                _ => InvalidKey::new(key, format!("{kind} n = {n}"), message),
            }
        }
    }
}

/// Read, parse and validate a study file.
pub fn load(path: &std::path::Path) -> Result<StudyPlan, StudyError> {
    let shown = path.display().to_string();
    let text = crate::input_file::read_text(path).map_err(|source| StudyError::Io {
        path: shown.clone(),
        source,
    })?;
    StudyFile::parse(&text, &shown)?.plan(&text, &shown)
}
