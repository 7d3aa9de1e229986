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
use crate::model::validate::{MAX_PLANES, MAX_TOTAL_WEIGHTS};
use crate::simulation::SolverSettings;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

mod resolve;

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
    /// Scene keys nobody measured exactly, each with a distribution, drawn
    /// per sample (`"effects.rolling_resistance.coefficient" = { distribution
    /// = "log_uniform", min = 3e-4, max = 3e-3 }`).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub uncertain: crate::uncertain::UncertainSpec,
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
    /// How the part is chosen among the designs not distinguishable from
    /// #1 at α: `"mass"` (least balancer mass, then fewest weights, then
    /// smallest ρ) or `"first"` (#1 by the point estimate).
    #[serde(default)]
    pub tie_break: super::tie_break::TieBreak,
    /// When the leading design settles too rarely, at most this many of its
    /// samples that did not settle are re-run with each effect removed in
    /// turn, to name the cause (`causes.parquet`); 0 turns it off.
    #[serde(default = "default_counterfactual_runs")]
    pub counterfactual_runs: u32,
}

impl Default for SummarySpec {
    fn default() -> Self {
        SummarySpec {
            rank_by: super::criterion::Criterion::default(),
            pareto: default_pareto(),
            tie_break: super::tie_break::TieBreak::default(),
            counterfactual_runs: default_counterfactual_runs(),
        }
    }
}

/// Samples re-run per effect by default: enough to tell "all" from "none"
/// (6 of 6 against 0 of 6), few enough to add little to a study's time.
fn default_counterfactual_runs() -> u32 {
    32
}

/// The most samples `summary.counterfactual_runs` may re-run.
pub const MAX_COUNTERFACTUAL_RUNS: u32 = 1024;

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
    /// Race the designs (docs/statistics.md, "Racing"): samples run in
    /// batches, and a design significantly worse than the leader, and
    /// dominated on every reported measure, leaves the race and keeps its
    /// runs. `false` runs every sample (baselines and checks always do).
    #[serde(default = "yes")]
    pub racing: bool,
    /// Manufacturing tolerances of the weights, sampled per run (off unless given).
    #[serde(default)]
    pub tolerances: Option<super::tolerance::Tolerances>,
    /// The couple unbalance of a rotor on two supports (off unless given;
    /// `sampling.unbalance` is then the static part).
    #[serde(default)]
    pub couple: Option<super::couple::CoupleSpec>,
    /// Where the sampled inputs come from: `random` (default) or `sobol`
    /// (an Owen-scrambled Sobol sequence; a power of two of samples).
    #[serde(default)]
    pub sequence: super::stream::Sequence,
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

/// Read, parse and validate a study file.
pub fn load(path: &std::path::Path) -> Result<StudyPlan, StudyError> {
    let shown = path.display().to_string();
    let text = crate::input_file::read_text(path).map_err(|source| StudyError::Io {
        path: shown.clone(),
        source,
    })?;
    StudyFile::parse(&text, &shown)?.plan(&text, &shown)
}
