//! Speed laws of the rotor: prescribed (constant, ramp) or driven by a torque.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How the rotor's spin angle φ evolves.
///
/// Files give each speed in rad/s (`omega…`) or in rpm (`rpm…`), one of the
/// two ([`SpeedLawText`]); the law itself holds rad/s.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "mode", rename_all = "snake_case")]
#[schemars(with = "SpeedLawText")]
pub enum SpeedLaw {
    /// φ = ω t (seed 004, eqs 19–20).
    Constant {
        /// Spin speed ω (rad/s).
        omega: f64,
    },
    /// Prescribed linear run-up from `omega_start` to `omega_end` over
    /// `duration`, constant afterwards.
    Ramp {
        /// Speed at t = 0 (rad/s).
        omega_start: f64,
        /// Speed from t = duration on (rad/s).
        omega_end: f64,
        /// Length of the ramp (s).
        duration: f64,
    },
    /// Engine with a linear characteristic M_rot = M_s (1 − φ̇/ω_sync)
    /// (seed 004, eqs 3, 15–18): φ is a free coordinate.
    Motor {
        /// Stall torque M_s (N·m).
        stall_torque: f64,
        /// Synchronous (no-load) speed ω_sync (rad/s).
        omega_sync: f64,
        /// Speed at t = 0 (rad/s).
        #[serde(default)]
        omega_start: f64,
    },
    /// No torque at all: φ free, for conservation checks.
    Free {
        /// Speed at t = 0 (rad/s).
        omega_start: f64,
    },
}

/// rad/s per rpm.
pub const RAD_PER_RPM: f64 = std::f64::consts::PI / 30.0;

/// A speed law as a file writes it: every speed in rad/s or in rpm.
#[derive(Deserialize, JsonSchema)]
#[serde(
    tag = "mode",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "a table with `mode` = \"constant\", \"ramp\", \"motor\" or \"free\" and that mode's keys"
)]
pub enum SpeedLawText {
    /// φ = ω t.
    Constant {
        /// Spin speed ω (rad/s); or give `rpm`.
        #[serde(default)]
        omega: Option<f64>,
        /// Spin speed (rpm, revolutions per minute); or give `omega`.
        #[serde(default)]
        rpm: Option<f64>,
    },
    /// Linear run-up from the start speed to the end speed over `duration`.
    Ramp {
        /// Speed at t = 0 (rad/s); or give `rpm_start`.
        #[serde(default)]
        omega_start: Option<f64>,
        /// Speed at t = 0 (rpm); or give `omega_start`.
        #[serde(default)]
        rpm_start: Option<f64>,
        /// Speed from t = duration on (rad/s); or give `rpm_end`.
        #[serde(default)]
        omega_end: Option<f64>,
        /// Speed from t = duration on (rpm); or give `omega_end`.
        #[serde(default)]
        rpm_end: Option<f64>,
        /// Length of the ramp (s).
        duration: f64,
    },
    /// Engine with a linear characteristic M_rot = M_s (1 − φ̇/ω_sync).
    Motor {
        /// Stall torque M_s (N·m).
        stall_torque: f64,
        /// Synchronous (no-load) speed ω_sync (rad/s); or give `rpm_sync`.
        #[serde(default)]
        omega_sync: Option<f64>,
        /// Synchronous (no-load) speed (rpm); or give `omega_sync`.
        #[serde(default)]
        rpm_sync: Option<f64>,
        /// Speed at t = 0 (rad/s; default 0); or give `rpm_start`.
        #[serde(default)]
        omega_start: Option<f64>,
        /// Speed at t = 0 (rpm; default 0); or give `omega_start`.
        #[serde(default)]
        rpm_start: Option<f64>,
    },
    /// No torque at all: φ free, for conservation checks.
    Free {
        /// Speed at t = 0 (rad/s); or give `rpm_start`.
        #[serde(default)]
        omega_start: Option<f64>,
        /// Speed at t = 0 (rpm); or give `omega_start`.
        #[serde(default)]
        rpm_start: Option<f64>,
    },
}

/// One speed given as `omega_key` (rad/s) or `rpm_key` (rpm), never both:
/// in rad/s; `default` when neither is given, or an error naming both keys.
/// A start speed may be 0 (`zero_allowed`).
fn one_speed(
    (omega_key, omega): (&str, Option<f64>),
    (rpm_key, rpm): (&str, Option<f64>),
    default: Option<f64>,
    zero_allowed: bool,
) -> Result<f64, String> {
    match (omega, rpm, default) {
        (Some(w), None, _) => Ok(w),
        (None, Some(r), _) => {
            // An rpm beyond any spin rate is named as typed, not as the
            // rad/s it would become.
            let w = r * RAD_PER_RPM;
            if (zero_allowed && r == 0.0)
                || (super::validate::MIN_SPIN_RATE..=super::validate::MAX_SPIN_RATE).contains(&w)
            {
                Ok(w)
            } else {
                Err(format!(
                    "speed.{rpm_key} = {}: must be a spin rate in [{:.3e}, {:.3e}] rpm{} (outside it every run fails)",
                    super::validate::shown(r),
                    super::validate::MIN_SPIN_RATE / RAD_PER_RPM,
                    super::validate::MAX_SPIN_RATE / RAD_PER_RPM,
                    if zero_allowed { ", or 0" } else { "" }
                ))
            }
        }
        (Some(w), Some(r), _) => Err(format!(
            "speed.{omega_key} = {} and speed.{rpm_key} = {}: give the speed once, in rad/s (`{omega_key}`) or in rpm (`{rpm_key}`), not both",
            super::validate::shown(w),
            super::validate::shown(r)
        )),
        (None, None, Some(d)) => Ok(d),
        (None, None, None) => Err(format!(
            "missing field `{omega_key}`: give the speed in rad/s (`{omega_key}`) or in rpm (`{rpm_key}`)"
        )),
    }
}

impl<'de> Deserialize<'de> for SpeedLaw {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        // Through the table's text, so that a bad value's error names its key.
        let table = toml::Table::deserialize(deserializer)?;
        let text: SpeedLawText = crate::input_file::from_table(&table).map_err(D::Error::custom)?;
        SpeedLaw::try_from(text).map_err(D::Error::custom)
    }
}

impl TryFrom<SpeedLawText> for SpeedLaw {
    type Error = String;

    fn try_from(text: SpeedLawText) -> Result<Self, String> {
        Ok(match text {
            SpeedLawText::Constant { omega, rpm } => SpeedLaw::Constant {
                omega: one_speed(("omega", omega), ("rpm", rpm), None, false)?,
            },
            SpeedLawText::Ramp {
                omega_start,
                rpm_start,
                omega_end,
                rpm_end,
                duration,
            } => SpeedLaw::Ramp {
                omega_start: one_speed(
                    ("omega_start", omega_start),
                    ("rpm_start", rpm_start),
                    None,
                    true,
                )?,
                omega_end: one_speed(("omega_end", omega_end), ("rpm_end", rpm_end), None, false)?,
                duration,
            },
            SpeedLawText::Motor {
                stall_torque,
                omega_sync,
                rpm_sync,
                omega_start,
                rpm_start,
            } => SpeedLaw::Motor {
                stall_torque,
                omega_sync: one_speed(
                    ("omega_sync", omega_sync),
                    ("rpm_sync", rpm_sync),
                    None,
                    false,
                )?,
                omega_start: one_speed(
                    ("omega_start", omega_start),
                    ("rpm_start", rpm_start),
                    Some(0.0),
                    true,
                )?,
            },
            SpeedLawText::Free {
                omega_start,
                rpm_start,
            } => SpeedLaw::Free {
                omega_start: one_speed(
                    ("omega_start", omega_start),
                    ("rpm_start", rpm_start),
                    None,
                    false,
                )?,
            },
        })
    }
}

impl SpeedLaw {
    /// True when φ(t) is prescribed (not a degree of freedom).
    pub fn is_prescribed(&self) -> bool {
        matches!(self, SpeedLaw::Constant { .. } | SpeedLaw::Ramp { .. })
    }

    /// φ, φ̇, φ̈ at time t for a prescribed law (zeros for free laws).
    pub fn prescribed(&self, t: f64) -> (f64, f64, f64) {
        match *self {
            SpeedLaw::Constant { omega } => (omega * t, omega, 0.0),
            SpeedLaw::Ramp {
                omega_start,
                omega_end,
                duration,
            } => {
                let accel = (omega_end - omega_start) / duration;
                if t < duration {
                    (
                        omega_start * t + 0.5 * accel * t * t,
                        omega_start + accel * t,
                        accel,
                    )
                } else {
                    let phi_end = 0.5 * (omega_start + omega_end) * duration;
                    (phi_end + omega_end * (t - duration), omega_end, 0.0)
                }
            }
            SpeedLaw::Motor { .. } | SpeedLaw::Free { .. } => (0.0, 0.0, 0.0),
        }
    }

    /// Driving torque at spin rate φ̇ for a free law (zero for prescribed laws).
    pub fn torque(&self, spin_rate: f64) -> f64 {
        match *self {
            SpeedLaw::Motor {
                stall_torque,
                omega_sync,
                ..
            } => stall_torque * (1.0 - spin_rate / omega_sync),
            _ => 0.0,
        }
    }

    /// Spin rate at t = 0.
    pub fn initial_rate(&self) -> f64 {
        match *self {
            SpeedLaw::Constant { omega } => omega,
            SpeedLaw::Ramp { omega_start, .. } => omega_start,
            SpeedLaw::Motor { omega_start, .. } | SpeedLaw::Free { omega_start } => omega_start,
        }
    }

    /// When the speed reaches its operating value, if the law says so in
    /// advance: at once for a constant speed, at the end of a ramp; `None`
    /// for a motor or a free rotor, whose speed only approaches it (the
    /// observer then watches φ̇).
    pub fn operating_time(&self) -> Option<f64> {
        match *self {
            SpeedLaw::Constant { .. } => Some(0.0),
            SpeedLaw::Ramp { duration, .. } => Some(duration),
            SpeedLaw::Motor { .. } | SpeedLaw::Free { .. } => None,
        }
    }

    /// The operating speed that defines a "revolution" for metrics: ω, the
    /// ramp's end speed, the motor's synchronous speed, or the free start
    /// speed; settling is judged there (see `operating_time`).
    pub fn nominal_speed(&self) -> f64 {
        match *self {
            SpeedLaw::Constant { omega } => omega,
            SpeedLaw::Ramp { omega_end, .. } => omega_end,
            SpeedLaw::Motor { omega_sync, .. } => omega_sync,
            SpeedLaw::Free { omega_start } => omega_start,
        }
    }
}
