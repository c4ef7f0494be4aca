//! The broad phase: a bounding-volume tree over the cloth's triangles, built once per
//! cloth from where its triangles lie at rest (halved at the median of their centres,
//! level by level: [`split_triangles_at_medians`]), so that each node holds a patch of
//! the cloth that stays together however it folds. Every search fits the boxes to the positions as
//! they are (the tree's shape never changes) and walks the tree against itself: two nodes
//! that keep apart are passed by with everything under them.
//!
//! Where the pairs are judged by the motion, a node holds two boxes — its particles'
//! starts and ends — and their mean motion, and two nodes are told apart in the frame that
//! moves with their mean motion: there each node stays in the box of its starts and its
//! ends less that motion (each particle's path runs between them), and a translation
//! changes no distance. Where the cloth lands, its parts move fast against the cloth's
//! mean but hardly against each other: in their own frame, two patches' boxes are hardly
//! larger than the patches.

use glam::{Vec3, Vec3A};

use crate::sim::obstacle::{Split, split_triangles_at_medians};

/// Triangles in a leaf at most: two leaves are tested triangle by triangle.
const LEAF: usize = 4;

/// A walk of the tree in one piece of a search: a node against itself (both the same) or
/// two nodes against each other.
type Task = (u32, u32);

/// A node of this many triangles or fewer is walked against itself in one piece of a
/// search.
pub(super) const TRIANGLES_PER_PIECE: u32 = 256;

/// The deepest walk: a balanced tree of 2³¹ triangles is 30 levels deep; a walk of two
/// nodes holds at most one task more for each level it goes down either, one of a node
/// against itself two more a level.
const STACK: usize = 128;

/// How a search tells two nodes, or two triangles, apart: as the last fit made them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Fit {
    /// By their boxes: apart where they do not overlap.
    #[default]
    Boxes,
    /// By their particles' motion: apart where, in the frame of their mean motion, the
    /// boxes of their starts and ends less that motion are `reach` apart along an axis.
    Motion { reach: f32 },
}

/// The tree and the boxes its last fit gave it. Its boxes are numbered nodes first, then
/// triangles in the tree's order.
#[derive(Clone, Debug, Default)]
pub(super) struct TriangleTree {
    nodes: Vec<Split>,
    /// The triangles in the tree's order, and each triangle's place in it.
    order: Vec<u32>,
    place_of: Vec<u32>,
    /// Each place's triangle's corners: two that share one are passed by without a test
    /// of their boxes (read in the tree's order, where a walk reads them).
    corners: Vec<[u32; 3]>,
    /// The pieces a search is cut into.
    tasks: Vec<Task>,
    /// Each one's box (by boxes), or the box of its starts (by motion), as `[lo, hi]`.
    boxes: Vec<[Vec3A; 2]>,
    /// By motion, each one's box of its ends and its mean motion, as `[lo, hi, mean]`.
    motion: Vec<[Vec3A; 3]>,
    fit: Fit,
    /// Whether each node's own pairs are certified apart for the motion of the last fit
    /// (see [`super::patches`]): a whole walk passes by a node against itself then.
    pub(super) covered: Vec<bool>,
}

impl TriangleTree {
    /// The tree over `triangles`, from the particles' `rest` positions (balanced: its
    /// depth is that of a complete tree).
    pub(super) fn build(triangles: &[[u32; 3]], rest: &[Vec3]) -> TriangleTree {
        let (nodes, order) = split_triangles_at_medians(triangles, rest, LEAF);
        let mut place_of = vec![0; order.len()];
        for (place, &t) in order.iter().enumerate() {
            place_of[t as usize] = place as u32;
        }
        let corners = order.iter().map(|&t| triangles[t as usize]).collect();
        let mut tree = TriangleTree {
            nodes,
            order,
            place_of,
            corners,
            ..TriangleTree::default()
        };
        if !tree.nodes.is_empty() {
            tree.cut(0);
        }
        tree
    }

    /// Adds the pieces of a walk of node `a` against itself to the tasks.
    fn cut(&mut self, a: u32) {
        let node = self.nodes[a as usize];
        if node.count <= TRIANGLES_PER_PIECE {
            self.tasks.push((a, a));
            return;
        }
        let (first, second) = (a + 1, node.second);
        self.cut(first);
        self.cut(second);
        self.tasks.push((first, second));
    }

    /// Triangles the tree was built for.
    pub(super) fn triangles(&self) -> usize {
        self.order.len()
    }

    /// The nodes, each parent before its children (the first right after it).
    pub(super) fn nodes(&self) -> &[Split] {
        &self.nodes
    }

    /// The triangles node `i` holds.
    pub(super) fn held(&self, i: usize) -> &[u32] {
        let node = self.nodes[i];
        &self.order[node.first as usize..(node.first + node.count) as usize]
    }

    fn is_leaf(node: Split) -> bool {
        node.count as usize <= LEAF
    }

    /// The box number of the triangle at `place` in the tree's order.
    fn place(&self, place: u32) -> usize {
        self.nodes.len() + place as usize
    }

    /// The boxes node `i` is fitted around: its children's, or its triangles'.
    fn parts(&self, i: usize) -> ([usize; LEAF], usize) {
        let node = self.nodes[i];
        let mut parts = [0; LEAF];
        if Self::is_leaf(node) {
            let first = self.place(node.first);
            for (k, part) in parts.iter_mut().enumerate().take(node.count as usize) {
                *part = first + k;
            }
            (parts, node.count as usize)
        } else {
            (parts[0], parts[1]) = (i + 1, node.second as usize);
            (parts, 2)
        }
    }

    /// Sizes the boxes for nodes and triangles.
    fn size(&mut self) {
        let n = self.nodes.len() + self.order.len();
        self.boxes.resize(n, [Vec3A::ZERO; 2]);
        self.motion.resize(n, [Vec3A::ZERO; 3]);
    }

    /// Fits the nodes' boxes around their parts', from the last node back (children come
    /// after their parents).
    fn fit_nodes(&mut self, moving: bool) {
        for i in (0..self.nodes.len()).rev() {
            let (parts, n) = self.parts(i);
            let parts = &parts[..n];
            let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            for &k in parts {
                let [l, h] = self.boxes[k];
                (lo, hi) = (lo.min(l), hi.max(h));
            }
            self.boxes[i] = [lo, hi];
            if moving {
                let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
                // The mean weighted by the triangles each part holds.
                let (mut sum, mut total) = (Vec3A::ZERO, 0.0);
                for &k in parts {
                    let [l, h, mean] = self.motion[k];
                    (lo, hi) = (lo.min(l), hi.max(h));
                    let weight = self.nodes.get(k).map_or(1.0, |n| n.count as f32);
                    (sum, total) = (sum + mean * weight, total + weight);
                }
                self.motion[i] = [lo, hi, sum / total];
            }
        }
    }

    /// Fits the tree to the triangles' boxes `lo..hi`.
    pub(super) fn fit_boxes(&mut self, lo: &[Vec3], hi: &[Vec3]) {
        self.size();
        let first = self.nodes.len();
        for (place, &t) in self.order.iter().enumerate() {
            self.boxes[first + place] = [lo[t as usize].into(), hi[t as usize].into()];
        }
        self.fit_nodes(false);
        self.fit = Fit::Boxes;
    }

    /// Fits the tree to the motion of its triangles' particles from `from` to `to`, told
    /// apart by `reach` (see [`Fit::Motion`]).
    pub(super) fn fit_motion(&mut self, [from, to]: [&[Vec3]; 2], reach: f32) {
        self.size();
        let first = self.nodes.len();
        for (place, &corners) in self.corners.iter().enumerate() {
            let [a, b, c] = corners.map(|k| Vec3A::from(from[k as usize]));
            let [d, e, f] = corners.map(|k| Vec3A::from(to[k as usize]));
            let i = first + place;
            self.boxes[i] = [a.min(b).min(c), a.max(b).max(c)];
            let mean = ((d - a) + (e - b) + (f - c)) / 3.0;
            self.motion[i] = [d.min(e).min(f), d.max(e).max(f), mean];
        }
        self.fit_nodes(true);
        self.fit = Fit::Motion { reach };
    }

    /// Whether boxes `a` and `b` do not overlap.
    #[inline(always)]
    fn boxes_apart(&self, a: usize, b: usize) -> bool {
        let ([alo, ahi], [blo, bhi]) = (self.boxes[a], self.boxes[b]);
        !(alo.cmple(bhi).all() && blo.cmple(ahi).all())
    }

    /// Whether `a` and `b` keep `reach` apart along their motion, told in the frame of
    /// their mean motion.
    #[inline(always)]
    fn moving_apart(&self, a: usize, b: usize, reach: f32) -> bool {
        let ([alo, ahi], [aend_lo, aend_hi, amean]) = (self.boxes[a], self.motion[a]);
        let ([blo, bhi], [bend_lo, bend_hi, bmean]) = (self.boxes[b], self.motion[b]);
        let m = 0.5 * (amean + bmean);
        let (alo, ahi) = (alo.min(aend_lo - m), ahi.max(aend_hi - m));
        let (blo, bhi) = (blo.min(bend_lo - m), bhi.max(bend_hi - m));
        (blo - ahi).max(alo - bhi).max_element() >= reach
    }

    /// Pieces a search of the whole tree is cut into, for a team to share.
    pub(super) fn pieces(&self) -> usize {
        self.tasks.len()
    }

    /// Calls `pair(a, b)` for each two triangles that share no corner, that the walk of
    /// piece `piece` does not tell apart (as the last fit tells them) and that no covered
    /// node holds both of; the pieces together call it once for every such two.
    pub(super) fn piece_pairs(&self, piece: usize, pair: impl FnMut(u32, u32)) {
        // One walk for each fit, each with its test inlined.
        match self.fit {
            Fit::Motion { reach } => {
                self.walk(piece, |a, b| self.moving_apart(a, b, reach), pair);
            }
            Fit::Boxes => self.walk(piece, |a, b| self.boxes_apart(a, b), pair),
        }
    }

    /// Calls `pair(t, b)` for each triangle `b` sharing no corner with `t` that `t`'s box
    /// is not told apart from (as the last fit tells them), not flagged by `searched`
    /// where `b < t`: a search of each flagged triangle so calls it once for each two of
    /// which one at least is flagged. By the boxes, the whole walk's tests of theirs and these tell the same
    /// two apart; by the motion, `t` is told apart from each node in their own frame
    /// rather than from the node the whole walk pairs with it.
    pub(super) fn triangle_pairs(&self, t: u32, searched: &[bool], pair: impl FnMut(u32, u32)) {
        match self.fit {
            Fit::Motion { reach } => {
                self.query(t, searched, |a, b| self.moving_apart(a, b, reach), pair);
            }
            Fit::Boxes => self.query(t, searched, |a, b| self.boxes_apart(a, b), pair),
        }
    }

    #[inline(always)]
    fn query(
        &self,
        t: u32,
        searched: &[bool],
        apart: impl Fn(usize, usize) -> bool,
        mut pair: impl FnMut(u32, u32),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let x = self.place(self.place_of[t as usize]);
        let corners = self.corners[self.place_of[t as usize] as usize];
        let mut stack = [0u32; STACK];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let a = stack[depth];
            if apart(a as usize, x) {
                continue;
            }
            let node = self.nodes[a as usize];
            if Self::is_leaf(node) {
                for q in node.first..node.first + node.count {
                    let b = self.order[q as usize];
                    let once = b != t && !(b < t && searched[b as usize]);
                    let near = !share_a_corner(self.corners[q as usize], corners);
                    if once && near && !apart(self.place(q), x) {
                        pair(t, b);
                    }
                }
            } else {
                stack[depth..depth + 2].copy_from_slice(&[node.second, a + 1]);
                depth += 2;
            }
        }
    }

    #[inline(always)]
    fn walk(
        &self,
        piece: usize,
        apart: impl Fn(usize, usize) -> bool,
        mut pair: impl FnMut(u32, u32),
    ) {
        let first = self.nodes.len();
        // Two triangles, at places `p` and `q`.
        let mut places = |p: usize, q: usize| {
            if !share_a_corner(self.corners[p], self.corners[q]) && !apart(first + p, first + q) {
                pair(self.order[p], self.order[q]);
            }
        };
        let mut stack = [(0u32, 0u32); STACK];
        stack[0] = self.tasks[piece];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let (a, b) = stack[depth];
            let (na, nb) = (self.nodes[a as usize], self.nodes[b as usize]);
            if a == b {
                if self.covered.get(a as usize).copied().unwrap_or(false) {
                    continue;
                }
                if Self::is_leaf(na) {
                    let held = na.first as usize..(na.first + na.count) as usize;
                    for p in held.clone() {
                        for q in p + 1..held.end {
                            places(p, q);
                        }
                    }
                } else {
                    let (first, second) = (a + 1, na.second);
                    stack[depth..depth + 3].copy_from_slice(&[
                        (first, second),
                        (second, second),
                        (first, first),
                    ]);
                    depth += 3;
                }
                continue;
            }
            if apart(a as usize, b as usize) {
                continue;
            }
            match (Self::is_leaf(na), Self::is_leaf(nb)) {
                (true, true) => {
                    for p in na.first..na.first + na.count {
                        for q in nb.first..nb.first + nb.count {
                            places(p as usize, q as usize);
                        }
                    }
                }
                // The larger is split.
                (false, _) if na.count >= nb.count || Self::is_leaf(nb) => {
                    stack[depth..depth + 2].copy_from_slice(&[(na.second, b), (a + 1, b)]);
                    depth += 2;
                }
                _ => {
                    stack[depth..depth + 2].copy_from_slice(&[(a, nb.second), (a, b + 1)]);
                    depth += 2;
                }
            }
        }
    }
}

/// Whether two triangles share a corner.
#[inline(always)]
fn share_a_corner(a: [u32; 3], b: [u32; 3]) -> bool {
    a.iter().any(|i| b.contains(i))
}

#[cfg(test)]
mod tests;
