//! A sphere the cloth cannot enter, still or spinning about its centre.

use glam::Vec3;

use super::effect_kind::{ClothBox, ContactPass, EffectKind, GuardShare};
#[cfg(doc)]
use super::faces::FacePatches;
use super::solid::{Solid, default_friction, resolve_in_boxes, touching};
use crate::cloth::ClothState;
use crate::sim::obstacle::closest_weights;
use crate::sim::param_error::ParamError;
use crate::sim::self_contacts::ContactError;

/// A sphere spinning with angular velocity `spin` (zero for a still one).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sphere {
    /// Metres.
    pub center: Vec3,
    /// Metres.
    pub radius: f32,
    /// rad/s about each axis (axis × rate; default still).
    #[serde(default)]
    pub spin: Vec3,
    /// Coulomb friction coefficient (dimensionless, default 0.5).
    #[serde(default = "default_friction")]
    pub friction: f32,
}

impl Solid for Sphere {
    #[inline]
    fn surface_at(&self, p: Vec3) -> (f32, Vec3, Vec3) {
        let r = p - self.center;
        let len = r.length();
        let n = if len > 1e-9 { r / len } else { Vec3::Y };
        (len - self.radius, n, self.spin.cross(n * self.radius))
    }

    /// A path entering the sphere is caught at its first contact: the part of the move
    /// that points into the surface after it is removed (the part along it is kept, so
    /// cloth still slides) before the particle is pushed out to `offset`; so a fast
    /// particle cannot pass through, however small the sphere.
    #[inline]
    fn catch(&self, from: Vec3, to: Vec3, offset: f32) -> Option<Vec3> {
        let center = self.center;
        let reach = self.radius + offset;
        let entry = first_entry(from - center, to - center, reach);
        if entry.is_none() && (to - center).length_squared() >= reach * reach {
            return None;
        }
        // Keep the move's tangential part at the first contact, drop what points in.
        let moved = match entry {
            Some(hit) => {
                let n = hit.normalize_or(Vec3::Y);
                let rest = (to - center) - hit;
                hit + rest - rest.dot(n).min(0.0) * n
            }
            None => to - center,
        };
        let len = moved.length();
        let n = if len > 1e-9 { moved / len } else { Vec3::Y };
        Some(center + n * reach.max(len))
    }

    /// Clear where the move's end lies farther from the centre than the reach and the
    /// move's length together (every point of the move is then beyond the reach), with a
    /// margin no rounding of the catch bridges: `|b| > 1.01 (r + |d|)`. Most of a cloth
    /// lies so far from a small sphere: the catch's own tests cost it several times as
    /// much. (Told without the root, as `|b|² > 2.05 (r² + |d|²)`, which holds only where
    /// that does, a particle still had to lie 1.43 reaches out: where `crumple` drapes over
    /// the sphere at 64², a quarter of the cloth went through the catch.)
    #[inline]
    fn clear(&self, from: Vec3, to: Vec3, offset: f32) -> bool {
        let far = 1.01 * (self.radius + offset + (to - from).length());
        (to - self.center).length_squared() > far * far
    }

    #[inline]
    fn friction(&self) -> f32 {
        self.friction
    }

    /// Clear where the box lies farther from the centre than the reach, by a
    /// ten-thousandth of it: a margin that keeps the paths' rounding out of the question.
    #[inline]
    fn box_clear(&self, lo: Vec3, hi: Vec3, offset: f32) -> bool {
        let reach = (self.radius + offset) * 1.0001;
        self.center.clamp(lo, hi).distance_squared(self.center) > reach * reach
    }
}

/// A face whose nearest point lies within this share of the offset inside the reach
/// touches it and is left as it is: the particles' pass leaves a corner exactly at the
/// reach, and whether a face's nearest point there then lies a rounding inside it turns on
/// the arithmetic, the CPU's or the GPU's; pushed, its point's whole approach is taken
/// out. (Without it, `sphere-drop` on the two backends parted by 0.8 mm in the frame it
/// lands, against 0.5 µm.)
pub const FACE_TOUCHING: f32 = 1e-4;

impl Sphere {
    /// Keeps each triangle's interior out of the sphere too (the guarantee covers the
    /// surface): a flat triangle over a small sphere dips in between its corners however
    /// far out they are. A triangle whose point nearest the centre is within the radius and
    /// the offset is pushed out along the line from the centre, its corners by their
    /// weights and inverse masses, and that point's velocity loses what points in, its
    /// sliding slowed by Coulomb friction as a particle's on the sphere is (the push lifts
    /// the corners of a face draped over it past the offset, where the particles' own pass
    /// no longer touches them), the change shared among the corners as the push is: the
    /// point's change is exactly Coulomb's, the triangle's momentum about the centre keeps
    /// but for the friction, and a corner that bears little of the contact (its weight a
    /// rounding from zero, near where the nearest point leaves its region) changes little.
    /// The triangles go one after another, colour after colour (as the GPU's pass takes
    /// them, a colour at once: two of a colour share no particle), each from where the last
    /// left its corners. (Each corner taking the average of its triangles' pushes, found
    /// from where the pass found the cloth, a draped cloth jittered on and a frictionless
    /// spinning sphere turned it.) Only the triangles of the patches whose box comes that
    /// near are tested ([`FacePatches`]), and of those only the ones a bound on their
    /// distance does not tell clear are measured. Returns the triangles pushed.
    fn keep_faces_out(&self, pass: &mut ContactPass<'_>) -> usize {
        let reach = self.radius + pass.offset;
        let (model, state) = (pass.model, &mut *pass.state);
        let Some(patches) = pass.faces.as_deref_mut() else {
            return 0;
        };
        // Only the triangles of the patches whose box comes within the reach.
        let center = self.center;
        let near =
            |lo: Vec3, hi: Vec3| center.clamp(lo, hi).distance_squared(center) < reach * reach;
        let inv = &model.inv_mass;
        let mut pushed = 0;
        for &t in patches.near(model, &state.pos, near) {
            let ids = model.triangles[t as usize].map(|i| i as usize);
            let x = ids.map(|i| state.pos[i]);
            if clear_of(center, reach, x) {
                continue;
            }
            let w = closest_weights(self.center, x);
            let q = w[0] * x[0] + w[1] * x[1] + w[2] * x[2];
            let gap = q - self.center;
            let d = gap.length();
            let weight: f32 = (0..3).map(|k| w[k] * w[k] * inv[ids[k]]).sum();
            if d >= reach - FACE_TOUCHING * pass.offset || d < 1e-9 || weight <= 0.0 {
                continue;
            }
            let n = gap / d;
            let lambda = (reach - d) / weight;
            // The surface there, spinning or not: the face's nearest point slides on it as
            // a particle resting on it would (Coulomb, the sphere's friction), the change
            // of its velocity shared among the corners as the push is.
            let v_surface = self.spin.cross(n * self.radius);
            let v: Vec3 = (0..3).map(|k| w[k] * state.vel[ids[k]]).sum();
            let change = (touching(v, v_surface, n, self.friction, 1.0) - v) / weight;
            for k in 0..3 {
                let i = ids[k];
                let share = w[k] * inv[i];
                state.pos[i] += (share * lambda) * n;
                state.vel[i] += share * change;
            }
            pushed += 1;
        }
        pushed
    }
}

/// Whether the triangle with corners `x` keeps at least `reach` from `center`, told
/// without its nearest point: each of its points `q = Σ wₖ xₖ` (weights summing to 1) is
/// `|q − c|² = Σ wₖ |xₖ − c|² − Σ wₖ |xₖ − q|²` from `c`, at least the nearest corner's
/// square less the largest square of a corner's distance from the centroid (the weighted
/// spread about `q` is at most that about any other point). A margin of a thousandth
/// covers the rounding; a triangle it leaves undecided is measured. Of the 2 000
/// triangles near the sphere where `crumple` drapes over it at 64², 1 300 are told clear
/// so.
#[inline]
fn clear_of(center: Vec3, reach: f32, x: [Vec3; 3]) -> bool {
    let nearest = x.map(|p| p.distance_squared(center));
    let g = (x[0] + x[1] + x[2]) / 3.0;
    let spread = x.map(|p| p.distance_squared(g));
    let least = nearest[0].min(nearest[1]).min(nearest[2]);
    least - spread[0].max(spread[1]).max(spread[2]) >= 1.001 * reach * reach
}

/// The first point (relative to the sphere's centre) where the segment `a → b` enters the
/// sphere of radius `r`, if `a` is outside it and the segment reaches it.
#[inline]
fn first_entry(a: Vec3, b: Vec3, r: f32) -> Option<Vec3> {
    let d = b - a;
    let (aa, dd) = (a.length_squared(), d.length_squared());
    if aa < r * r || dd == 0.0 {
        return None;
    }
    // |a + t·d|² = r²  ⇔  dd·t² + 2(a·d)·t + (aa − r²) = 0; the smaller root enters.
    let half_b = a.dot(d);
    let disc = half_b * half_b - dd * (aa - r * r);
    if half_b >= 0.0 || disc < 0.0 {
        return None;
    }
    let t = (-half_b - disc.sqrt()) / dd;
    (0.0..=1.0).contains(&t).then(|| a + t * d)
}

impl EffectKind for Sphere {
    const NAME: &'static str = "sphere";
    const TITLE: &'static str = "Sphere";
    const MANY: bool = true;
    const ADDABLE: bool = true;

    fn check(&self) -> Result<(), ParamError> {
        ParamError::require(
            self.radius.is_finite() && self.radius > 0.0,
            "radius",
            self.radius,
            "must be positive metres",
        )?;
        ParamError::require(
            self.center.is_finite() && self.spin.is_finite(),
            "center",
            self.center,
            "must be finite metres",
        )
    }

    fn is_contact(&self) -> bool {
        true
    }

    fn resolve(&self, pass: &mut ContactPass<'_>) -> Result<usize, ContactError> {
        // Where the substep's whole motion lies in a box clear of the sphere (a cloth
        // falling onto it, still above), no path enters it and no triangle reaches it. The
        // box is taken as the particles are: where a member's part is clear, it tests none
        // of its particles (one section rather than two).
        let (particles, (lo, hi)) = resolve_in_boxes(self, pass);
        if self.box_clear(lo, hi, pass.offset) {
            return Ok(particles);
        }
        Ok(particles + self.keep_faces_out(pass))
    }

    fn is_solid(&self) -> bool {
        true
    }

    /// The same at any time: it spins about its centre.
    fn surface(&self, p: Vec3, _t: f64) -> Option<(f32, Vec3, Vec3)> {
        Some(self.surface_at(p))
    }

    fn shell(&self, _t: f64, offset: f32) -> Option<(Vec3, Vec3)> {
        let reach = Vec3::splat(self.radius + offset);
        Some((self.center - reach, self.center + reach))
    }

    fn guard(&self, up: Vec3, _cloth: &ClothState) -> GuardShare {
        GuardShare {
            floor: Some(up.dot(self.center) - self.radius),
            surface_speed: self.spin.length() * self.radius,
            flow_speed: 0.0,
        }
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    /// Just under the cloth's middle, a quarter of its size across, so it falls onto it.
    fn suggested(cloth: &ClothBox) -> Self {
        let size = (cloth.hi - cloth.lo).max_element().max(0.1);
        let radius = 0.25 * size;
        let mid = 0.5 * (cloth.lo + cloth.hi);
        Sphere {
            center: Vec3::new(mid.x, cloth.lo.y - 0.05 * size - radius, mid.z),
            radius,
            spin: Vec3::ZERO,
            friction: default_friction(),
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::mesh::bounds;

    /// A horizontal grid cloth of `quads` quads a side, `size` metres across, centred at
    /// `center`.
    fn grid(quads: u32, size: f32, center: Vec3) -> crate::cloth::ClothModel {
        use crate::mesh::{GridOrientation, GridSpec};
        let mesh = GridSpec::square(quads, size, GridOrientation::Horizontal, center)
            .build()
            .unwrap();
        crate::cloth::ClothModel::new(&mesh, 0.2, &[])
    }

    /// A substep of 10 ms of `model` from `start` to `state`, an offset of 1 cm, no faces.
    fn pass_of<'a>(
        model: &'a crate::cloth::ClothModel,
        start: &'a [Vec3],
        state: &'a mut crate::cloth::ClothState,
        self_contacts: &'a mut crate::sim::self_contacts::SelfContacts,
    ) -> ContactPass<'a> {
        ContactPass {
            model,
            start,
            substep: 0.01,
            state,
            offset: 0.01,
            self_contacts,
            faces: None,
        }
    }

    /// A 4 × 4-quad cloth 1 m wide falls from 1 m above a sphere of 10 cm to 1 m below it
    /// within one substep: it starts and ends far from the sphere, yet the path of its
    /// middle particle goes through it, and is caught where it enters: that particle ends
    /// on the sphere's top, the others (25 cm and more to the side) fall on. A cloth that
    /// stays above moves nothing.
    #[test]
    fn a_cloth_that_falls_past_the_sphere_within_a_substep_is_caught() {
        use crate::cloth::ClothState;
        use crate::sim::self_contacts::SelfContacts;
        let model = grid(4, 1.0, Vec3::Y);
        let sphere = Sphere {
            center: Vec3::ZERO,
            radius: 0.1,
            spin: Vec3::ZERO,
            friction: 0.0,
        };
        let start = model.rest_positions.clone();
        let middle = (start.iter())
            .position(|p| p.x == 0.0 && p.z == 0.0)
            .unwrap();
        let mut self_contacts = SelfContacts::default();
        let mut fall = |by: f32| {
            let mut state = ClothState::at_rest(&model);
            state.pos.iter_mut().for_each(|p| p.y -= by);
            let mut pass = pass_of(&model, &start, &mut state, &mut self_contacts);
            let moved = sphere.resolve(&mut pass).unwrap();
            (moved, state.pos)
        };
        let (moved, pos) = fall(2.0);
        assert_eq!(moved, 1);
        assert!(
            pos[middle].distance(Vec3::Y * 0.11) < 1e-6,
            "{}",
            pos[middle]
        );
        let others = (0..pos.len()).filter(|&i| i != middle);
        assert!(others.clone().all(|i| pos[i] == start[i] - 2.0 * Vec3::Y));
        let (moved, pos) = fall(0.5);
        assert_eq!(moved, 0);
        assert!((0..pos.len()).all(|i| pos[i] == start[i] - 0.5 * Vec3::Y));
    }

    /// A 64 × 64-quad cloth (above the size the team shares from) falls onto a sphere
    /// under one side of it: on two threads the member whose part lies far from the sphere
    /// tests none of its particles, yet every particle ends where it does on one thread, to
    /// the bit, and as many are caught; the box returned is that of both ends of every
    /// move. A cloth still above the sphere moves nothing, and its box is still that of its
    /// moves.
    #[test]
    fn the_particles_caught_in_parts_are_those_caught_in_one_and_the_box_is_every_moves() {
        use crate::cloth::ClothState;
        use crate::sim::self_contacts::SelfContacts;
        let model = grid(64, 1.0, Vec3::Y);
        assert!(model.particle_count() >= crate::parallel::PARALLEL_ELEMENTS);
        let sphere = Sphere {
            center: Vec3::new(0.3, 0.0, 0.3),
            radius: 0.15,
            spin: Vec3::ZERO,
            friction: 0.3,
        };
        let start = model.rest_positions.clone();
        let mut rnd = crate::test_rng::uniform(3);
        let drops: Vec<Vec3> = (start.iter())
            .map(|_| Vec3::new(rnd() - 0.5, -10.0 * rnd(), rnd() - 0.5) * 0.02)
            .collect();
        // Falls by `by` (each particle a little more or less, and sideways), on `threads`.
        let fall = |by: f32, threads: usize| {
            let mut state = ClothState::at_rest(&model);
            for ((p, v), d) in state.pos.iter_mut().zip(&mut state.vel).zip(&drops) {
                *p += *d - by * Vec3::Y;
                *v = (*d - by * Vec3::Y) / 0.01;
            }
            let both: Vec<Vec3> = start.iter().chain(&state.pos).copied().collect();
            let mut self_contacts = SelfContacts::default();
            let mut pass = pass_of(&model, &start, &mut state, &mut self_contacts);
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            let (caught, found) = pool.install(|| resolve_in_boxes(&sphere, &mut pass));
            assert_eq!(found, bounds(&both), "{threads} threads");
            (caught, state)
        };
        let bits = |v: &[Vec3]| -> Vec<[u32; 3]> {
            v.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
        };
        let (one, alone) = fall(0.9, 1);
        let (two, shared) = fall(0.9, 2);
        assert!(one > 100, "{one} caught");
        assert_eq!(one, two);
        assert_eq!(bits(&alone.pos), bits(&shared.pos));
        assert_eq!(bits(&alone.vel), bits(&shared.vel));
        // Far from the sphere, the first rows keep their moves on both.
        assert!((0..65).all(|i| alone.pos[i] == start[i] + (drops[i] - 0.9 * Vec3::Y)));
        for threads in [1, 2] {
            let (caught, above) = fall(0.1, threads);
            assert_eq!(caught, 0);
            assert!(
                (0..start.len()).all(|i| above.pos[i] == start[i] + (drops[i] - 0.1 * Vec3::Y))
            );
        }
    }

    /// The nearest any point of the triangle `x` comes to `c`, in f64, from a fine
    /// sampling of its barycentric weights (a lower bound within the sampling's step).
    fn nearest_sampled(c: Vec3, x: [Vec3; 3]) -> f64 {
        let (c, x) = (c.as_dvec3(), x.map(|p| p.as_dvec3()));
        let n = 200;
        let mut least = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                let q: DVec3 = (1.0 - u - v) * x[0] + u * x[1] + v * x[2];
                least = least.min(q.distance(c));
            }
        }
        least
    }

    /// A face the sphere holds up by its interior slides on it by Coulomb's law, as a
    /// particle resting on it does: a 20 cm quad lies 5 mm above the top of a sphere of
    /// 10 cm, whose centre lies under one of its triangles 7 cm from the quad's middle
    /// (the corners far outside the reach, the triangle's point above the centre 5 mm
    /// inside it, the other triangle outside), and moves at 1 m/s along x while falling
    /// at 0.5 m/s. That triangle's point over the centre loses its fall and 0.4 × 0.5 m/s
    /// of its slide (μ = 0.4), ending at (0.8, 0, 0) m/s: each of the three corners is
    /// lifted and its velocity changed by `wₖ mₖ⁻¹ / Σ wⱼ² mⱼ⁻¹` times that change, its
    /// weight `wₖ` in that point and its inverse mass `mₖ⁻¹` (so the point's change is
    /// exactly it, as its move is the push); the fourth corner keeps its
    /// motion. Without the face's friction the corners slid on at 1 m/s, and a cloth
    /// draped over a sphere slid off it; with the whole change at every corner, one that
    /// bears a rounding of the contact took all of it.
    #[test]
    fn a_face_the_sphere_holds_up_slides_by_coulombs_law() {
        use crate::cloth::ClothState;
        use crate::sim::effects::faces::FacePatches;
        use crate::sim::self_contacts::SelfContacts;
        let model = grid(1, 0.2, Vec3::ZERO);
        let sphere = Sphere {
            center: Vec3::new(0.07, 0.0, 0.0),
            radius: 0.1,
            spin: Vec3::ZERO,
            friction: 0.4,
        };
        let mut state = ClothState::at_rest(&model);
        for (x, v) in state.pos.iter_mut().zip(&mut state.vel) {
            x.y = 0.105;
            *v = Vec3::new(1.0, -0.5, 0.0);
        }
        let start = state.pos.clone();
        let (mut self_contacts, mut faces) = (SelfContacts::default(), FacePatches::default());
        faces.prepare(&model);
        let mut pass = ContactPass {
            model: &model,
            start: &start,
            substep: 0.01,
            state: &mut state,
            offset: 0.01,
            self_contacts: &mut self_contacts,
            faces: Some(&mut faces),
        };
        assert_eq!(sphere.resolve(&mut pass).unwrap(), 1);
        let lifted: Vec<usize> = (0..4).filter(|&i| state.pos[i] != start[i]).collect();
        assert_eq!(lifted.len(), 3, "{:?}", state.pos);
        // The lifted corners' weights in the point over the centre, (0.07, 0) across the
        // quad: barycentric in the plane of the cloth.
        let flat = |v: Vec3| glam::Vec2::new(v.x, v.z);
        let [a, b, c] = [0, 1, 2].map(|k| flat(start[lifted[k]]));
        let p = flat(sphere.center);
        let area = (b - a).perp_dot(c - a);
        let w = [
            (b - p).perp_dot(c - p),
            (c - p).perp_dot(a - p),
            (a - p).perp_dot(b - p),
        ]
        .map(|x| x / area);
        let inv = [0, 1, 2].map(|k| model.inv_mass[lifted[k]]);
        let weight: f32 = (0..3).map(|k| w[k] * w[k] * inv[k]).sum();
        let (before, after) = (Vec3::new(1.0, -0.5, 0.0), Vec3::new(0.8, 0.0, 0.0));
        for i in 0..4 {
            let expected = match lifted.iter().position(|&k| k == i) {
                Some(k) => before + (after - before) * (w[k] * inv[k] / weight),
                None => before,
            };
            let v = state.vel[i];
            assert!(v.distance(expected) < 1e-6, "{i}: {v} against {expected}");
        }
        let point: Vec3 = (0..3).map(|k| w[k] * state.vel[lifted[k]]).sum();
        assert!(point.distance(after) < 1e-6, "the point moves at {point}");
    }

    /// What `clear_of` tells clear keeps the reach, for triangles of every shape and size
    /// about a sphere of 15 cm (a flat one over it dips in between corners that stay
    /// out); and it tells clear most of those that keep a few millimetres more.
    #[test]
    fn a_triangle_told_clear_of_the_sphere_keeps_the_reach() {
        let mut rnd = crate::test_rng::uniform(5);
        let mut point = |scale: f32| Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * scale;
        let (center, reach) = (Vec3::new(0.1, -0.2, 0.3), 0.153);
        let (mut clear, mut farther) = (0, 0);
        for k in 0..4000 {
            // A point near the surface and corners about it, from 2 mm to 20 cm apart.
            let around = center + point(1.0).normalize_or(Vec3::Y) * (reach + point(0.02).x);
            let size = [0.002, 0.016, 0.05, 0.2][k % 4];
            let x = [
                around + point(size),
                around + point(size),
                around + point(size),
            ];
            let nearest = nearest_sampled(center, x);
            // The sampling's step is at most 1 mm at the largest size.
            if clear_of(center, reach, x) {
                clear += 1;
                assert!(nearest >= f64::from(reach) - 1e-3, "{x:?}: {nearest}");
            }
            if nearest > f64::from(reach) + 0.003 && size < 0.02 {
                farther += 1;
            }
        }
        assert!(
            clear * 2 > farther,
            "{clear} told clear of {farther} farther"
        );
        // Corners all 3 mm outside, the middle 5 mm inside: not clear.
        let flat = [0.0f32, 120.0, 240.0].map(|a| {
            let (sin, cos) = a.to_radians().sin_cos();
            center + Vec3::new(0.05 * cos, reach - 0.005, 0.05 * sin)
        });
        assert!(flat.iter().all(|p| p.distance(center) > reach + 0.003));
        assert!(nearest_sampled(center, flat) < f64::from(reach) - 0.004);
        assert!(!clear_of(center, reach, flat));
    }

    /// A move `Solid::clear` passes by stays beyond the reach all along (sampled), so the
    /// catch would not have caught it; and it passes by every move that ends beyond 1.02
    /// times the reach and its length together (told by their squares alone, it left those
    /// up to 1.43 reaches out to the catch). Moves end from 0.9 to 4 reaches from a sphere
    /// of 15 cm, 1 mm to 60 cm long.
    #[test]
    fn a_move_told_clear_of_the_sphere_stays_beyond_the_reach() {
        let mut rnd = crate::test_rng::uniform(9);
        let mut unit = || Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or(Vec3::Y);
        let sphere = Sphere {
            center: Vec3::new(0.1, -0.2, 0.3),
            radius: 0.15,
            spin: Vec3::ZERO,
            friction: 0.5,
        };
        let (offset, reach) = (0.003, 0.153);
        let (mut clear, mut far) = (0, 0);
        for k in 0..8000 {
            let ends = 0.9 + 3.1 * (k % 97) as f32 / 96.0;
            let to = sphere.center + unit() * ends * reach;
            let length = [0.001, 0.02, 0.15, 0.6][k % 4];
            let from = to + unit() * length;
            let nearest = (0..=400)
                .map(|j| (from + (to - from) * (j as f32 / 400.0)).distance(sphere.center))
                .fold(f32::INFINITY, f32::min);
            if sphere.clear(from, to, offset) {
                clear += 1;
                assert!(nearest >= 1.01 * reach, "{from} → {to}: {nearest}");
                assert!(sphere.catch(from, to, offset).is_none());
            }
            if to.distance(sphere.center) > 1.02 * (reach + length) {
                far += 1;
                assert!(sphere.clear(from, to, offset), "{from} → {to}");
            }
        }
        assert!(clear >= far && far > 1000, "{clear} told clear, {far} far");
    }
}
