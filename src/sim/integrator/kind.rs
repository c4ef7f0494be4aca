//! The integrators a user can choose, by name.

/// The integrators a user can choose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    /// Forward Euler: `x += v·h; v += a·h`, both from the start of the step. First order, one
    /// force evaluation; gains energy every step.
    ExplicitEuler,
    /// Symplectic Euler: `v += a·h; x += v·h`. First order, one force evaluation, bounded
    /// energy error for conservative forces.
    SemiImplicitEuler,
    /// Velocity Verlet: `x += v·h + ½a·h²; v += ½(a + a')·h`. Second order, symplectic, one
    /// force evaluation per step (the new acceleration is reused by the next step).
    Verlet,
    /// Midpoint Runge–Kutta. Second order, two force evaluations.
    Rk2,
    /// Classical Runge–Kutta. Fourth order, four force evaluations.
    Rk4,
    /// Linearised backward Euler (Baraff–Witkin) solved by conjugate gradients. First order,
    /// stable at any step for the springs; damps.
    ImplicitEuler,
    /// Extended position-based dynamics: springs as compliant distance constraints.
    Xpbd,
    /// Vertex block descent: implicit Euler's step as a minimisation, one particle at a
    /// time by a 3 × 3 Newton step, colour by colour.
    Vbd,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 8] = [
        IntegratorKind::ExplicitEuler,
        IntegratorKind::SemiImplicitEuler,
        IntegratorKind::Verlet,
        IntegratorKind::Rk2,
        IntegratorKind::Rk4,
        IntegratorKind::ImplicitEuler,
        IntegratorKind::Xpbd,
        IntegratorKind::Vbd,
    ];

    /// The name the CLI accepts and JSON prints.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::ExplicitEuler => "explicit-euler",
            IntegratorKind::SemiImplicitEuler => "semi-implicit-euler",
            IntegratorKind::Verlet => "verlet",
            IntegratorKind::Rk2 => "rk2",
            IntegratorKind::Rk4 => "rk4",
            IntegratorKind::ImplicitEuler => "implicit-euler",
            IntegratorKind::Xpbd => "xpbd",
            IntegratorKind::Vbd => "vbd",
        }
    }

    /// Human-readable label for the UI.
    pub fn label(self) -> &'static str {
        match self {
            IntegratorKind::ExplicitEuler => "Explicit Euler",
            IntegratorKind::SemiImplicitEuler => "Semi-implicit Euler",
            IntegratorKind::Verlet => "Velocity Verlet",
            IntegratorKind::Rk2 => "RK2 (midpoint)",
            IntegratorKind::Rk4 => "RK4",
            IntegratorKind::ImplicitEuler => "Implicit Euler (CG)",
            IntegratorKind::Xpbd => "XPBD",
            IntegratorKind::Vbd => "VBD (vertex block descent)",
        }
    }

    /// Order of accuracy in the step (global error ∝ hᵖ).
    pub fn order(self) -> u32 {
        match self {
            IntegratorKind::ExplicitEuler
            | IntegratorKind::SemiImplicitEuler
            | IntegratorKind::ImplicitEuler
            | IntegratorKind::Xpbd
            | IntegratorKind::Vbd => 1,
            IntegratorKind::Verlet | IntegratorKind::Rk2 => 2,
            IntegratorKind::Rk4 => 4,
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
