//! The cloth's triangles in patches, for the solids' face passes: a pass that keeps the
//! triangles' interiors out of a solid tests each patch's box first, and only the
//! triangles of the patches near the solid one by one. The patches are cut once per cloth
//! from where its triangles lie at rest (halved at the medians of their centres, as the
//! trees are), so each is a piece of cloth that stays together however it folds and its
//! box stays small. The triangles near come in the order of their colours (greedy, by the
//! particles they share: [`colour_greedily`]), the order in which the GPU's face pass
//! takes them, a dispatch a colour.

use glam::{Vec3, Vec3A};

use crate::cloth::{ClothModel, colour_greedily};
use crate::sim::obstacle::split_triangles_at_medians;

/// Triangles in a patch at most (at least half as many, but for a cloth with fewer).
const PATCH: usize = 32;

/// The triangles near are sorted into the cloth's order while they are fewer than one in
/// this many of the cloth's; more, and every triangle is looked at in order.
const SORTED_BELOW: usize = 16;

/// The patches and the triangles a face pass takes (scratch: nothing is allocated once
/// warm).
#[derive(Clone, Debug, Default)]
pub struct FacePatches {
    /// The triangles, patch by patch; patch `k`'s are `triangles[starts[k]..starts[k + 1]]`.
    triangles: Vec<u32>,
    starts: Vec<usize>,
    /// The particles of each patch's triangles, each once a patch, cut as the triangles.
    particles: Vec<u32>,
    particle_starts: Vec<usize>,
    /// Each triangle's patch.
    patch_of: Vec<u32>,
    /// Whether each patch was near in the last call, and its box then.
    flagged: Vec<bool>,
    boxes: Vec<(Vec3A, Vec3A)>,
    /// The cloth they were cut for: its triangles and particles.
    cut_for: (usize, usize),
    /// The triangles colour after colour, and each triangle's place in that order.
    coloured: Vec<u32>,
    rank: Vec<u32>,
    /// The triangles of the patches the last call found near, in colour order.
    near: Vec<u32>,
}

impl FacePatches {
    /// Cuts the patches for `model` if they were cut for another cloth (a stepper serves
    /// one cloth: its size tells a new one apart); returns whether it cut them.
    pub fn prepare(&mut self, model: &ClothModel) -> bool {
        let size = (model.triangles.len(), model.particle_count());
        if size == self.cut_for && !self.starts.is_empty() {
            return false;
        }
        let (triangles, rest) = (&model.triangles, &model.rest_positions);
        let (nodes, order) = split_triangles_at_medians(triangles, rest, PATCH);
        *self = FacePatches {
            cut_for: size,
            patch_of: vec![0; triangles.len()],
            ..FacePatches::default()
        };
        (self.coloured, _) = colour_greedily(model.particle_count(), triangles.iter().copied());
        self.rank = vec![0; triangles.len()];
        for (k, &t) in self.coloured.iter().enumerate() {
            self.rank[t as usize] = k as u32;
        }
        let mut seen = vec![usize::MAX; model.particle_count()];
        self.starts.push(0);
        self.particle_starts.push(0);
        for (k, node) in (nodes.iter().filter(|n| n.count as usize <= PATCH)).enumerate() {
            let held = &order[node.first as usize..(node.first + node.count) as usize];
            for &t in held {
                self.triangles.push(t);
                self.patch_of[t as usize] = k as u32;
                for i in triangles[t as usize] {
                    if let Some(mark) = seen.get_mut(i as usize).filter(|m| **m != k) {
                        *mark = k;
                        self.particles.push(i);
                    }
                }
            }
            self.starts.push(self.triangles.len());
            self.particle_starts.push(self.particles.len());
        }
        true
    }

    /// The triangles, in colour order, of every patch whose particles at `pos` lie in a box
    /// for which `near(lo, hi)` holds: a triangle lies in the box of its corners, so one
    /// that a solid could touch is among them when `near` holds for every box the solid
    /// comes within its reach of.
    pub fn near(
        &mut self,
        model: &ClothModel,
        pos: &[Vec3],
        near: impl Fn(Vec3, Vec3) -> bool,
    ) -> &[u32] {
        self.flag(model, |i| Vec3A::from(pos[i as usize]), near);
        self.near.clear();
        let held: usize = (self.flagged.iter().enumerate())
            .filter(|(_, f)| **f)
            .map(|(k, _)| self.starts[k + 1] - self.starts[k])
            .sum();
        // In colour order: sorted where they are few, picked out of every triangle where
        // they are many (a cloth draped over a sphere: 2 000 of 8 192 at 64², whose sort
        // took a fifth of the pass).
        if held * SORTED_BELOW < self.patch_of.len() {
            for (k, _) in self.flagged.iter().enumerate().filter(|(_, f)| **f) {
                (self.near).extend_from_slice(&self.triangles[self.starts[k]..self.starts[k + 1]]);
            }
            let rank = &self.rank;
            self.near.sort_unstable_by_key(|&t| rank[t as usize]);
        } else {
            let (flagged, patch_of) = (&self.flagged, &self.patch_of);
            (self.near).extend(
                (self.coloured.iter().copied()).filter(|&t| flagged[patch_of[t as usize] as usize]),
            );
        }
        &self.near
    }

    /// Each patch [`FacePatches::flag`] flagged, patch by patch: its triangles and the box
    /// of its particles it was flagged for.
    pub fn flagged(&self) -> impl Iterator<Item = (&[u32], Vec3, Vec3)> {
        (self.flagged.iter().zip(&self.boxes).enumerate())
            .filter(|(_, (f, _))| **f)
            .map(|(k, (_, &(lo, hi)))| {
                let held = &self.triangles[self.starts[k]..self.starts[k + 1]];
                (held, lo.into(), hi.into())
            })
    }

    /// Flags each patch whose particles, each where `position` puts it (in another frame,
    /// say), lie in a box for which `near(lo, hi)` holds, and keeps each patch's box.
    pub fn flag(
        &mut self,
        model: &ClothModel,
        position: impl Fn(u32) -> Vec3A,
        near: impl Fn(Vec3, Vec3) -> bool,
    ) {
        self.prepare(model);
        self.flagged.clear();
        self.boxes.clear();
        for k in 0..self.starts.len() - 1 {
            let ids = &self.particles[self.particle_starts[k]..self.particle_starts[k + 1]];
            let (lo, hi) =
                (ids.iter()).fold((Vec3A::INFINITY, Vec3A::NEG_INFINITY), |(lo, hi), &i| {
                    let p = position(i);
                    (lo.min(p), hi.max(p))
                });
            self.flagged.push(near(lo.into(), hi.into()));
            self.boxes.push((lo, hi));
        }
    }
}

#[cfg(test)]
mod tests;
