//! The wind's forces eight triangles at a time (`f32` only): each triangle's corners and
//! their velocities are gathered into SIMD lanes, its drag and lift taken lane by lane, and
//! its three shares added back triangle by triangle in the model's order. The lanes do the
//! scalar path's IEEE operations in its order and take the gusts' sines lane by lane from
//! `f32::sin`, so the forces are the scalar path's to the bit (see the test below).

use glam::Vec3;
use wide::f32x8;

use crate::sim::kernels::{LANES, Vec3x8};

use super::{TONES, VEER, Wind};

/// The sine of each lane, as `f32::sin` gives it: so the forces stay the one-at-a-time
/// path's bits (the lanes' own `f32x8::sin_cos` saved 4 % of the wind's time and lost them).
fn sin(x: f32x8) -> f32x8 {
    x.to_array().map(f32::sin).into()
}

/// The sine and the cosine of each lane, as `f32::sin_cos` gives them.
fn sin_cos(x: f32x8) -> (f32x8, f32x8) {
    let both = x.to_array().map(f32::sin_cos);
    (both.map(|(s, _)| s).into(), both.map(|(_, c)| c).into())
}

impl Wind {
    /// [`Wind::air_velocity`] at eight points.
    fn air_lanes(&self, x: Vec3x8, t: f64) -> Vec3x8 {
        let speed = self.speed();
        if speed == 0.0 || self.gust == 0.0 {
            return Vec3x8::splat(self.velocity);
        }
        let c = f32x8::splat;
        let along = Vec3x8::splat(self.velocity / speed);
        let s = c(t as f32) - x.dot(along) / c(speed);
        let p = self.gust_period.max(1e-3);
        let tau = c(std::f32::consts::TAU);
        let tone =
            |[share, phase, weight]: [f32; 3]| sin(tau * s / c(share * p) + c(phase)) * c(weight);
        let strength = tone(TONES[0]) + tone(TONES[1]) + tone(TONES[2]);
        let veer = tone(VEER) * c(self.gust);
        let (sin, cos) = sin_cos(veer);
        let turned = Vec3x8 {
            x: cos * along.x + sin * along.z,
            y: along.y,
            z: -sin * along.x + cos * along.z,
        };
        turned * c(speed) * (c(1.0) + c(self.gust) * strength)
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
            let [a, b, cc] = [0, 1, 2].map(|k| Vec3x8::gather(pos, triangles, k));
            let [va, vb, vc] = [0, 1, 2].map(|k| Vec3x8::gather(vel, triangles, k));
            let normal = (b - a).cross(cc - a);
            let twice_area = normal.dot(normal).sqrt();
            let n = normal / twice_area;
            let centre = (a + b + cc) / third;
            let air = self.air_lanes(centre, t);
            let relative = (va + vb + vc) / third - air;
            let speed = relative.dot(relative).sqrt();
            let flow = relative / speed;
            let facing = flow.dot(n);
            let area = half * twice_area;
            let drag = n * (-half_rho * c(self.drag) * area * speed * speed * facing);
            let across = n - flow * facing;
            let lift = across * (-half_rho * c(self.lift) * area * speed * speed * facing);
            // Lanes past the last triangle hold zeros: a degenerate triangle.
            let skip = (twice_area.simd_le(c(1e-12)) | speed.simd_le(c(1e-6))).to_bitmask();
            let all = ((drag + lift) / third).unpack();
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

    /// A flag of `quads`, standing, at places jittered by up to `by` (seeded with `seed`)
    /// and speeds of up to 3 m/s, with triangle `flat` folded flat (degenerate) and
    /// triangle `with_air` moving with the steady wind; and the wind gusting and steady.
    fn flag_in_the_wind(
        quads: [u32; 2],
        [by, seed]: [f32; 2],
        [flat, with_air]: [usize; 2],
    ) -> (ClothModel, Vec<Vec3>, Vec<Vec3>, [Wind; 2]) {
        let mesh = GridSpec {
            quads_x: quads[0],
            quads_y: quads[1],
            size_x: 0.1 * quads[0] as f32,
            size_y: 0.1 * quads[1] as f32,
            orientation: GridOrientation::Vertical,
            center: Vec3::ZERO,
        }
        .build()
        .unwrap();
        let model = ClothModel::new(&mesh, 0.2, &[]);
        let mut jitter = crate::test_rng::jitter(seed as u64);
        let mut pos: Vec<Vec3> = (model.rest_positions.iter())
            .map(|&p| p + jitter(by))
            .collect();
        let mut vel: Vec<Vec3> = (0..pos.len()).map(|_| jitter(3.0)).collect();
        let [a, _, c] = model.triangles[flat].map(|i| i as usize);
        pos[c] = pos[a];
        let gusting = Wind::default();
        let steady = Wind {
            gust: 0.0,
            ..gusting
        };
        for &i in &model.triangles[with_air] {
            vel[i as usize] = steady.velocity;
        }
        (model, pos, vel, [gusting, steady])
    }

    /// A 7 × 5-quad flag (70 triangles: the last chunk holds six) at jittered places and
    /// speeds, with one triangle folded flat (degenerate) and, in a steady wind, one moving
    /// with the air: eight triangles at a time push every particle as one at a time does,
    /// to the bit, in a gusting wind and a steady one, early and an hour in.
    #[test]
    fn eight_triangles_at_a_time_push_as_one_at_a_time() {
        let (model, pos, vel, [gusting, steady]) = flag_in_the_wind([7, 5], [0.03, 7.0], [9, 30]);
        assert!(!model.triangles.len().is_multiple_of(LANES));
        let pushed = model.triangles[9][1] as usize;
        for (wind, t) in [(gusting, 0.25), (gusting, 3600.0), (steady, 1.0)] {
            let (mut lanes, mut one) = (vec![Vec3::ZERO; pos.len()], vec![Vec3::ZERO; pos.len()]);
            let term = WindForce::new(wind, &model);
            ForceTerm::<f32>::add_forces(&term, &model, &pos, &vel, t, &mut lanes);
            wind.add_forces_one_by_one::<f32>(&model, &pos, &vel, t, &mut one);
            assert_eq!(lanes, one, "t = {t} s");
            assert!(lanes.iter().all(|f| f.is_finite()) && lanes[pushed] != Vec3::ZERO);
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
        let (model, pos, vel, [gusting, steady]) =
            flag_in_the_wind([64, 64], [0.005, 14.0], [100, 5000]);
        assert!(model.triangles.len() >= crate::parallel::PARALLEL_ELEMENTS);
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
