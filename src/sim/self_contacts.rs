//! Self-collision's solver: particle against triangle, so cloth folds onto itself without
//! passing through itself. Candidates come from a hierarchical spatial hash (triangles binned by
//! their box grown by the thickness, sorted by cell, each at the level whose cells are as
//! large as the box), so the work grows with the particle count, not its square, and the
//! table holds at most eight entries a triangle however the cloth is stretched.

use glam::Vec3;

use crate::cloth::{ClothModel, ClothState};

/// Work done by the last resolve: for cost checks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SelfWork {
    /// Particle–triangle pairs examined.
    pub candidates: u64,
    /// Pairs that were closer than the thickness.
    pub contacts: u64,
    /// Entries in the spatial hash's table (at most [`CELLS_PER_TRIANGLE`] per triangle).
    pub binned: u64,
}

/// Levels of the hierarchical hash: a triangle goes to the first level whose cells (the base
/// cell times 2^level) hold its box in at most two cells along each axis, so it is binned in
/// at most eight. A box wider than the base cell times 2^`MAX_LEVEL` (a million times the
/// cloth's own scale) is a state that has blown up, refused rather than binned.
const MAX_LEVEL: u32 = 20;

/// Most cells one triangle is binned in: two along each axis.
pub const CELLS_PER_TRIANGLE: usize = 8;

/// A state contact detection cannot bin.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    #[error("particle {particle} has a non-finite position")]
    NonFinite { particle: usize },
    #[error(
        "triangle {triangle} spans {extent:.3e} m, more than a million times the cloth's \
         cell of {cell:.3e} m: the state has blown up"
    )]
    Extent {
        triangle: usize,
        extent: f32,
        cell: f32,
    },
}

/// Reusable buffers of the spatial hash.
#[derive(Clone, Debug, Default)]
pub struct SelfContacts {
    /// (cell key, triangle), sorted by key: at most [`CELLS_PER_TRIANGLE`] per triangle.
    bins: Vec<(u64, u32)>,
    /// Bit `l` is set when some triangle is binned at level `l`.
    levels: u32,
    pub work: SelfWork,
}

/// The key of cell `c` at `level`: three coordinates wrapped into 21 bits each, mixed with
/// the level. Distinct cells rarely share a key, and a shared key only adds candidates.
fn cell_key(c: [i32; 3], level: u32) -> u64 {
    let w = |x: i32| (x as u64) & 0x1F_FFFF;
    (w(c[0]) | (w(c[1]) << 21) | (w(c[2]) << 42))
        ^ (level as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

fn cell_of(p: Vec3, size: f32) -> [i32; 3] {
    // Float-to-int casts saturate: a far-away point lands in an edge cell, which only adds
    // candidates.
    (p / size).floor().as_ivec3().to_array()
}

/// The point of triangle (a, b, c) closest to `p`, with its barycentric weights.
fn closest_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, [f32; 3]) {
    // Ericson, Real-Time Collision Detection, 5.1.5: regions by barycentric signs.
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

impl SelfContacts {
    /// Keeps every particle at least `thickness` (m) from every triangle it is not a
    /// corner of, on the side it was on at the start of the substep (`start`): a particle
    /// over a triangle is pushed out along the triangle's normal, one beside it away from
    /// its closest point; particle and triangle share the correction by inverse mass.
    /// Approaching relative velocity is removed and Coulomb `friction` applied. Returns the
    /// contacts.
    ///
    /// # Errors
    /// [`ContactError`] for a state that has blown up (a non-finite position, or a triangle
    /// a million times wider than the cloth's scale); nothing is binned or moved then.
    pub fn resolve(
        &mut self,
        thickness: f32,
        friction: f32,
        model: &ClothModel,
        start: &[Vec3],
        state: &mut ClothState,
    ) -> Result<usize, ContactError> {
        if thickness <= 0.0 || model.triangles.is_empty() {
            return Ok(0);
        }
        let cell = self.bin(model, &state.pos, thickness)?;
        let mut work = SelfWork {
            binned: self.bins.len() as u64,
            ..SelfWork::default()
        };
        for p in 0..state.pos.len() {
            if model.inv_mass[p] == 0.0 {
                continue;
            }
            let mut levels = self.levels;
            while levels != 0 {
                let level = levels.trailing_zeros();
                levels &= levels - 1;
                let size = cell * (1u32 << level) as f32;
                let key = cell_key(cell_of(state.pos[p], size), level);
                let first = self.bins.partition_point(|&(k, _)| k < key);
                for slot in first..self.bins.len() {
                    let (k, t) = self.bins[slot];
                    if k != key {
                        break;
                    }
                    let tri = model.triangles[t as usize];
                    if tri.contains(&(p as u32)) {
                        continue;
                    }
                    work.candidates += 1;
                    if push_apart([thickness, friction], model, start, state, p, tri) {
                        work.contacts += 1;
                    }
                }
            }
        }
        self.work = work;
        Ok(work.contacts as usize)
    }

    /// Entries in the hash's table now: at most [`CELLS_PER_TRIANGLE`] per triangle,
    /// whatever the positions.
    pub fn table_len(&self) -> usize {
        self.bins.len()
    }

    /// Bins every triangle into the cells its box, grown by the thickness, touches, at the
    /// first level where that is at most two cells along each axis; returns the base cell
    /// size (twice the longest rest edge or the thickness, whichever is larger).
    fn bin(
        &mut self,
        model: &ClothModel,
        pos: &[Vec3],
        thickness: f32,
    ) -> Result<f32, ContactError> {
        if let Some(particle) = pos.iter().position(|p| !p.is_finite()) {
            return Err(ContactError::NonFinite { particle });
        }
        let longest = model.springs.rest[..model.mesh_edges.min(model.springs.len())]
            .iter()
            .fold(0.0f32, |m, &r| m.max(r));
        let cell = (2.0 * longest).max(2.0 * thickness).max(1e-6);
        self.bins.clear();
        self.levels = 0;
        let grow = Vec3::splat(thickness);
        for (t, tri) in model.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| pos[i as usize]);
            let (lo, hi) = (a.min(b).min(c) - grow, a.max(b).max(c) + grow);
            let (level, lo, hi) = level_of(lo, hi, cell).ok_or(ContactError::Extent {
                triangle: t,
                extent: (hi - lo).max_element(),
                cell,
            })?;
            self.levels |= 1 << level;
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        self.bins.push((cell_key([x, y, z], level), t as u32));
                    }
                }
            }
        }
        self.bins.sort_unstable();
        Ok(cell)
    }
}

/// The first level at which the box `lo..hi` lies in at most two cells along each axis, with
/// the first and last cell it touches; `None` past [`MAX_LEVEL`].
fn level_of(lo: Vec3, hi: Vec3, cell: f32) -> Option<(u32, [i32; 3], [i32; 3])> {
    let extent = (hi - lo).max_element();
    (0..=MAX_LEVEL).find_map(|level| {
        let size = cell * (1u32 << level) as f32;
        if extent > size {
            return None;
        }
        let (first, last) = (cell_of(lo, size), cell_of(hi, size));
        let narrow = (0..3).all(|i| i64::from(last[i]) - i64::from(first[i]) <= 1);
        narrow.then_some((level, first, last))
    })
}

/// Resolves particle `p` against triangle `tri` if closer than `thickness`, with `friction`;
/// returns whether it was.
fn push_apart(
    [thickness, friction]: [f32; 2],
    model: &ClothModel,
    start: &[Vec3],
    state: &mut ClothState,
    p: usize,
    tri: [u32; 3],
) -> bool {
    let [ia, ib, ic] = tri.map(|i| i as usize);
    let (a, b, c) = (state.pos[ia], state.pos[ib], state.pos[ic]);
    let x = state.pos[p];
    let (closest, bary) = closest_on_triangle(x, a, b, c);
    let gap = x - closest;
    let dist = gap.length();
    if dist >= thickness {
        return false;
    }
    let normal = (b - a).cross(c - a).normalize_or_zero();
    if normal == Vec3::ZERO {
        return false;
    }
    let over = bary.iter().all(|&w| w > 0.0);
    let direction = if over {
        // Over the triangle: out along its normal, to the side the particle started on.
        let before = (b - a).cross(c - a);
        let was = (start[p] - start[ia]).dot((start[ib] - start[ia]).cross(start[ic] - start[ia]));
        let side = if was != 0.0 {
            was.signum()
        } else {
            gap.dot(before).signum()
        };
        normal * if side == 0.0 { 1.0 } else { side }
    } else if dist > 1e-9 {
        gap / dist
    } else {
        normal
    };
    let depth = thickness - gap.dot(direction);
    if depth <= 0.0 {
        return false;
    }
    let w = &model.inv_mass;
    let corners = [ia, ib, ic];
    let weight = w[p]
        + corners
            .iter()
            .zip(bary)
            .map(|(&i, b)| b * b * w[i])
            .sum::<f32>();
    if weight <= 0.0 {
        return false;
    }
    let lambda = depth / weight;
    state.pos[p] += (w[p] * lambda) * direction;
    for (&i, b) in corners.iter().zip(bary) {
        state.pos[i] -= (b * w[i] * lambda) * direction;
    }
    // Velocities: no approach along the direction; friction on the sliding part.
    let surface: Vec3 = corners
        .iter()
        .zip(bary)
        .map(|(&i, b)| b * state.vel[i])
        .sum();
    let relative = state.vel[p] - surface;
    let approach = relative.dot(direction);
    if approach < 0.0 {
        let sliding = relative - approach * direction;
        let speed = sliding.length();
        let friction = if speed > 0.0 {
            (friction * -approach / speed).min(1.0)
        } else {
            0.0
        };
        let change = -approach * direction - friction * sliding;
        let impulse = change / weight;
        state.vel[p] += w[p] * impulse;
        for (&i, b) in corners.iter().zip(bary) {
            state.vel[i] -= b * w[i] * impulse;
        }
    }
    true
}
