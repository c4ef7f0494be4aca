//! Forces, evaluated apart from any integrator: each one adds its acceleration to a buffer.

use glam::Vec3;

use crate::cloth::ClothModel;

/// One force field acting on the cloth. Each contributes acceleration (force × inverse mass),
/// so pinned particles (inverse mass 0) never accelerate.
#[derive(Clone, Debug, PartialEq)]
pub enum Force {
    /// Uniform gravity, m/s².
    Gravity(Vec3),
    /// Hookean springs with damping along the spring; per-kind stiffness (N/m) and damping
    /// (N·s/m) indexed by [`crate::mesh::SpringKind::index`].
    Springs {
        stiffness: [f32; 3],
        damping: [f32; 3],
    },
    /// Linear air damping, 1/s: `a = −c·v`.
    AirDamping(f32),
}

impl Force {
    /// Short name for timings and logs.
    pub fn name(&self) -> &'static str {
        match self {
            Force::Gravity(_) => "gravity",
            Force::Springs { .. } => "springs",
            Force::AirDamping(_) => "air damping",
        }
    }

    /// Adds this force's acceleration at state `(pos, vel)` to `acc`.
    pub fn accumulate(&self, model: &ClothModel, pos: &[Vec3], vel: &[Vec3], acc: &mut [Vec3]) {
        match *self {
            Force::Gravity(g) => {
                for (a, &w) in acc.iter_mut().zip(&model.inv_mass) {
                    if w > 0.0 {
                        *a += g;
                    }
                }
            }
            Force::AirDamping(c) => {
                for ((a, v), &w) in acc.iter_mut().zip(vel).zip(&model.inv_mass) {
                    if w > 0.0 {
                        *a -= c * *v;
                    }
                }
            }
            Force::Springs { stiffness, damping } => {
                let s = &model.springs;
                let w = &model.inv_mass;
                for i in 0..s.len() {
                    let (ia, ib) = (s.a[i] as usize, s.b[i] as usize);
                    let d = pos[ib] - pos[ia];
                    let len = d.length();
                    if len <= 1e-9 {
                        continue; // coincident ends: no defined direction
                    }
                    let n = d / len;
                    let kind = s.kind[i].index();
                    let f = stiffness[kind] * (len - s.rest[i])
                        + damping[kind] * (vel[ib] - vel[ia]).dot(n);
                    acc[ia] += (f * w[ia]) * n;
                    acc[ib] -= (f * w[ib]) * n;
                }
            }
        }
    }
}

/// The forces a scene uses, evaluated together. Only listed forces run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ForceSet {
    pub forces: Vec<Force>,
}

impl ForceSet {
    /// Writes the total acceleration at `(pos, vel)` into `acc` (resized to the particle count).
    pub fn acceleration(
        &self,
        model: &ClothModel,
        pos: &[Vec3],
        vel: &[Vec3],
        acc: &mut Vec<Vec3>,
    ) {
        acc.clear();
        acc.resize(pos.len(), Vec3::ZERO);
        for f in &self.forces {
            f.accumulate(model, pos, vel, acc);
        }
    }
}
