//! How the GPU backend lays the cloth out for its shader: particles as two `vec4`s, spring
//! ends as 8-byte records with a strength class, the uniform parameters. Every vector is a
//! `vec4` (WGSL gives `vec3` arrays a 16-byte stride).

use bytemuck::{Pod, Zeroable};

use crate::cloth::ClothModel;
use crate::mesh::SpringKind;
use crate::sim::{BendingModel, Effect, Material};

/// Colliders the shader has room for.
pub(super) const MAX_COLLIDERS: usize = 4;

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
    pub(super) colliders: [GpuCollider; MAX_COLLIDERS],
}

/// The solids among `effects` as the shader reads them (the first [`MAX_COLLIDERS`]), and
/// how many there are. A plane's normal is made unit here.
pub(super) fn pack_solids(effects: &[Effect]) -> ([GpuCollider; MAX_COLLIDERS], u32) {
    let mut out = [GpuCollider::zeroed(); MAX_COLLIDERS];
    let solids = effects.iter().filter_map(|e| match e {
        Effect::Sphere(s) => Some(GpuCollider {
            info: [1.0, s.radius, s.friction, 0.0],
            a: s.center.extend(0.0).to_array(),
            b: s.spin.extend(0.0).to_array(),
        }),
        Effect::Plane(p) => Some(GpuCollider {
            info: [2.0, 0.0, p.friction, 0.0],
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
}
