//! How the GPU backend lays the cloth out for its shader: particles as two `vec4`s, spring
//! ends as 8-byte records with a strength class, the uniform parameters. Every vector is a
//! `vec4` (WGSL gives `vec3` arrays a 16-byte stride).

use bytemuck::{Pod, Zeroable};

use crate::cloth::ClothModel;
use crate::mesh::SpringKind;
use crate::sim::{BendingModel, Effect, Material};

/// Colliders the shader has room for.
pub(super) const MAX_COLLIDERS: usize = 4;

/// Rigid mesh obstacles the obstacle pass has room for (its shader's `array<Obstacle, 4>`).
pub(super) const MAX_OBSTACLES: usize = 4;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct Particle {
    pub(super) x: [f32; 4],
    pub(super) v: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct Neighbour {
    /// The other end's index in the high bits, its strength class (an index into the
    /// class table) in the low [`CLASS_BITS`] (see [`end_bits`]).
    pub(super) other: u32,
    pub(super) rest: f32,
}

/// Low bits of [`Neighbour::other`] that hold the strength class; the other end's index
/// takes the 28 above, so a cloth has at most 2²⁸ particles on the GPU backend. The shader
/// has the same constants (`shaders/substep.wgsl`; a test compares them).
pub(super) const CLASS_BITS: u32 = 4;
/// Strength classes (distinct stiffness–damping pairs) the shader's table holds: a cloth
/// has at most one per spring kind (3), which leaves room for strengths set otherwise.
pub(super) const MAX_CLASSES: usize = 1 << CLASS_BITS;
/// Particles a cloth may have on the GPU backend.
pub(super) const MAX_PARTICLES: u64 = 1 << (32 - CLASS_BITS);

/// A spring end's [`Neighbour::other`]: the index shifted up, the class below it. The class
/// sits low so that a shader that decodes either half wrongly reads another particle or
/// another class for every end (with the index low, a dropped mask would be hidden by
/// 32-bit address arithmetic that wraps the class bits away).
pub(super) fn end_bits(other: u32, class: u8) -> u32 {
    (other << CLASS_BITS) | u32::from(class)
}

/// Per strength class `[stiffness, damping, 0, 0]`: the shader's uniform `classes`.
pub(super) type ClassTable = [[f32; 4]; MAX_CLASSES];

/// What decides the spring ends' bits besides the model: whether each spring term (the
/// structural and shear springs; the bend springs, the model's last) is sent, and each
/// spring kind's class. A spring's stiffness and damping are its kind's, so the classes
/// are the distinct pairs among the kinds, and a strength change is known to keep the ends
/// as they are from three numbers, without a pass over the springs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct EndsKey {
    terms: [bool; 2],
    of_kind: [u8; SpringKind::ALL.len()],
}

/// The class of a spring the shader does not get.
pub(super) const NO_CLASS: u8 = u8::MAX;
const _: () = assert!(
    SpringKind::ALL.len() <= MAX_CLASSES,
    "every kind can have a class of its own"
);

impl EndsKey {
    /// The class of spring `e` of `model`, or [`NO_CLASS`] if its term is not sent.
    fn class_of(&self, model: &ClothModel, e: usize) -> u8 {
        if self.terms[usize::from(e >= model.bend_start())] {
            self.of_kind[model.springs.kind[e].index()]
        } else {
            NO_CLASS
        }
    }
}

/// Sorts the spring kinds into classes of equal stiffness and damping, numbered in kind
/// order, for the spring terms `effects` turn on: the ends' key and the class table.
pub(super) fn classify(material: &Material, effects: &[Effect]) -> (EndsKey, ClassTable) {
    let terms = [
        effects.iter().any(|e| matches!(e, Effect::Springs(_))),
        effects.contains(&Effect::Bending(BendingModel::Springs)),
    ];
    let mut table: ClassTable = [[0.0; 4]; MAX_CLASSES];
    let mut classes = 0;
    let mut of_kind = [NO_CLASS; SpringKind::ALL.len()];
    for kind in SpringKind::ALL.map(SpringKind::index) {
        let entry = [material.stiffness[kind], material.damping[kind], 0.0, 0.0];
        let same = |t: &[f32; 4]| t.map(f32::to_bits) == entry.map(f32::to_bits);
        let class = match table[..classes].iter().position(same) {
            Some(at) => at,
            None => {
                table[classes] = entry;
                classes += 1;
                classes - 1
            }
        };
        of_kind[kind] = class as u8;
    }
    (EndsKey { terms, of_kind }, table)
}

/// The springs as the shader reads them: per particle its range of `ends` (CSR offsets),
/// each end its other particle and class.
#[derive(Clone)]
pub(super) struct PackedSprings {
    pub(super) offsets: Vec<u32>,
    pub(super) ends: Vec<Neighbour>,
}

/// Packs the model's adjacency: each end of a spring that `key` gives a class, with the
/// class.
pub(super) fn pack_springs(model: &ClothModel, key: &EndsKey) -> PackedSprings {
    let adj = &model.adjacency;
    let count = model.particle_count();
    let mut offsets = Vec::with_capacity(count + 1);
    let mut ends = Vec::with_capacity(adj.spring.len());
    offsets.push(0u32);
    for p in 0..count {
        for slot in adj.range(p) {
            let (e, other) = (adj.spring[slot] as usize, adj.other[slot]);
            let class = key.class_of(model, e);
            if class != NO_CLASS && other as usize != p {
                ends.push(Neighbour {
                    other: end_bits(other, class),
                    rest: model.springs.rest[e],
                });
            }
        }
        offsets.push(ends.len() as u32);
    }
    PackedSprings { offsets, ends }
}

/// Links a grid particle may have (a 12-neighbour stencil has 12).
pub(super) const MAX_LINKS: usize = 16;

/// One link of a grid's stencil: the other particle `di` columns and `dj` rows away (two's
/// complement), the spring's strength class and the bits of its rest length.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub(super) struct GridLink {
    pub(super) di: i32,
    pub(super) dj: i32,
    pub(super) class: u32,
    pub(super) rest: f32,
}

/// A cloth whose particles are a `width` × `height` grid numbered row by row, every one
/// joined to the same neighbours (those the grid's edges leave) by springs of the same
/// class and rest length: the springs a particle gathers follow from its index.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct GridStencil {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) links: Vec<GridLink>,
}

/// Rest lengths of one link that differ by more than this fraction are not one link: the
/// rest lengths come from positions in f32 and differ by about 10⁻⁶ of themselves along a
/// regular grid (the flag's 5 cm structural springs by 6 × 10⁻⁸ m), so the grid path takes
/// the first one's for all, a prestrain of at most this much.
const REST_SPREAD: f32 = 1e-5;

/// The grid `packed` (the spring ends of `count` particles) is, if it is one: tried for
/// each width that particle 0's neighbours suggest.
pub(super) fn grid_of(packed: &PackedSprings, count: usize) -> Option<GridStencil> {
    let first = packed.offsets.first().copied()? as usize..*packed.offsets.get(1)? as usize;
    let mut widths: Vec<usize> = (packed.ends[first].iter())
        .map(|e| (e.other >> CLASS_BITS) as usize)
        .flat_map(|q| [q.saturating_sub(1), q, q + 1])
        .filter(|&w| w >= 2 && count.is_multiple_of(w) && count / w >= 2)
        .collect();
    widths.sort_unstable();
    widths.dedup();
    widths
        .into_iter()
        .find_map(|w| grid_with_width(packed, count, w))
}

/// [`grid_of`] for one width.
fn grid_with_width(packed: &PackedSprings, count: usize, width: usize) -> Option<GridStencil> {
    let height = count / width;
    let mut links: Vec<GridLink> = Vec::new();
    let place = |p: usize| ((p % width) as i32, (p / width) as i32);
    for p in 0..count {
        let (i, j) = place(p);
        let range = packed.offsets[p] as usize..packed.offsets[p + 1] as usize;
        for end in &packed.ends[range] {
            let (oi, oj) = place((end.other >> CLASS_BITS) as usize);
            let link = GridLink {
                di: oi - i,
                dj: oj - j,
                class: end.other & ((1 << CLASS_BITS) - 1),
                rest: end.rest,
            };
            match links.iter().find(|l| (l.di, l.dj) == (link.di, link.dj)) {
                Some(l)
                    if l.class == link.class
                        && (l.rest - link.rest).abs() <= REST_SPREAD * l.rest.abs() => {}
                Some(_) => return None,
                None if links.len() < MAX_LINKS => links.push(link),
                None => return None,
            }
        }
    }
    // Each end is one of the links; every link that stays on the grid must be one of the
    // particle's ends (no more of them than links, no link twice).
    let all = (0..count).all(|p| {
        let (i, j) = place(p);
        let on_grid = (links.iter())
            .filter(|l| {
                let (a, b) = (i + l.di, j + l.dj);
                a >= 0 && b >= 0 && a < width as i32 && b < height as i32
            })
            .count();
        on_grid == (packed.offsets[p + 1] - packed.offsets[p]) as usize
    });
    links.sort_by_key(|l| (l.dj, l.di));
    all.then_some(GridStencil {
        width: width as u32,
        height: height as u32,
        links,
    })
}

/// A collider's kind, `GpuCollider::info[0]` (the shaders compare `info.x` with 1 and 2).
pub(super) const SPHERE: f32 = 1.0;
pub(super) const PLANE: f32 = 2.0;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct GpuCollider {
    pub(super) info: [f32; 4],
    pub(super) a: [f32; 4],
    pub(super) b: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct Params {
    pub(super) gravity: [f32; 4],
    pub(super) drag: [f32; 4],
    pub(super) counts: [u32; 4],
    /// VBD: where its stencil's spans, links and memory start, and 1 when the memory is
    /// stale.
    pub(super) solver: [u32; 4],
    /// A grid cloth's width and height in particles and its links (0 wide: not a grid).
    pub(super) grid: [u32; 4],
    /// Where the handles' targets start among the element forces, and how many particles
    /// the handles carry.
    pub(super) handles: [u32; 4],
    pub(super) links: [GridLink; MAX_LINKS],
    pub(super) colliders: [GpuCollider; MAX_COLLIDERS],
}

/// The solids among `effects` as the shader reads them (the first [`MAX_COLLIDERS`]), and
/// how many there are. A plane's normal is made unit here.
pub(super) fn pack_solids(effects: &[Effect]) -> ([GpuCollider; MAX_COLLIDERS], u32) {
    let mut out = [GpuCollider::zeroed(); MAX_COLLIDERS];
    let solids = effects.iter().filter_map(|e| match e {
        Effect::Sphere(s) => Some(GpuCollider {
            info: [SPHERE, s.radius, s.friction, 0.0],
            a: s.center.extend(0.0).to_array(),
            b: s.spin.extend(0.0).to_array(),
        }),
        Effect::Plane(p) => Some(GpuCollider {
            info: [PLANE, 0.0, p.friction, 0.0],
            a: p.point.extend(0.0).to_array(),
            b: p.unit_normal().extend(0.0).to_array(),
        }),
        // What is not a solid takes no slot, and `gpu_support` refuses what the GPU lacks
        // (mesh obstacles).
        Effect::Obstacle(_)
        | Effect::Handle(_)
        | Effect::Springs(_)
        | Effect::Gravity(_)
        | Effect::AirDamping(_)
        | Effect::Bending(_)
        | Effect::Wind(_)
        | Effect::SelfCollision(_) => None,
    });
    let mut count = 0;
    for (slot, solid) in out.iter_mut().zip(solids) {
        *slot = solid;
        count += 1;
    }
    (out, count)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// `effects` without bending.
    pub(in crate::gpu) fn unbent(effects: &[Effect]) -> Vec<Effect> {
        (effects.iter())
            .filter(|e| !matches!(e, Effect::Bending(_)))
            .cloned()
            .collect()
    }

    /// Every spring end the CPU's force set has carries its other particle, its rest length
    /// and the class whose table entry is that spring's stiffness and damping there, in the
    /// adjacency's order; with the bend springs switched off, their ends are not sent.
    #[test]
    fn each_spring_end_points_at_the_strengths_the_cpu_gives_its_spring() {
        use crate::sim::ForceSet;
        let scene = crate::scene::Scene::builtin("sphere-drop").expect("scene");
        let (model, params) = (&scene.model, &scene.params);
        let unbent = unbent(&scene.effects);
        for (effects, classes) in [(&scene.effects, 3), (&unbent, 2)] {
            let forces = ForceSet::new(model, &params.material, effects);
            let strengths: std::collections::HashMap<usize, (f32, f32)> = (forces.springs())
                .flat_map(|t| t.each())
                .map(|(e, k, c)| (e, (k, c)))
                .collect();
            let (key, table) = classify(&params.material, effects);
            let packed = pack_springs(model, &key);
            let adj = &model.adjacency;
            let mut used = std::collections::BTreeSet::new();
            for p in 0..model.particle_count() {
                let range = packed.offsets[p] as usize..packed.offsets[p + 1] as usize;
                let slots: Vec<usize> = (adj.range(p))
                    .filter(|&slot| strengths.contains_key(&(adj.spring[slot] as usize)))
                    .collect();
                assert_eq!(range.len(), slots.len(), "particle {p}");
                for (end, slot) in packed.ends[range].iter().zip(slots) {
                    let e = adj.spring[slot] as usize;
                    let class = (end.other % MAX_CLASSES as u32) as usize;
                    used.insert(class);
                    assert_eq!(end.other >> CLASS_BITS, adj.other[slot]);
                    assert_eq!(end.rest, model.springs.rest[e]);
                    let [k, c, ..] = table[class];
                    assert_eq!((k, c), strengths[&e], "spring {e}");
                }
            }
            assert_eq!(used.len(), classes, "one class per kind sent: {used:?}");
        }
    }

    /// The packed ends of `scene`'s springs as the GPU gets them.
    fn packed(scene: &crate::scene::Scene) -> PackedSprings {
        let (key, _) = classify(&scene.params.material, &scene.effects);
        pack_springs(&scene.model, &key)
    }

    /// The bench cloth is a grid of 12 links (structural, shear, skip-one bends), its rows
    /// N particles wide; the flag (dihedral bending: no bend springs sent) one of 8 links,
    /// 31 wide; five cloths stacked one after another are not one grid (no springs between
    /// them), nor is the bench cloth with one spring end gone.
    #[test]
    fn a_grid_cloth_is_found_with_its_links_and_nothing_else_is() {
        let options = crate::mesh::ImportOptions::default();
        let bench = crate::scene::Scene::open_resized("hanging-bench", None, &options, Some(15))
            .expect("scene");
        let ends = packed(&bench);
        let grid = grid_of(&ends, 256).expect("the bench cloth is a grid");
        assert_eq!((grid.width, grid.height, grid.links.len()), (16, 16, 12));
        let offsets: Vec<(i32, i32)> = grid.links.iter().map(|l| (l.di, l.dj)).collect();
        for o in [(1, 0), (0, 1), (1, 1), (-1, 1), (2, 0), (0, 2)] {
            assert!(
                offsets.contains(&o) && offsets.contains(&(-o.0, -o.1)),
                "{o:?}"
            );
        }
        let flag = crate::scene::Scene::builtin("flag").expect("scene");
        let grid = grid_of(&packed(&flag), flag.model.particle_count()).expect("a grid");
        assert_eq!((grid.width, grid.height, grid.links.len()), (31, 21, 8));
        let layers = crate::scene::Scene::builtin("layers").expect("scene");
        assert_eq!(
            grid_of(&packed(&layers), layers.model.particle_count()),
            None
        );
        let mut gone = ends.clone();
        let p = 16 * 8 + 8;
        gone.ends.remove(gone.offsets[p] as usize);
        gone.offsets[p + 1..].iter_mut().for_each(|o| *o -= 1);
        assert_eq!(grid_of(&gone, 256), None);
    }
}
