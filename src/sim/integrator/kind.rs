//! The integrators a user can choose, by name.

use super::semi_implicit_euler::SemiImplicitEuler;
use super::step::Integrator;
use super::velocity_verlet::VelocityVerlet;

/// The integrators a user can choose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    /// Symplectic Euler: `v += a·h; x += v·h`. First order, one force evaluation, bounded
    /// energy error for conservative forces.
    SemiImplicitEuler,
    /// Velocity Verlet: `x += v·h + ½a·h²; v += ½(a + a')·h`. Second order, symplectic, one
    /// force evaluation per step (the new acceleration is reused by the next step).
    Verlet,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 2] =
        [IntegratorKind::SemiImplicitEuler, IntegratorKind::Verlet];

    /// The name the CLI accepts and JSON prints.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::SemiImplicitEuler => "semi-implicit-euler",
            IntegratorKind::Verlet => "verlet",
        }
    }

    /// Human-readable label for the UI.
    pub fn label(self) -> &'static str {
        match self {
            IntegratorKind::SemiImplicitEuler => "Semi-implicit Euler",
            IntegratorKind::Verlet => "Velocity Verlet",
        }
    }

    /// A fresh integrator of this kind.
    pub fn build(self) -> Box<dyn Integrator> {
        match self {
            IntegratorKind::SemiImplicitEuler => Box::new(SemiImplicitEuler::default()),
            IntegratorKind::Verlet => Box::new(VelocityVerlet::default()),
        }
    }
}

impl std::fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for IntegratorKind {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let wanted = s.trim().to_ascii_lowercase().replace('_', "-");
        Self::ALL
            .into_iter()
            .find(|k| k.name() == wanted || (wanted == "euler" && *k == Self::SemiImplicitEuler))
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|k| k.name()).collect();
                format!(
                    "unknown integrator `{s}`; choose one of: {}",
                    names.join(", ")
                )
            })
    }
}
