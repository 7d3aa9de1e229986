//! The rig file: what was measured on a physical rig, how, and which keys
//! of its scene nobody measured. `study calibrate` reads it. Every key is
//! documented in `docs/calibration.md`.
//!
//! A rig file names a scene file (the rig as far as it is known), its
//! unknowns with their prior ranges, the cases that were run (each a few
//! scene keys set, such as the unbalance of a washer count), the protocol
//! that measured them (the scene's own speed law, or a stepped sweep), and
//! the measured points: a case, a quantity, a value and its uncertainty,
//! used in the fit or held out to be predicted.

use crate::input_file::{read_text, toml_message};
use crate::invalid_key::InvalidKey;
use crate::model::validate::shown;
use crate::uncertain::UncertainSpec;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A rig file as written by the user.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RigFile {
    /// Name of the rig (the default output folder's name).
    pub name: String,
    /// The scene file, relative to the rig file: the rig as far as it is known.
    pub scene: PathBuf,
    /// Seed of the prior draws, the proposal and any synthetic noise.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// The unknowns: scene-file keys (dotted, e.g.
    /// `"effects.rolling_resistance.coefficient"`, `"balancer.drag"`) and
    /// their prior distributions.
    pub unknowns: UncertainSpec,
    /// How every case was run.
    pub protocol: Protocol,
    /// The cases run on the rig.
    #[serde(rename = "case")]
    pub cases: Vec<Case>,
    /// The measured points.
    #[serde(rename = "point")]
    pub points: Vec<Point>,
}

fn default_seed() -> u64 {
    crate::study::plan::config::DEFAULT_SEED
}

/// How the rig ran a case and read its quantities.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Protocol {
    /// One run under the scene's own speed law: settling time and residual.
    Run,
    /// A stepped speed sweep carrying the state (`study stepped`): bearing
    /// peaks, their ratio to the same without the balls, onset speed.
    Stepped {
        /// Lowest and highest speed of the run-up (rpm).
        rpm: [f64; 2],
        /// Speed step (rpm).
        step_rpm: f64,
        /// Time held at each speed (s).
        dwell: f64,
        /// Time at the end of each dwell over which the rig read the
        /// vibration (s); default one revolution.
        #[serde(default)]
        window: Option<f64>,
        /// Run back down after the run-up.
        #[serde(default)]
        down: bool,
    },
}

/// One case run on the rig: the scene with a few keys set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// The case's name, as points refer to it.
    pub name: String,
    /// Scene-file keys (dotted) and their values in this case.
    #[serde(default)]
    pub set: BTreeMap<String, f64>,
}

/// A measured quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Time to settle, capped at the run's horizon when it never settles (s; `run`).
    SettlingTime,
    /// RMS of the vibration over the residual window (m; `run`).
    Residual,
    /// Mean over the bearings and over the steps in `rpm` of the bearing
    /// peak (m; `stepped`).
    BearingPeak,
    /// The same over the peak without the balls' unbalance (`stepped`).
    Ratio,
    /// Lowest run-up speed from which the balls help for good (rpm;
    /// `stepped`; the top speed when they never do).
    OnsetRpm,
    /// Mean over the steps in `rpm` of the angle between the balls' mean
    /// direction and the light spot, either way (degrees; `stepped`).
    BallOffsetDeg,
}

impl Quantity {
    /// Its name in files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::SettlingTime => "settling_time",
            Quantity::Residual => "residual",
            Quantity::BearingPeak => "bearing_peak",
            Quantity::Ratio => "ratio",
            Quantity::OnsetRpm => "onset_rpm",
            Quantity::BallOffsetDeg => "ball_offset_deg",
        }
    }

    /// The values a reading of it can take: every quantity is a size or a
    /// speed (≥ 0), and an angle either way is at most 180°.
    pub fn range(self) -> (f64, f64) {
        match self {
            Quantity::BallOffsetDeg => (0.0, 180.0),
            _ => (0.0, f64::INFINITY),
        }
    }

    /// True when a stepped sweep measures it (false: a run does).
    pub fn is_stepped(self) -> bool {
        matches!(
            self,
            Quantity::BearingPeak | Quantity::Ratio | Quantity::OnsetRpm | Quantity::BallOffsetDeg
        )
    }
}

/// What a point is for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Use {
    /// Fitted: the unknowns are chosen to match it.
    #[default]
    Fit,
    /// Held out: predicted from the fit and compared.
    Predict,
}

impl Use {
    /// Its name in files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Use::Fit => "fit",
            Use::Predict => "predict",
        }
    }
}

/// Which run of a stepped sweep a point was read on.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Run {
    /// The run-up.
    #[default]
    Up,
    /// The run-down.
    Down,
    /// Both.
    Both,
}

/// One measured point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Point {
    /// The case it was measured in.
    pub case: String,
    /// What was measured.
    pub quantity: Quantity,
    /// The measured value, in the quantity's unit.
    pub value: f64,
    /// Its standard uncertainty (one standard deviation, same unit).
    pub sd: f64,
    /// Fitted or held out.
    #[serde(default, rename = "use")]
    pub role: Use,
    /// Speed band of a stepped point (rpm): the mean over its steps.
    #[serde(default)]
    pub rpm: Option<[f64; 2]>,
    /// Run-up, run-down or both, for a stepped point.
    #[serde(default)]
    pub run: Run,
    /// Where the number comes from (a table, a figure and how it was read).
    #[serde(default)]
    pub source: Option<String>,
}

/// A rig file that could not be read or is refused.
#[derive(Debug, thiserror::Error)]
pub enum RigFileError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// TOML syntax or schema error.
    #[error("{path}: {message}")]
    Parse {
        /// The path.
        path: String,
        /// The parser's message.
        message: String,
    },
    /// A value refused, naming its key.
    #[error("{path}: {key}")]
    Invalid {
        /// The path.
        path: String,
        /// The refused key.
        key: InvalidKey,
    },
}

impl RigFile {
    /// Read, parse and check a rig file (not its scene: see
    /// [`super::problem::RigProblem::new`]).
    pub fn read(path: &Path) -> Result<Self, RigFileError> {
        let shown_path = path.display().to_string();
        let text = read_text(path).map_err(|source| RigFileError::Io {
            path: shown_path.clone(),
            source,
        })?;
        let rig: RigFile = toml::from_str(&text).map_err(|e| RigFileError::Parse {
            path: shown_path.clone(),
            message: toml_message(&text, &e),
        })?;
        rig.check().map_err(|key| RigFileError::Invalid {
            path: shown_path,
            key,
        })?;
        Ok(rig)
    }

    /// The scene file's path, relative to the rig file at `rig_path`.
    pub fn scene_path(&self, rig_path: &Path) -> PathBuf {
        rig_path
            .parent()
            .unwrap_or_else(|| Path::new("."))
            .join(&self.scene)
    }

    /// The file's own consistency (the scene's keys are checked against
    /// the scene itself when the problem is built).
    pub fn check(&self) -> Result<(), InvalidKey> {
        if self.unknowns.is_empty() {
            return Err(InvalidKey::new(
                "unknowns",
                "{}",
                "name at least one scene key to fit, with its prior range",
            ));
        }
        for (key, d) in &self.unknowns {
            d.check()
                .map_err(|e| e.under(&format!("unknowns.\"{key}\"")))?;
        }
        self.check_protocol()?;
        let mut names = std::collections::BTreeSet::new();
        for (i, case) in self.cases.iter().enumerate() {
            if !names.insert(case.name.as_str()) {
                return Err(InvalidKey::new(
                    format!("case[{i}].name"),
                    &case.name,
                    "two cases have this name",
                ));
            }
            for (key, value) in &case.set {
                if !value.is_finite() {
                    return Err(InvalidKey::new(
                        format!("case[{i}].set.\"{key}\""),
                        shown(*value),
                        "must be finite",
                    ));
                }
                if self.unknowns.contains_key(key) {
                    return Err(InvalidKey::new(
                        format!("case[{i}].set.\"{key}\""),
                        shown(*value),
                        "this key is an unknown to be fitted; a case cannot also set it",
                    ));
                }
            }
        }
        if self.points.is_empty() {
            return Err(InvalidKey::new(
                "point",
                "[]",
                "give at least one measured point",
            ));
        }
        for (i, p) in self.points.iter().enumerate() {
            self.check_point(p)
                .map_err(|e| e.under(&format!("point[{i}]")))?;
        }
        if !self.points.iter().any(|p| p.role == Use::Fit) {
            return Err(InvalidKey::new(
                "point",
                "no point with use = \"fit\"",
                "at least one point must be fitted",
            ));
        }
        Ok(())
    }

    fn check_protocol(&self) -> Result<(), InvalidKey> {
        let Protocol::Stepped {
            rpm,
            step_rpm,
            dwell,
            window,
            down,
        } = self.protocol
        else {
            return Ok(());
        };
        let bad = |key: &str, v: f64, why: &str| {
            Err(InvalidKey::new(format!("protocol.{key}"), shown(v), why))
        };
        if !(rpm[0].is_finite() && rpm[0] > 0.0 && rpm[1].is_finite() && rpm[1] > rpm[0]) {
            return bad("rpm", rpm[1], "must be [lo, hi] with 0 < lo < hi (rpm)");
        }
        if !(step_rpm.is_finite() && step_rpm > 0.0) || (rpm[1] - rpm[0]) / step_rpm > 100_000.0 {
            return bad(
                "step_rpm",
                step_rpm,
                "must be positive, and at most 100 000 steps over the range",
            );
        }
        let slowest_rev = 60.0 / rpm[0];
        if !(dwell.is_finite() && dwell >= slowest_rev) {
            return bad(
                "dwell",
                dwell,
                &format!(
                    "must last at least one revolution at the lowest speed ({slowest_rev:.4} s)"
                ),
            );
        }
        if let Some(w) = window
            && !(w.is_finite() && w > 0.0 && w <= dwell)
        {
            return bad("window", w, "must be positive and no longer than the dwell");
        }
        let to_rad = std::f64::consts::PI / 30.0;
        let speeds = crate::simulation::stepped::stepped_speeds(
            rpm[0] * to_rad,
            rpm[1] * to_rad,
            step_rpm * to_rad,
            down,
        );
        if let Err(crate::model::scene::SceneError::Invalid { reason, .. }) =
            crate::simulation::stepped::check_dwell(&speeds, dwell)
        {
            return bad("dwell", dwell, &reason);
        }
        Ok(())
    }

    fn check_point(&self, p: &Point) -> Result<(), InvalidKey> {
        if !self.cases.iter().any(|c| c.name == p.case) {
            let names: Vec<&str> = self.cases.iter().map(|c| c.name.as_str()).collect();
            return Err(InvalidKey::new(
                "case",
                &p.case,
                format!(
                    "no [[case]] has this name (there are: {})",
                    names.join(", ")
                ),
            ));
        }
        if !p.value.is_finite() {
            return Err(InvalidKey::new("value", shown(p.value), "must be finite"));
        }
        if !(p.sd.is_finite() && p.sd > 0.0) {
            return Err(InvalidKey::new(
                "sd",
                shown(p.sd),
                "the measurement's standard uncertainty must be positive: no reading is exact",
            ));
        }
        let stepped = matches!(self.protocol, Protocol::Stepped { .. });
        if p.quantity.is_stepped() != stepped {
            let needs = if p.quantity.is_stepped() {
                "a stepped sweep (protocol.kind = \"stepped\")"
            } else {
                "one run (protocol.kind = \"run\")"
            };
            return Err(InvalidKey::new(
                "quantity",
                p.quantity.name(),
                format!("is measured by {needs}, not by this rig file's protocol"),
            ));
        }
        match (p.quantity, p.rpm) {
            (Quantity::BearingPeak | Quantity::Ratio | Quantity::BallOffsetDeg, None) => {
                Err(InvalidKey::new(
                    "rpm",
                    "missing",
                    "give the speed band [lo, hi] (rpm) the reading averages over",
                ))
            }
            (Quantity::BearingPeak | Quantity::Ratio | Quantity::BallOffsetDeg, Some([lo, hi]))
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) =>
            {
                Err(InvalidKey::new(
                    "rpm",
                    shown(hi),
                    "must be [lo, hi], finite, with lo ≤ hi",
                ))
            }
            (q, Some(_))
                if !matches!(
                    q,
                    Quantity::BearingPeak | Quantity::Ratio | Quantity::BallOffsetDeg
                ) =>
            {
                Err(InvalidKey::new(
                    "rpm",
                    "given",
                    format!("{} is not read over a speed band", q.name()),
                ))
            }
            _ => Ok(()),
        }
    }
}
