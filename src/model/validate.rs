//! Why a scene is rejected, and the small domain checks every part of the
//! model uses to say so. A leaf: rotor models, effects and the scene all
//! validate their own fields with these, so nothing here may import from
//! [`crate::model`] (that is what keeps the model's modules free of cycles).

use crate::design::DesignError;

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

/// A [`SceneError::Invalid`] for a numeric field.
pub(crate) fn invalid(field: &str, value: f64, reason: &str) -> SceneError {
    SceneError::Invalid {
        field: field.to_string(),
        value: shown(value),
        reason: reason.to_string(),
    }
}

/// A number as a user would write it in a message: plain in the everyday
/// range, scientific beyond it (`1e300`, not three hundred digits).
pub fn shown(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&v.abs()) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

/// Require a positive, finite value.
pub(crate) fn positive(field: &str, value: f64) -> Result<(), SceneError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be positive and finite"))
    }
}

/// Most balancer planes a rotor may carry: machines carry one or two, a
/// long shaft a few; each plane adds a balancer's equations, and a
/// 120 000-plane array once ran for ever instead of being refused.
pub const MAX_PLANES: usize = 16;
/// Most weights over every balancer of a scene: the state and the
/// implicit method's Jacobian grow with their number (its square), and
/// two full balancers of 256 weights each stay within it.
pub const MAX_TOTAL_WEIGHTS: usize = 512;

/// Slowest spin rate a scene may name (rad/s): a revolution of over an hour
/// and three quarters; below it no run reaches a revolution boundary.
pub const MIN_SPIN_RATE: f64 = 1e-3;
/// Fastest spin rate a scene may name (rad/s): ten million rpm, far beyond
/// any ultracentrifuge (about 16 000 rad/s); above it every run fails.
pub const MAX_SPIN_RATE: f64 = 1e6;

/// Require a spin rate (rad/s) in [`MIN_SPIN_RATE`, `MAX_SPIN_RATE`], or 0
/// where `zero_allowed` (a start from rest).
pub(crate) fn spin_rate(field: &str, value: f64, zero_allowed: bool) -> Result<(), SceneError> {
    if (zero_allowed && value == 0.0) || (MIN_SPIN_RATE..=MAX_SPIN_RATE).contains(&value) {
        Ok(())
    } else {
        Err(invalid(
            field,
            value,
            &format!(
                "must be a positive spin rate in [{MIN_SPIN_RATE:e}, {MAX_SPIN_RATE:e}] rad/s{} (outside it every run fails: no revolution completes, or the steps underflow)",
                if zero_allowed { ", or 0" } else { "" }
            ),
        ))
    }
}

/// Smallest and largest race radius (m): a tenth of a millimetre to a
/// hundred metres spans micro-drives to the largest drums (and the
/// dimensionless scenes' R = 1); beyond it the weights' mass over- or
/// underflows.
pub const RACE_RADIUS_RANGE: (f64, f64) = (1e-4, 100.0);
/// Lightest and densest weight material (kg/m³): from foam to ten times
/// the densest metal (the dimensionless scenes use 10 to 20).
pub const DENSITY_RANGE: (f64, f64) = (1.0, 1e5);

/// Require `value` in `[range.0, range.1]` (`unit` for the message).
pub(crate) fn within(
    field: &str,
    value: f64,
    range: (f64, f64),
    unit: &str,
) -> Result<(), SceneError> {
    if (range.0..=range.1).contains(&value) {
        Ok(())
    } else {
        Err(invalid(
            field,
            value,
            &format!("must be in [{}, {}] {unit}", shown(range.0), shown(range.1)),
        ))
    }
}

/// Require a finite value.
pub(crate) fn finite(field: &str, value: f64) -> Result<(), SceneError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(invalid(field, value, "must be finite"))
    }
}

/// Require a non-negative, finite value.
pub(crate) fn non_negative(field: &str, value: f64) -> Result<(), SceneError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be zero or positive and finite"))
    }
}
