//! The dynamic part of a cloth: what changes every step.

use glam::Vec3;

use super::model::ClothModel;
use super::real::{Real, Vector};

/// Positions and velocities at a simulated time, in precision `R` (`f32` unless a run asks
/// for `f64`). Reset is a copy of the initial state.
#[derive(Debug, PartialEq)]
pub struct ClothState<R: Real = f32> {
    /// Metres.
    pub pos: Vec<R::V3>,
    /// Metres per second.
    pub vel: Vec<R::V3>,
    /// Simulated time, seconds.
    pub time: f64,
}

impl<R: Real> Default for ClothState<R> {
    fn default() -> Self {
        Self {
            pos: Vec::new(),
            vel: Vec::new(),
            time: 0.0,
        }
    }
}

/// `clone_from` reuses the buffers (the stepper copies states every frame: frame start,
/// rollback points); a derived `Clone` would allocate new ones each time.
impl<R: Real> Clone for ClothState<R> {
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
}

impl<R: Real> ClothState<R> {
    /// `state` in this precision: exact from `f32`; rounded to the nearest from `f64`.
    pub fn of<S: Real>(state: &ClothState<S>) -> Self {
        let mut out = Self::default();
        out.take(state);
        out
    }

    /// Sets this state to `state`, converted as [`ClothState::of`], into the buffers it has.
    pub fn take<S: Real>(&mut self, state: &ClothState<S>) {
        let convert = |v: &S::V3| R::v3_of(S::v3_f64(*v));
        self.pos.clear();
        self.pos.extend(state.pos.iter().map(convert));
        self.vel.clear();
        self.vel.extend(state.vel.iter().map(convert));
        self.time = state.time;
    }

    /// True when every position and velocity is finite.
    pub fn is_finite(&self) -> bool {
        self.pos.iter().chain(&self.vel).all(|v| v.is_finite())
    }

    /// Largest particle speed, m/s.
    pub fn max_speed(&self) -> f32 {
        let fastest = self.vel.iter().map(|v| v.length()).fold(R::ZERO, R::max);
        fastest.to_f32()
    }

    /// Kinetic energy ½Σmv², joules (accumulated in f64).
    pub fn kinetic_energy(&self, model: &ClothModel) -> f64 {
        self.vel
            .iter()
            .zip(&model.mass)
            .map(|(v, &m)| 0.5 * m as f64 * v.length_squared().to_f64())
            .sum()
    }
}

impl ClothState {
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
        let source = ClothState::<f32> {
            pos: vec![Vec3::X, Vec3::Y],
            vel: vec![Vec3::Z, Vec3::ONE],
            time: 2.5,
        };
        let mut copy = ClothState::<f32> {
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
