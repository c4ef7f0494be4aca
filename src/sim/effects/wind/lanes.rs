//! The wind's forces eight triangles at a time (`f32` only): each triangle's corners and
//! their velocities are gathered into SIMD lanes, its drag and lift taken lane by lane, and
//! its three shares added back triangle by triangle in the model's order. The lanes do the
//! scalar path's IEEE operations in its order and take the gusts' sines lane by lane from
//! `f32::sin`, so the forces are the scalar path's to the bit (see the test below).

use glam::Vec3;
use wide::f32x8;

use super::Wind;

/// Triangles a chunk holds: the lanes of an `f32x8`.
const LANES: usize = 8;

/// Eight vectors, one a lane.
#[derive(Clone, Copy)]
struct Lanes3 {
    x: f32x8,
    y: f32x8,
    z: f32x8,
}

impl Lanes3 {
    fn splat(v: Vec3) -> Lanes3 {
        Lanes3 {
            x: f32x8::splat(v.x),
            y: f32x8::splat(v.y),
            z: f32x8::splat(v.z),
        }
    }

    fn gather(of: &[Vec3], triangles: &[[u32; 3]], corner: usize) -> Lanes3 {
        let [mut x, mut y, mut z] = [[0.0f32; LANES]; 3];
        for (lane, t) in triangles.iter().enumerate() {
            let p = of[t[corner] as usize];
            (x[lane], y[lane], z[lane]) = (p.x, p.y, p.z);
        }
        Lanes3 {
            x: x.into(),
            y: y.into(),
            z: z.into(),
        }
    }

    fn add(self, o: Lanes3) -> Lanes3 {
        Lanes3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    fn sub(self, o: Lanes3) -> Lanes3 {
        Lanes3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    fn scale(self, s: f32x8) -> Lanes3 {
        Lanes3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    fn div(self, s: f32x8) -> Lanes3 {
        Lanes3 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }

    /// As `glam::Vec3::cross`.
    fn cross(self, o: Lanes3) -> Lanes3 {
        Lanes3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// As `glam::Vec3::dot`.
    fn dot(self, o: Lanes3) -> f32x8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// The eight vectors, one a lane.
    fn unpack(self) -> [Vec3; LANES] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|lane| Vec3::new(x[lane], y[lane], z[lane]))
    }
}

/// The sine of each lane, as `f32::sin` gives it (a lane's own arithmetic costs less
/// than a whole vector's: the gusts need sines alone, the lanes' kernel makes cosines too).
fn sin(x: f32x8) -> f32x8 {
    let x = x.to_array();
    f32x8::from(std::array::from_fn::<f32, LANES, _>(|lane| x[lane].sin()))
}

/// The sine and the cosine of each lane, as `f32::sin_cos` gives them.
fn sin_cos(x: f32x8) -> (f32x8, f32x8) {
    let both = x.to_array().map(f32::sin_cos);
    (both.map(|(s, _)| s).into(), both.map(|(_, c)| c).into())
}

impl Wind {
    /// [`Wind::air_velocity`] at eight points.
    fn air_lanes(&self, x: Lanes3, t: f64) -> Lanes3 {
        let speed = self.speed();
        if speed == 0.0 || self.gust == 0.0 {
            return Lanes3::splat(self.velocity);
        }
        let c = f32x8::splat;
        let along = self.velocity / speed;
        let s = c(t as f32) - x.dot(Lanes3::splat(along)) / c(speed);
        let p = self.gust_period.max(1e-3);
        let tau = c(std::f32::consts::TAU);
        let strength = sin(tau * s / c(p)) * c(0.5)
            + sin(tau * s / c(0.61 * p) + c(1.3)) * c(0.3)
            + sin(tau * s / c(0.37 * p) + c(2.1)) * c(0.2);
        let veer = sin(tau * s / c(0.83 * p) + c(0.7)) * c(0.25) * c(self.gust);
        let (sin, cos) = sin_cos(veer);
        let along3 = Lanes3::splat(along);
        let turned = Lanes3 {
            x: cos * along3.x + sin * along3.z,
            y: along3.y,
            z: -sin * along3.x + cos * along3.z,
        };
        turned
            .scale(c(speed))
            .scale(c(1.0) + c(self.gust) * strength)
    }

    /// Each triangle's drag and lift (N) at time `t`, a third of it, the share each of its
    /// corners takes: what the one-at-a-time path adds, eight triangles at a time, handed to
    /// `shares(first, shares, adds)` a chunk at a time in the triangles' order: `first` the
    /// chunk's first triangle, bit `k` of `adds` clear where its `k`-th adds nothing
    /// (degenerate, or moving with the air).
    pub(super) fn each_share(
        &self,
        triangles: &[[u32; 3]],
        [pos, vel]: [&[Vec3]; 2],
        t: f64,
        mut shares: impl FnMut(usize, &[Vec3], u32),
    ) {
        let c = f32x8::splat;
        let half_rho = c(0.5 * self.air_density);
        let (third, half) = (c(3.0), c(0.5));
        for (chunk, triangles) in triangles.chunks(LANES).enumerate() {
            let [a, b, cc] = [0, 1, 2].map(|k| Lanes3::gather(pos, triangles, k));
            let [va, vb, vc] = [0, 1, 2].map(|k| Lanes3::gather(vel, triangles, k));
            let normal = b.sub(a).cross(cc.sub(a));
            let twice_area = normal.dot(normal).sqrt();
            let n = normal.div(twice_area);
            let centre = a.add(b).add(cc).div(third);
            let air = self.air_lanes(centre, t);
            let relative = va.add(vb).add(vc).div(third).sub(air);
            let speed = relative.dot(relative).sqrt();
            let flow = relative.div(speed);
            let facing = flow.dot(n);
            let area = half * twice_area;
            let drag = n.scale(-half_rho * c(self.drag) * area * speed * speed * facing);
            let across = n.sub(flow.scale(facing));
            let lift = across.scale(-half_rho * c(self.lift) * area * speed * speed * facing);
            // Lanes past the last triangle hold zeros: a degenerate triangle.
            let skip = (twice_area.simd_le(c(1e-12)) | speed.simd_le(c(1e-6))).to_bitmask();
            let all = drag.add(lift).div(third).unpack();
            shares(chunk * LANES, &all[..triangles.len()], !skip);
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::cloth::ClothModel;
    use crate::mesh::{GridOrientation, GridSpec};
    use crate::sim::effects::wind::WindForce;
    use crate::sim::forces::ForceTerm;

    /// A 7 × 5-quad flag (70 triangles: the last chunk holds six) at jittered places and
    /// speeds, with one triangle folded flat (degenerate) and, in a steady wind, one moving
    /// with the air: eight triangles at a time push every particle as one at a time does,
    /// to the bit, in a gusting wind and a steady one, early and an hour in.
    #[test]
    fn eight_triangles_at_a_time_push_as_one_at_a_time() {
        let mesh = GridSpec {
            quads_x: 7,
            quads_y: 5,
            size_x: 0.7,
            size_y: 0.5,
            orientation: GridOrientation::Vertical,
            center: Vec3::ZERO,
        }
        .build()
        .unwrap();
        let model = ClothModel::new(&mesh, 0.2, &[]);
        assert!(!model.triangles.len().is_multiple_of(LANES));
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut jitter = |scale: f32| {
            let mut unit = || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
            };
            Vec3::new(unit(), unit(), unit()) * scale
        };
        let mut pos: Vec<Vec3> = (model.rest_positions.iter())
            .map(|&p| p + jitter(0.03))
            .collect();
        let mut vel: Vec<Vec3> = (0..pos.len()).map(|_| jitter(3.0)).collect();
        let [a, b, c] = model.triangles[9].map(|i| i as usize);
        pos[c] = pos[a];
        let gusting = Wind::default();
        let steady = Wind {
            gust: 0.0,
            ..gusting
        };
        for &i in &model.triangles[30] {
            vel[i as usize] = steady.velocity;
        }
        for (wind, t) in [(gusting, 0.25), (gusting, 3600.0), (steady, 1.0)] {
            let (mut lanes, mut one) = (vec![Vec3::ZERO; pos.len()], vec![Vec3::ZERO; pos.len()]);
            ForceTerm::<f32>::add_forces(
                &WindForce::new(wind, &model),
                &model,
                &pos,
                &vel,
                t,
                &mut lanes,
            );
            wind.add_forces_one_by_one::<f32>(&model, &pos, &vel, t, &mut one);
            assert_eq!(lanes, one, "t = {t} s");
            assert!(lanes.iter().all(|f| f.is_finite()) && lanes[b] != Vec3::ZERO);
        }
    }

    /// A 64 × 64-quad cloth (8 192 triangles: shared with the team from 4 096) at jittered
    /// places and speeds, with a triangle folded flat and, in a steady wind, one moving with
    /// the air: the wind pushes every particle to the same bits on teams of one, two and
    /// three, and as one triangle at a time does, call after call with the wind changed
    /// between (a slot left unwritten by a triangle that adds nothing would keep the last
    /// call's share).
    #[test]
    fn shared_with_the_team_the_wind_pushes_as_on_one_thread() {
        let mesh = GridSpec::square(64, 1.0, GridOrientation::Vertical, Vec3::ZERO)
            .build()
            .unwrap();
        let model = ClothModel::new(&mesh, 0.2, &[]);
        assert!(model.triangles.len() >= crate::parallel::PARALLEL_ELEMENTS);
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut jitter = |scale: f32| {
            let mut unit = || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
            };
            Vec3::new(unit(), unit(), unit()) * scale
        };
        let mut pos: Vec<Vec3> = (model.rest_positions.iter())
            .map(|&p| p + jitter(0.005))
            .collect();
        let mut vel: Vec<Vec3> = (0..pos.len()).map(|_| jitter(3.0)).collect();
        let [a, _, c] = model.triangles[100].map(|i| i as usize);
        pos[c] = pos[a];
        let gusting = Wind::default();
        let steady = Wind {
            gust: 0.0,
            ..gusting
        };
        for &i in &model.triangles[5000] {
            vel[i as usize] = steady.velocity;
        }
        let push = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let (mut gusting_f, mut steady_f) =
                    (vec![Vec3::ONE; pos.len()], vec![Vec3::ONE; pos.len()]);
                let term = WindForce::new(gusting, &model);
                ForceTerm::<f32>::add_forces(&term, &model, &pos, &vel, 2.0, &mut gusting_f);
                let mut term = term;
                term.wind = steady;
                ForceTerm::<f32>::add_forces(&term, &model, &pos, &vel, 2.0, &mut steady_f);
                [gusting_f, steady_f]
            })
        };
        let mut one = [vec![Vec3::ONE; pos.len()], vec![Vec3::ONE; pos.len()]];
        for (wind, f) in [gusting, steady].iter().zip(&mut one) {
            wind.add_forces_one_by_one::<f32>(&model, &pos, &vel, 2.0, f);
        }
        for threads in [1, 2, 3] {
            assert!(push(threads) == one, "{threads} threads");
        }
    }
}
