//! A parameter out of its range: which one, its value, and what it must be.

/// A parameter out of its range ([`super::SimParams::validate`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("parameter `{name}` = {value} {rule}")]
pub struct ParamError {
    /// The parameter as [`super::SimParams`] names it: `dt`, `stiffness`,
    /// `solver.tolerance`, `guard.headroom`, …
    pub name: &'static str,
    /// Its value, as written.
    pub value: String,
    /// What it must be: "is out of range (0 < dt ≤ 1 s)", "must be > 0", …
    pub rule: String,
}

impl ParamError {
    pub fn new(name: &'static str, value: impl std::fmt::Display, rule: impl Into<String>) -> Self {
        Self {
            name,
            value: value.to_string(),
            rule: rule.into(),
        }
    }

    /// `Ok` where `ok` holds, else the error naming `name`, its `value` and its `rule`.
    ///
    /// # Errors
    /// The [`ParamError`] when `ok` is false.
    pub fn require(
        ok: bool,
        name: &'static str,
        value: impl std::fmt::Display,
        rule: impl Into<String>,
    ) -> Result<(), Self> {
        if ok {
            Ok(())
        } else {
            Err(Self::new(name, value, rule))
        }
    }
}
