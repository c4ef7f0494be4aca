//! Wind: aerodynamic drag and lift on every triangle from its velocity relative to the air
//! and its normal, so a flag flutters instead of being pushed uniformly.

use glam::Vec3;

use crate::cloth::{ClothModel, ClothState, Real, Vector};
use crate::sim::forces::{Force, ForceTerm};
use crate::sim::kernels::{ElementForces, NOTHING};
use crate::sim::param_error::ParamError;
use crate::sim::params::Material;

use super::effect_kind::{ClothBox, EffectKind, GuardShare};

mod lanes;

/// Wind with gusts, and the cloth's aerodynamic coefficients.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Wind {
    /// Steady wind velocity, m/s.
    pub velocity: Vec3,
    /// Gust strength: the fraction of the steady speed gusts add and take away (0 steady).
    pub gust: f32,
    /// Typical period of a gust, seconds. Gusts travel with the wind.
    pub gust_period: f32,
    /// Drag coefficient of a face across the flow (dimensionless, ~1 for cloth).
    pub drag: f32,
    /// Lift coefficient (dimensionless): the force across the flow on a tilted face.
    pub lift: f32,
    /// Air density, kg/m³.
    pub air_density: f32,
}

impl Default for Wind {
    fn default() -> Self {
        Self {
            velocity: Vec3::new(4.0, 0.0, 0.0),
            gust: 0.5,
            gust_period: 1.5,
            drag: 1.0,
            lift: 0.6,
            air_density: 1.2,
        }
    }
}

/// The gusts' strength: three incommensurate tones (no visible period, smooth, in
/// [−1, 1]), each its period as a share of the gust period, its phase (rad) and its weight.
/// The air's velocity in lanes (`wind/lanes.rs`) reads these too; the GPU's
/// `shaders/elements.wgsl` writes them out (held to the CPU's forces by its tests).
const TONES: [[f32; 3]; 3] = [[1.0, 0.0, 0.5], [0.61, 1.3, 0.3], [0.37, 2.1, 0.2]];

/// The gusts' veer about the vertical: its tone's period share and phase, and its
/// amplitude (rad for a gust of 1).
const VEER: [f32; 3] = [0.83, 0.7, 0.25];

impl Wind {
    /// Steady speed, m/s.
    pub fn speed(&self) -> f32 {
        self.velocity.length()
    }

    /// Fastest the air gets, m/s (steady speed plus the strongest gust).
    pub fn peak_speed(&self) -> f32 {
        self.speed() * (1.0 + self.gust.abs())
    }

    /// The air's velocity at `x` at time `t`, m/s: the steady wind scaled by a gust factor
    /// that travels with it, and turned a little about the vertical by the same gusts.
    pub fn air_velocity<R: Real>(&self, x: R::V3, t: f64) -> R::V3 {
        let speed = self.speed();
        if speed == 0.0 || self.gust == 0.0 {
            return R::v3(self.velocity);
        }
        let c = R::of_f32;
        let along = R::v3(self.velocity / speed);
        let speed = c(speed);
        // Time at which this bit of air passed the origin: gusts are frozen in the flow.
        let s = R::of_f64(t) - x.dot(along) / speed;
        let p = self.gust_period.max(1e-3);
        let tau = c(std::f32::consts::TAU);
        let tone = |[share, phase, weight]: [f32; 3]| {
            (tau * s / c(share * p) + c(phase)).sin() * c(weight)
        };
        let strength = tone(TONES[0]) + tone(TONES[1]) + tone(TONES[2]);
        let veer = tone(VEER) * c(self.gust);
        let (sin, cos) = veer.sin_cos();
        let turned = R::V3::new(
            cos * along.x() + sin * along.z(),
            along.y(),
            -sin * along.x() + cos * along.z(),
        );
        turned * speed * (R::ONE + c(self.gust) * strength)
    }
}

/// The wind as a force term: its parameters, and where the cloth has enough triangles to
/// share them with the team, each particle's triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct WindForce {
    wind: Wind,
    shared: Option<ElementForces<3>>,
}

impl WindForce {
    /// `wind` on the triangles of `model`.
    pub fn new(wind: Wind, model: &ClothModel) -> Self {
        let particles = model.rest_positions.len();
        let shared = ElementForces::new(&model.triangles, particles);
        Self { wind, shared }
    }
}

impl<R: Real> ForceTerm<R> for WindForce {
    /// Adds each triangle's drag and lift (N), a third to each corner, at time `t` (in
    /// `f32` eight triangles at a time, `wind/lanes.rs`, and from
    /// [`crate::parallel::PARALLEL_ELEMENTS`] triangles on shared with the team: the same
    /// bits).
    fn add_forces(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        t: f64,
        f: &mut [R::V3],
    ) {
        let (wind, triangles) = (&self.wind, &model.triangles[..]);
        let (Some(pos), Some(vel), Some(f)) =
            (R::f32_slice(pos), R::f32_slice(vel), R::f32_slice_mut(f))
        else {
            return wind.add_forces_one_by_one::<R>(model, pos, vel, t, f);
        };
        let Some(shared) = self.shared.as_ref().filter(|s| s.pays()) else {
            return wind.each_share(triangles, [pos, vel], t, |first, shares, adds| {
                for (k, share) in shares.iter().enumerate() {
                    if adds & (1 << k) != 0 {
                        for &i in &triangles[first + k] {
                            f[i as usize] += *share;
                        }
                    }
                }
            });
        };
        shared.add_shared(f, |range, slots| {
            let base = range.start;
            wind.each_share(&triangles[range], [pos, vel], t, |first, shares, adds| {
                for (k, &share) in shares.iter().enumerate() {
                    let share = if adds & (1 << k) != 0 { share } else { NOTHING };
                    slots.set(base + first + k, [share; 3]);
                }
            });
        });
    }
}

impl Wind {
    /// The wind's forces a triangle at a time, in either precision.
    fn add_forces_one_by_one<R: Real>(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        t: f64,
        f: &mut [R::V3],
    ) {
        let k = R::of_f32;
        let half_rho = k(0.5 * self.air_density);
        let (third, half) = (k(3.0), k(0.5));
        for tri in &model.triangles {
            let [a, b, c] = tri.map(|i| i as usize);
            let normal = (pos[b] - pos[a]).cross(pos[c] - pos[a]);
            let twice_area = normal.length();
            if twice_area <= k(1e-12) {
                continue;
            }
            let n = normal / twice_area;
            let centre = (pos[a] + pos[b] + pos[c]) / third;
            let air = self.air_velocity::<R>(centre, t);
            let relative = (vel[a] + vel[b] + vel[c]) / third - air;
            let speed = relative.length();
            if speed <= k(1e-6) {
                continue;
            }
            let flow = relative / speed;
            let facing = flow.dot(n);
            let area = half * twice_area;
            // Drag: pressure on the face, from the flow's component across it.
            let drag = n * (-half_rho * k(self.drag) * area * speed * speed * facing);
            // Lift: across the flow, largest at 45°; unchanged if the normal flips.
            let across = n - flow * facing;
            let lift = across * (-half_rho * k(self.lift) * area * speed * speed * facing);
            let share = (drag + lift) / third;
            f[a] += share;
            f[b] += share;
            f[c] += share;
        }
    }
}

impl EffectKind for Wind {
    const NAME: &'static str = "wind";
    const TITLE: &'static str = "Wind";
    const MANY: bool = false;
    const ADDABLE: bool = true;

    fn check(&self) -> Result<(), ParamError> {
        // Thirty times the speed of sound; at 1e30 m/s its drag left what `f32` holds.
        ParamError::require(
            self.velocity.is_finite() && self.velocity.length() <= 1e4,
            "velocity",
            self.velocity,
            "must be at most 1e4 m/s",
        )?;
        ParamError::require(
            self.gust_period.is_finite() && self.gust_period > 0.0,
            "gust_period",
            self.gust_period,
            "must be > 0 s",
        )?;
        for (key, value) in [
            ("gust", self.gust),
            ("drag", self.drag),
            ("lift", self.lift),
            ("air_density", self.air_density),
        ] {
            ParamError::require(value.is_finite(), key, value, "must be finite")?;
        }
        Ok(())
    }

    fn force<R: Real>(
        &self,
        model: &ClothModel,
        _material: &Material,
        _kept: &[Force<R>],
    ) -> Option<Force<R>> {
        Some(Force::of(Self::NAME, WindForce::new(*self, model)))
    }

    fn guard(&self, _up: Vec3, _cloth: &ClothState) -> GuardShare {
        GuardShare {
            flow_speed: self.peak_speed(),
            ..GuardShare::default()
        }
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    fn suggested(_cloth: &ClothBox) -> Self {
        Self::default()
    }
}
