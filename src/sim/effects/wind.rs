//! Wind: aerodynamic drag and lift on every triangle from its velocity relative to the air
//! and its normal, so a flag flutters instead of being pushed uniformly.

use glam::Vec3;

use crate::cloth::ClothModel;
use crate::sim::forces::{Force, ForceTerm};
use crate::sim::param_error::ParamError;
use crate::sim::params::Material;

use super::effect_kind::{ClothBox, EffectKind, GuardShare};

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
    pub fn air_velocity(&self, x: Vec3, t: f64) -> Vec3 {
        let speed = self.speed();
        if speed == 0.0 || self.gust == 0.0 {
            return self.velocity;
        }
        let along = self.velocity / speed;
        // Time at which this bit of air passed the origin: gusts are frozen in the flow.
        let s = t as f32 - x.dot(along) / speed;
        let p = self.gust_period.max(1e-3);
        let tau = std::f32::consts::TAU;
        // Three incommensurate tones: no visible period, smooth, in [−1, 1].
        let strength = (tau * s / p).sin() * 0.5
            + (tau * s / (0.61 * p) + 1.3).sin() * 0.3
            + (tau * s / (0.37 * p) + 2.1).sin() * 0.2;
        let veer = (tau * s / (0.83 * p) + 0.7).sin() * 0.25 * self.gust;
        let (sin, cos) = veer.sin_cos();
        let turned = Vec3::new(
            cos * along.x + sin * along.z,
            along.y,
            -sin * along.x + cos * along.z,
        );
        turned * speed * (1.0 + self.gust * strength)
    }
}

impl ForceTerm for Wind {
    /// Adds each triangle's drag and lift (N), a third to each corner, at time `t`.
    fn add_forces(&self, model: &ClothModel, pos: &[Vec3], vel: &[Vec3], t: f64, f: &mut [Vec3]) {
        let half_rho = 0.5 * self.air_density;
        for tri in &model.triangles {
            let [a, b, c] = tri.map(|i| i as usize);
            let normal = (pos[b] - pos[a]).cross(pos[c] - pos[a]);
            let twice_area = normal.length();
            if twice_area <= 1e-12 {
                continue;
            }
            let n = normal / twice_area;
            let centre = (pos[a] + pos[b] + pos[c]) / 3.0;
            let relative = (vel[a] + vel[b] + vel[c]) / 3.0 - self.air_velocity(centre, t);
            let speed = relative.length();
            if speed <= 1e-6 {
                continue;
            }
            let flow = relative / speed;
            let facing = flow.dot(n);
            let area = 0.5 * twice_area;
            // Drag: pressure on the face, from the flow's component across it.
            let drag = (-half_rho * self.drag * area * speed * speed * facing) * n;
            // Lift: across the flow, largest at 45°; unchanged if the normal flips.
            let across = n - facing * flow;
            let lift = (-half_rho * self.lift * area * speed * speed * facing) * across;
            let share = (drag + lift) / 3.0;
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
        ParamError::require(
            self.velocity.is_finite(),
            "velocity",
            self.velocity,
            "must be finite m/s",
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

    fn force(&self, _model: &ClothModel, _material: &Material, _kept: &[Force]) -> Option<Force> {
        Some(Force::new(Self::NAME, *self))
    }

    fn guard(&self, _up: Vec3) -> GuardShare {
        GuardShare {
            flow_speed: self.peak_speed(),
            ..GuardShare::default()
        }
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Err("wind")
    }

    fn suggested(_cloth: &ClothBox) -> Self {
        Self::default()
    }
}
