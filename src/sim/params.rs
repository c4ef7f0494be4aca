//! Simulation parameters, in SI units, with the defaults the scenarios start from.

use super::guard_policy::GuardPolicy;
use super::integrator::IntegratorKind;
use super::param_error::ParamError;
use super::precision::Precision;

/// Every tunable number of the solver, by concern: each subsystem takes its own part. Units
/// are SI; each field says how it affects stability.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimParams {
    /// Frame length, substeps and integrator.
    pub step: StepConfig,
    /// The cloth's springs and mass.
    pub material: Material,
    /// How contacts with solids are kept.
    pub contact: ContactConfig,
    /// What the stability guard checks and may do.
    #[serde(default)]
    pub guard: GuardPolicy,
    /// How the integrators that solve something solve it.
    #[serde(default)]
    pub solver: SolverConfig,
}

/// How a frame is stepped.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepConfig {
    /// Frame time step, seconds (default 1/60). The physics always advances in fixed steps of
    /// `dt / substeps`, never by the wall-clock frame time.
    pub dt: f32,
    /// Substeps per frame (default 48; the default cloth is stable from about 40). Explicit
    /// integrators are stable while `ω_max · dt/substeps ≲ 2`, with `ω_max ≈ 2·√(k/m)` for the
    /// stiffest spring; raise this when stiffening the cloth or lightening it.
    pub substeps: u32,
    pub integrator: IntegratorKind,
}

impl Default for StepConfig {
    fn default() -> Self {
        Self {
            dt: 1.0 / 60.0,
            substeps: 48,
            integrator: IntegratorKind::SemiImplicitEuler,
        }
    }
}

impl StepConfig {
    /// Length of one substep, seconds.
    pub fn substep_length(&self) -> f32 {
        self.dt / self.substeps.max(1) as f32
    }
}

/// The cloth's material: its springs' strengths and its mass.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    /// Spring stiffness per kind `[structural, shear, bend]`, N/m. Higher is stiffer and needs
    /// more substeps.
    pub stiffness: [f32; 3],
    /// Spring damping per kind along the spring, N·s/m. Damps stretching oscillations;
    /// excessive values also limit the stable step.
    pub damping: [f32; 3],
    /// Areal density of the cloth, kg/m² (default 0.2, a light cotton). Changing it rebuilds
    /// the masses.
    pub density: f32,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            stiffness: [400.0, 150.0, 20.0],
            damping: [0.02, 0.01, 0.002],
            density: 0.2,
        }
    }
}

/// How contacts with solids are kept.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactConfig {
    /// Collision thickness, metres: particles are kept this far outside solids' surfaces
    /// (`collision_offset` in scene files).
    pub offset: f32,
}

impl Default for ContactConfig {
    fn default() -> Self {
        Self { offset: 0.01 }
    }
}

bitflags::bitflags! {
    /// What a new configuration changed, so that each subsystem redoes only what depends on
    /// it: a stiffness slider retunes the springs in place and rebuilds nothing.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub struct Changes: u16 {
        /// The frame length.
        const DT = 1;
        /// The requested substeps per frame.
        const SUBSTEPS = 1 << 1;
        /// Which integrator.
        const INTEGRATOR = 1 << 2;
        /// Spring stiffness or damping.
        const STRENGTHS = 1 << 3;
        /// The areal density (the masses).
        const DENSITY = 1 << 4;
        /// The collision thickness against solids.
        const CONTACT = 1 << 5;
        /// The guard's policy.
        const GUARD = 1 << 6;
        /// The solvers' tolerances and caps.
        const SOLVER = 1 << 7;
        /// The effect list (an effect on or off, or its settings).
        const EFFECTS = 1 << 8;
        /// The precision the stepper computes in (a new stepper).
        const PRECISION = 1 << 9;
    }
}

impl SimParams {
    /// What going from `self` to `new` changes.
    pub fn changes_to(&self, new: &SimParams) -> Changes {
        let (a, b) = (self, new);
        let flags = [
            (Changes::DT, a.step.dt != b.step.dt),
            (Changes::SUBSTEPS, a.step.substeps != b.step.substeps),
            (Changes::INTEGRATOR, a.step.integrator != b.step.integrator),
            (
                Changes::STRENGTHS,
                (a.material.stiffness, a.material.damping)
                    != (b.material.stiffness, b.material.damping),
            ),
            (Changes::DENSITY, a.material.density != b.material.density),
            (Changes::CONTACT, a.contact != b.contact),
            (Changes::GUARD, a.guard != b.guard),
            (
                Changes::SOLVER,
                SolverConfig {
                    precision: b.solver.precision,
                    ..a.solver
                } != b.solver,
            ),
            (Changes::PRECISION, a.solver.precision != b.solver.precision),
        ];
        (flags.into_iter())
            .filter(|(_, changed)| *changed)
            .fold(Changes::empty(), |all, (flag, _)| all | flag)
    }
}

/// The configuration integrators take: linear-solver tolerance and caps.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SolverConfig {
    /// Conjugate gradients stop when the residual is this fraction of the right-hand
    /// side's norm (default 1e-3).
    pub tolerance: f32,
    /// Conjugate-gradient iteration cap per solve (default 200).
    pub max_iterations: u32,
    /// Newton iterations of implicit Euler per step (default 1: the linearised
    /// Baraff–Witkin step; more refine it towards the exact backward-Euler step).
    pub newton_iterations: u32,
    /// Newton stops when the backward-Euler residual is this fraction of `‖h·f‖`
    /// (default 1e-3).
    pub newton_tolerance: f32,
    /// Constraint sweeps per XPBD substep (default 1: small steps, one iteration).
    pub xpbd_iterations: u32,
    /// Descent sweeps per VBD substep (default 1: small steps, one iteration).
    pub vbd_iterations: u32,
    /// What the state, forces and integrators compute in (default `f32`).
    pub precision: Precision,
}

impl Default for SolverConfig {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            max_iterations: 200,
            newton_iterations: 1,
            newton_tolerance: 1e-3,
            xpbd_iterations: 1,
            vbd_iterations: 1,
            precision: Precision::F32,
        }
    }
}

/// The areal densities a cloth may have, kg/m²: from far lighter than any film to a plate
/// of lead a metre thick. Much lighter, the particles' masses leave what `f32` holds (at
/// 1e-38 a cloth hung in the air under gravity, and the run said nothing).
const DENSITY: std::ops::RangeInclusive<f32> = 1e-9..=1e5;

impl SimParams {
    /// Checks that every number is finite and in range.
    ///
    /// # Errors
    /// [`ParamError`] naming the parameter and the allowed range.
    pub fn validate(&self) -> Result<(), ParamError> {
        // `(name, value, allowed, what is allowed)`; NaN and infinities are never allowed.
        let checks = [
            (
                "dt",
                self.step.dt,
                self.step.dt > 0.0 && self.step.dt <= 1.0,
                "0 < dt ≤ 1 s",
            ),
            (
                "density",
                self.material.density,
                DENSITY.contains(&self.material.density),
                "1e-9 to 1e5 kg/m²",
            ),
            (
                "collision_offset",
                self.contact.offset,
                self.contact.offset >= 0.0,
                "≥ 0 m",
            ),
        ];
        for (name, value, ok, allowed) in checks {
            ParamError::require(
                value.is_finite() && ok,
                name,
                value,
                format!("is out of range ({allowed})"),
            )?;
        }
        for (name, values, unit) in [
            ("stiffness", self.material.stiffness, "N/m"),
            ("damping", self.material.damping, "N·s/m"),
        ] {
            if let Some(v) = values.into_iter().find(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(ParamError::new(
                    name,
                    v,
                    format!("is out of range (≥ 0 {unit})"),
                ));
            }
        }
        self.guard.validate()?;
        let solver = &self.solver;
        ParamError::require(
            solver.tolerance.is_finite() && solver.tolerance > 0.0 && solver.tolerance < 1.0,
            "solver.tolerance",
            solver.tolerance,
            "is out of range (0 < tolerance < 1)",
        )?;
        for (name, value) in [
            ("solver.max_iterations", solver.max_iterations),
            ("solver.newton_iterations", solver.newton_iterations),
            ("solver.xpbd_iterations", solver.xpbd_iterations),
            ("solver.vbd_iterations", solver.vbd_iterations),
        ] {
            ParamError::require(
                (1..=10_000).contains(&value),
                name,
                value,
                "must be in 1..=10000",
            )?;
        }
        ParamError::require(
            solver.newton_tolerance.is_finite() && solver.newton_tolerance > 0.0,
            "solver.newton_tolerance",
            solver.newton_tolerance,
            "must be > 0",
        )?;
        ParamError::require(
            (1..=100_000).contains(&self.step.substeps),
            "substeps",
            self.step.substeps,
            "must be in 1..=100000",
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        assert_eq!(SimParams::default().validate(), Ok(()));
    }

    #[test]
    fn each_bad_value_is_named() {
        type Spoil = fn(&mut SimParams);
        let cases: [(&str, Spoil); 7] = [
            ("dt", |p| p.step.dt = 0.0),
            ("dt", |p| p.step.dt = f32::NAN),
            ("substeps", |p| p.step.substeps = 0),
            ("stiffness", |p| p.material.stiffness[1] = -1.0),
            ("damping", |p| p.material.damping[2] = f32::NAN),
            ("density", |p| p.material.density = 0.0),
            ("density", |p| p.material.density = 1e-38),
        ];
        for (name, spoil) in cases {
            let mut p = SimParams::default();
            spoil(&mut p);
            let err = p.validate().expect_err(name);
            assert_eq!(err.name, name);
            assert!(
                err.to_string().contains(&format!("`{name}`")),
                "{name}: {err}"
            );
        }
    }

    /// Each setting is named by its own flag and no other; nothing changed is no flag.
    #[test]
    fn a_change_names_its_concern() {
        type Edit = fn(&mut SimParams);
        let cases: [(Changes, Edit); 12] = [
            (Changes::DT, |p| p.step.dt *= 2.0),
            (Changes::SUBSTEPS, |p| p.step.substeps += 1),
            (Changes::INTEGRATOR, |p| {
                p.step.integrator = IntegratorKind::ImplicitEuler;
            }),
            (Changes::STRENGTHS, |p| p.material.stiffness[2] += 1.0),
            (Changes::STRENGTHS, |p| p.material.damping[0] += 1.0),
            (Changes::DENSITY, |p| p.material.density += 0.1),
            (Changes::CONTACT, |p| p.contact.offset += 0.001),
            (Changes::GUARD, |p| p.guard.enabled = !p.guard.enabled),
            (Changes::SOLVER, |p| p.solver.tolerance *= 0.5),
            (Changes::SOLVER, |p| p.solver.xpbd_iterations += 1),
            (Changes::SOLVER, |p| p.solver.vbd_iterations += 1),
            (Changes::PRECISION, |p| p.solver.precision = Precision::F64),
        ];
        let before = SimParams::default();
        assert_eq!(before.changes_to(&before.clone()), Changes::empty());
        for (flag, edit) in cases {
            let mut after = before.clone();
            edit(&mut after);
            assert_eq!(before.changes_to(&after), flag, "{after:?}");
        }
    }
}
