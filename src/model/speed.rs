//! Speed laws of the rotor: prescribed (constant, ramp) or driven by a torque.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How the rotor's spin angle φ evolves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(
    tag = "mode",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "a table with `mode` = \"constant\", \"ramp\", \"motor\" or \"free\" and that mode's keys"
)]
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
