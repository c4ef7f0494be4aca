//! Which floating-point type a simulation computes in ([`Precision`]).

/// The precision of the state, the forces and the integrators: `f32` (the default: the
/// vectorised kernels, half the memory) or `f64` (the same code over `f64`; rounding stays
/// about nine orders of magnitude further down, for measurements such as the accuracy
/// report's). Contacts compute in `f32` either way.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    #[default]
    F32,
    F64,
}

impl Precision {
    pub const ALL: [Precision; 2] = [Precision::F32, Precision::F64];

    /// Its name in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Precision {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let wanted = s.trim().to_ascii_lowercase();
        (Self::ALL.into_iter())
            .find(|p| p.name() == wanted)
            .ok_or_else(|| format!("unknown precision `{s}`; choose one of: f32, f64"))
    }
}
