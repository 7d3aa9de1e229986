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
        value: value.to_string(),
        reason: reason.to_string(),
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
