//! A value a user gave outside its domain: the dotted key as the file
//! spells it, the value as given, and why it is refused. Every check of a
//! study or scene file returns this one type, and every error message that
//! names a key is built from it.

/// A refused value: key, value and reason.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InvalidKey {
    /// Dotted key, as the file spells it (`sampling.couple.at`).
    pub key: String,
    /// The offending value, as shown to the user.
    pub value: String,
    /// Why it is refused.
    pub reason: String,
}

impl InvalidKey {
    /// A refusal of `value` at `key`, for `reason`.
    pub fn new(
        key: impl Into<String>,
        value: impl Into<String>,
        reason: impl Into<String>,
    ) -> Self {
        InvalidKey {
            key: key.into(),
            value: value.into(),
            reason: reason.into(),
        }
    }
}

impl InvalidKey {
    /// The same refusal with its key under `prefix` (`max` → `sampling.unbalance.max`).
    pub fn under(self, prefix: &str) -> Self {
        InvalidKey {
            key: format!("{prefix}.{}", self.key),
            ..self
        }
    }
}

impl std::fmt::Display for InvalidKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} = {}: {}", self.key, self.value, self.reason)
    }
}
