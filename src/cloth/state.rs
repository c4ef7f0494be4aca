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

    /// Largest particle speed, m/s (infinite only for a velocity that is not finite, or a
    /// speed past what an `f32` holds).
    pub fn max_speed(&self) -> f32 {
        let fastest = (self.vel.iter())
            .map(|v| in_range(v, v.length(), |d| d.length()))
            .fold(0.0, f64::max);
        fastest as f32
    }

    /// Kinetic energy ½Σmv², joules (accumulated in f64).
    pub fn kinetic_energy(&self, model: &ClothModel) -> f64 {
        self.vel
            .iter()
            .zip(&model.mass)
            .map(|(v, &m)| 0.5 * m as f64 * in_range(v, v.length_squared(), |d| d.length_squared()))
            .sum()
    }
}

/// `measured` (a measure of `v` in `R`, exact in f64), or, where it overflowed `R` though
/// `v` is finite (a speed past 1.8·10¹⁹ m/s squares past `f32`'s range), the same measure
/// `again` in f64: so a finite state never reads as an infinite speed or energy.
fn in_range<R: Real>(v: &R::V3, measured: R, again: impl Fn(glam::DVec3) -> f64) -> f64 {
    let measured = measured.to_f64();
    if measured.is_finite() || !v.is_finite() {
        measured
    } else {
        again(R::v3_f64(*v))
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

    /// A finite velocity whose square overflows `f32` (a cloth under an absurd gravity of
    /// 10³⁰ m/s² after half a second) reads as its speed, not infinity: the summary once
    /// printed "finite true, max speed inf"; and a velocity that is not finite still
    /// reads as infinite.
    #[test]
    fn a_finite_speed_past_what_its_square_holds_reads_finite() {
        let mut state = ClothState::<f32> {
            pos: vec![Vec3::ZERO; 2],
            vel: vec![Vec3::new(3e19, -4e19, 0.0), Vec3::X],
            time: 0.0,
        };
        assert!(state.is_finite());
        assert_eq!(state.max_speed(), 5e19);
        let mesh = crate::mesh::GridSpec::square(
            1,
            1.0,
            crate::mesh::GridOrientation::Horizontal,
            Vec3::ZERO,
        )
        .build()
        .unwrap();
        let model = ClothModel::new(&mesh, 0.2, &[]);
        let m = f64::from(model.mass[0]);
        let energy = state.kinetic_energy(&model);
        let expected = 0.5 * m * 25e38 + 0.5 * f64::from(model.mass[1]);
        assert!(
            (energy / expected - 1.0).abs() < 1e-6,
            "{energy} against {expected}"
        );
        state.vel[1] = Vec3::new(f32::INFINITY, 0.0, 0.0);
        assert_eq!(state.max_speed(), f32::INFINITY);
    }

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
