//! Simulation parameters, in SI units, with the defaults the scenarios start from.

use super::guard_policy::GuardPolicy;
use super::integrator::IntegratorKind;
use super::param_error::ParamError;

/// Every tunable number of the solver. Units are SI; each field says how it affects
/// stability.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimParams {
    /// Frame time step, seconds (default 1/60). The physics always advances in fixed steps of
    /// `dt / substeps`, never by the wall-clock frame time.
    pub dt: f32,
    /// Substeps per frame (default 48; the default cloth is stable from about 40). Explicit integrators are stable while
    /// `ω_max · dt/substeps ≲ 2`, with `ω_max ≈ 2·√(k/m)` for the stiffest spring; raise this
    /// when stiffening the cloth or lightening it.
    pub substeps: u32,
    pub integrator: IntegratorKind,
    /// Spring stiffness per kind `[structural, shear, bend]`, N/m. Higher is stiffer and needs
    /// more substeps.
    pub stiffness: [f32; 3],
    /// Spring damping per kind along the spring, N·s/m. Damps stretching oscillations;
    /// excessive values also limit the stable step.
    pub damping: [f32; 3],
    /// Areal density of the cloth, kg/m² (default 0.2, a light cotton). Changing it rebuilds
    /// the masses.
    pub density: f32,
    /// Collision thickness, metres: particles are kept this far outside collider surfaces.
    pub collision_offset: f32,
    /// What the stability guard checks and may do.
    #[serde(default)]
    pub guard: GuardPolicy,
    /// How the integrators that solve something solve it.
    #[serde(default)]
    pub solver: SolverConfig,
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
}

impl Default for SolverConfig {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            max_iterations: 200,
            newton_iterations: 1,
            newton_tolerance: 1e-3,
            xpbd_iterations: 1,
        }
    }
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            dt: 1.0 / 60.0,
            substeps: 48,
            integrator: IntegratorKind::SemiImplicitEuler,
            stiffness: [400.0, 150.0, 20.0],
            damping: [0.02, 0.01, 0.002],
            density: 0.2,
            collision_offset: 0.01,
            guard: GuardPolicy::default(),
            solver: SolverConfig::default(),
        }
    }
}

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
                self.dt,
                self.dt > 0.0 && self.dt <= 1.0,
                "0 < dt ≤ 1 s",
            ),
            ("density", self.density, self.density > 0.0, "> 0 kg/m²"),
            (
                "collision_offset",
                self.collision_offset,
                self.collision_offset >= 0.0,
                "≥ 0 m",
            ),
        ];
        for (name, value, ok, allowed) in checks {
            if !(value.is_finite() && ok) {
                return Err(ParamError::new(
                    name,
                    value,
                    format!("is out of range ({allowed})"),
                ));
            }
        }
        for (name, values, unit) in [
            ("stiffness", self.stiffness, "N/m"),
            ("damping", self.damping, "N·s/m"),
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
        if !(solver.tolerance.is_finite() && solver.tolerance > 0.0 && solver.tolerance < 1.0) {
            return Err(ParamError::new(
                "solver.tolerance",
                solver.tolerance,
                "is out of range (0 < tolerance < 1)",
            ));
        }
        for (name, value) in [
            ("solver.max_iterations", solver.max_iterations),
            ("solver.newton_iterations", solver.newton_iterations),
            ("solver.xpbd_iterations", solver.xpbd_iterations),
        ] {
            if !(1..=10_000).contains(&value) {
                return Err(ParamError::new(name, value, "must be in 1..=10000"));
            }
        }
        if !(solver.newton_tolerance.is_finite() && solver.newton_tolerance > 0.0) {
            return Err(ParamError::new(
                "solver.newton_tolerance",
                solver.newton_tolerance,
                "must be > 0",
            ));
        }
        if self.substeps == 0 || self.substeps > 100_000 {
            return Err(ParamError::new(
                "substeps",
                self.substeps,
                "must be in 1..=100000",
            ));
        }
        Ok(())
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
        let cases: [(&str, Spoil); 6] = [
            ("dt", |p| p.dt = 0.0),
            ("dt", |p| p.dt = f32::NAN),
            ("substeps", |p| p.substeps = 0),
            ("stiffness", |p| p.stiffness[1] = -1.0),
            ("damping", |p| p.damping[2] = f32::NAN),
            ("density", |p| p.density = 0.0),
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
}
