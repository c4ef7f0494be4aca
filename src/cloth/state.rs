//! The dynamic part of a cloth: what changes every step.

use glam::Vec3;

use super::model::ClothModel;

/// Positions and velocities at a simulated time. Reset is a copy of the initial state.
#[derive(Debug, Default, PartialEq)]
pub struct ClothState {
    /// Metres.
    pub pos: Vec<Vec3>,
    /// Metres per second.
    pub vel: Vec<Vec3>,
    /// Simulated time, seconds.
    pub time: f64,
}

/// `clone_from` reuses the buffers (the stepper copies states every frame: frame start,
/// rollback points); a derived `Clone` would allocate new ones each time.
impl Clone for ClothState {
    fn clone(&self) -> Self {
        Self {
            pos: self.pos.clone(),
            vel: self.vel.clone(),
            time: self.time,
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.pos.clone_from(&source.pos);
        self.vel.clone_from(&source.vel);
        self.time = source.time;
    }
}

impl ClothState {
    /// The model's rest shape, at rest.
    pub fn at_rest(model: &ClothModel) -> Self {
        Self {
            pos: model.rest_positions.clone(),
            vel: vec![Vec3::ZERO; model.particle_count()],
            time: 0.0,
        }
    }

    /// True when every position and velocity is finite.
    pub fn is_finite(&self) -> bool {
        self.pos.iter().chain(&self.vel).all(|v| v.is_finite())
    }

    /// Largest particle speed, m/s.
    pub fn max_speed(&self) -> f32 {
        self.vel.iter().map(|v| v.length()).fold(0.0, f32::max)
    }

    /// Kinetic energy ½Σmv², joules (accumulated in f64).
    pub fn kinetic_energy(&self, model: &ClothModel) -> f64 {
        self.vel
            .iter()
            .zip(&model.mass)
            .map(|(v, &m)| 0.5 * m as f64 * v.length_squared() as f64)
            .sum()
    }

    /// Angular momentum about an axis through `origin` along unit `axis`, kg·m²/s.
    pub fn angular_momentum(&self, model: &ClothModel, origin: Vec3, axis: Vec3) -> f64 {
        self.pos
            .iter()
            .zip(&self.vel)
            .zip(&model.mass)
            .map(|((p, v), &m)| (m as f64) * ((*p - origin).cross(*v).dot(axis)) as f64)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clone_from_copies_into_the_existing_buffers() {
        let source = ClothState {
            pos: vec![Vec3::X, Vec3::Y],
            vel: vec![Vec3::Z, Vec3::ONE],
            time: 2.5,
        };
        let mut copy = ClothState {
            pos: Vec::with_capacity(8),
            vel: Vec::with_capacity(8),
            time: 0.0,
        };
        let (p, v) = (copy.pos.as_ptr(), copy.vel.as_ptr());
        copy.clone_from(&source);
        assert_eq!(copy, source);
        assert_eq!(
            (copy.pos.as_ptr(), copy.vel.as_ptr()),
            (p, v),
            "no new buffers"
        );
    }
}
