//! The broad phase: a bounding-volume tree over the cloth's triangles, built once per
//! cloth from where its triangles lie at rest (halved at the median of their centres,
//! level by level: [`split_triangles_at_medians`]), so that each node holds a patch of
//! the cloth that stays together however it folds. Every search fits the boxes to the positions as
//! they are (the tree's shape never changes) and walks the tree against itself: two nodes
//! that keep apart are passed by with everything under them.
//!
//! Where the pairs are judged by the motion, a node holds two boxes — its particles'
//! starts and ends — and two nodes are told apart where one's boxes lie `reach` beyond the
//! other's along one axis, in the same direction, at both ends ([`moving_apart`]; why
//! that holds all along: [`super::gap`]). Where the cloth lands, its parts move fast against the
//! cloth's mean but hardly against each other: two patches' gaps hardly change. Two
//! leaves' triangles, four at a time, are told apart more cheaply: by the box of each
//! one's starts and ends in the frame that moves with the two leaves' motion
//! ([`TriangleTree::frame`]), each leaf's boxes carried into it once for its four rows.

use std::sync::atomic::{AtomicU32, Ordering};

use glam::{Vec3, Vec3A};

use self::lanes::{Corners, Lanes, One, share_none};
use super::gap::gap_at_both_ends;
use crate::parallel::{Disjoint, PARALLEL_ELEMENTS, Team};
use crate::sim::obstacle::{Split, split_triangles_at_medians};

mod lanes;

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
    /// By their particles' motion: apart where the boxes of their starts, and those of
    /// their ends, are `reach` apart along one axis in the same direction.
    Motion { reach: f32 },
}

/// The tree and the boxes its last fit gave it: the nodes', and the triangles' side by side
/// in their leaves.
#[derive(Clone, Debug, Default)]
pub(super) struct TriangleTree {
    nodes: Vec<Split>,
    /// Each leaf's node, and each node's leaf ([`NOT_A_LEAF`] for the others); the leaf of
    /// each place in the tree's order.
    leaves: Vec<u32>,
    leaf_of: Vec<u32>,
    leaf_at: Vec<u32>,
    /// Each leaf's triangles' corners, side by side: two triangles that share one are
    /// passed by without a test of their boxes.
    leaf_corners: Vec<Corners>,
    /// The triangles in the tree's order, and each triangle's place in it.
    order: Vec<u32>,
    place_of: Vec<u32>,
    /// The pieces a search is cut into.
    tasks: Vec<Task>,
    /// The nodes and the leaves of each subtree whose root holds at most
    /// [`TRIANGLES_PER_PIECE`] triangles and its parent more, as ranges in the tree's
    /// order: fitted, and its patches decided ([`super::patches`]), in pieces shared with
    /// the team.
    pub(super) subtrees: Vec<(std::ops::Range<usize>, std::ops::Range<usize>)>,
    /// Each node's box (by boxes), or the box of its starts (by motion), as `[lo, hi]`.
    boxes: Vec<[Vec3A; 2]>,
    /// By motion, each node's box of its ends, as `[lo, hi]`.
    motion: Vec<[Vec3A; 2]>,
    /// Each leaf's triangles' boxes.
    lanes: Vec<Lanes>,
    fit: Fit,
    /// Whether each node's own pairs are certified apart for the motion of the last fit
    /// (see [`super::patches`]): a whole walk passes by a node against itself then.
    pub(super) covered: Vec<bool>,
    /// Each node's parent (the root's: [`NO_PARENT`]).
    parent: Vec<u32>,
    /// Scratch of a fit of some triangles: the nodes that hold one, as flags (all clear
    /// between fits) and as a list.
    stale: Vec<bool>,
    stale_nodes: Vec<u32>,
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
        let (mut leaves, mut leaf_of) = (Vec::new(), vec![NOT_A_LEAF; nodes.len()]);
        let mut parent = vec![NO_PARENT; nodes.len()];
        let (mut leaf_at, mut leaf_corners) = (vec![0; order.len()], Vec::new());
        for (i, &node) in nodes.iter().enumerate() {
            if !Self::is_leaf(node) {
                (parent[i + 1], parent[node.second as usize]) = (i as u32, i as u32);
            }
            if Self::is_leaf(node) {
                leaf_of[i] = leaves.len() as u32;
                // Lanes past the leaf's triangles hold no particle's number.
                let mut lanes = [[u32::MAX; 4]; 3];
                for (k, place) in (node.first..node.first + node.count).enumerate() {
                    leaf_at[place as usize] = leaves.len() as u32;
                    let corners = triangles[order[place as usize] as usize];
                    for (lane, corner) in lanes.iter_mut().zip(corners) {
                        lane[k] = corner;
                    }
                }
                leaves.push(i as u32);
                leaf_corners.push(lanes);
            }
        }
        let nodes_len = nodes.len();
        let mut tree = TriangleTree {
            nodes,
            leaves,
            leaf_of,
            leaf_at,
            leaf_corners,
            order,
            place_of,
            stale: vec![false; nodes_len],
            parent,
            ..TriangleTree::default()
        };
        if !tree.nodes.is_empty() {
            tree.cut(0);
        }
        // In the tree's order a subtree's nodes follow its root, up to its last leaf, the
        // end of the chain of second children; its leaves are numbered in that order too.
        let mut i = 0;
        while i < tree.nodes.len() {
            if tree.nodes[i].count > TRIANGLES_PER_PIECE {
                i += 1;
                continue;
            }
            let mut last = i;
            while !Self::is_leaf(tree.nodes[last]) {
                last = tree.nodes[last].second as usize;
            }
            let below = |end: usize| tree.leaves.partition_point(|&n| (n as usize) < end);
            tree.subtrees.push((i..last + 1, below(i)..below(last + 1)));
            i = last + 1;
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

    /// Triangle `t`'s place in the tree's order.
    pub(super) fn place(&self, t: u32) -> u32 {
        self.place_of[t as usize]
    }

    /// The triangles node `i` holds.
    pub(super) fn held(&self, i: usize) -> &[u32] {
        let node = self.nodes[i];
        &self.order[node.first as usize..(node.first + node.count) as usize]
    }

    fn is_leaf(node: Split) -> bool {
        node.count as usize <= LEAF
    }

    /// Sizes the boxes for nodes and leaves.
    fn size(&mut self) {
        let n = self.nodes.len();
        self.boxes.resize(n, [Vec3A::ZERO; 2]);
        self.motion.resize(n, [Vec3A::ZERO; 2]);
        self.lanes.resize(self.leaves.len(), Lanes::default());
    }

    /// Lists node `i` and the nodes above it that are not yet (a leaf whose lanes changed).
    fn make_stale(&mut self, mut i: u32) {
        while i != NO_PARENT && !std::mem::replace(&mut self.stale[i as usize], true) {
            self.stale_nodes.push(i);
            i = self.parent[i as usize];
        }
    }

    /// Fits the nodes listed stale, from the last node back (children come after their
    /// parents), and clears the list.
    fn fit_stale(&mut self, moving: bool) {
        let fitting = Fitting {
            nodes: &self.nodes,
            leaf_of: &self.leaf_of,
            moving,
        };
        self.stale_nodes.sort_unstable_by(|a, b| b.cmp(a));
        for &i in &self.stale_nodes {
            let i = i as usize;
            fitting.node(i, (&mut self.boxes, &mut self.motion, 0), (&self.lanes, 0));
            self.stale[i] = false;
        }
        self.stale_nodes.clear();
    }

    /// Sets every leaf's lanes by `set(lanes, lane, triangle, corners)`, for each of its
    /// triangles, and fits every node's boxes around its parts', subtree by subtree
    /// (shared with the team for a large cloth), then the nodes above them. Returns the
    /// largest `set` returned.
    fn fit_all(&mut self, moving: bool, set: impl SetLane) -> f32 {
        self.size();
        // The largest as bits: non-negative floats order as their bits do.
        let largest = AtomicU32::new(0);
        let fitting = Fitting {
            nodes: &self.nodes,
            leaf_of: &self.leaf_of,
            moving,
        };
        let (lanes, boxes, motion) = (
            Disjoint::new(&mut self.lanes),
            Disjoint::new(&mut self.boxes),
            Disjoint::new(&mut self.motion),
        );
        let (leaves, corners, order) = (&self.leaves, &self.leaf_corners, &self.order);
        let subtrees = &self.subtrees;
        let work = |_: usize, piece: usize| {
            let (at, held) = subtrees[piece].clone();
            // SAFETY: the subtrees' nodes, and their leaves, are disjoint.
            let (lanes, boxes, motion) = unsafe {
                (
                    lanes.part(held.clone()),
                    boxes.part(at.clone()),
                    motion.part(at.clone()),
                )
            };
            let mut most = 0.0f32;
            for (leaf, lanes) in held.clone().zip(lanes.iter_mut()) {
                let node = fitting.nodes[leaves[leaf] as usize];
                let held = &order[node.first as usize..(node.first + node.count) as usize];
                most = most.max(set(lanes, held, &corners[leaf]));
            }
            for i in at.clone().rev() {
                fitting.node(i, (boxes, motion, at.start), (lanes, held.start));
            }
            largest.fetch_max(most.to_bits(), Ordering::Relaxed);
        };
        let parallel = order.len() >= PARALLEL_ELEMENTS;
        Team::current().run_large_pieces_if(parallel, subtrees.len(), &work);
        let above = (0..fitting.nodes.len()).rev();
        for i in above.filter(|&i| fitting.nodes[i].count > TRIANGLES_PER_PIECE) {
            fitting.node(i, (&mut self.boxes, &mut self.motion, 0), (&self.lanes, 0));
        }
        f32::from_bits(largest.into_inner())
    }

    /// Fits the tree to the triangles' boxes `lo..hi`.
    pub(super) fn fit_boxes(&mut self, lo: &[Vec3], hi: &[Vec3]) {
        self.fit_all(false, |lanes, held, _| {
            for (lane, &t) in held.iter().enumerate() {
                let t = t as usize;
                lanes.set_box(lane, [lo[t].into(), hi[t].into()]);
            }
            0.0
        });
        self.fit = Fit::Boxes;
    }

    /// [`TriangleTree::fit_boxes`] where only the boxes of the triangles `changed` differ
    /// from the last fit's: only those and the nodes above them are fitted again (the whole
    /// tree where the last fit was not by boxes).
    pub(super) fn refit_boxes(&mut self, changed: &[u32], lo: &[Vec3], hi: &[Vec3]) {
        if self.fit != Fit::Boxes || self.boxes.len() != self.nodes.len() {
            return self.fit_boxes(lo, hi);
        }
        self.fit_some(changed, false, |lanes, lane, t, _| {
            lanes.set_box(lane, [lo[t].into(), hi[t].into()]);
            0.0
        });
    }

    /// Fits the tree to the motion of its triangles' particles from `from` to `to`, told
    /// apart by `reach` (see [`Fit::Motion`]). Returns the widest any triangle's particles
    /// span along an axis over the motion.
    pub(super) fn fit_motion(&mut self, [from, to]: [&[Vec3A]; 2], reach: f32) -> f32 {
        let widest = self.fit_all(true, |lanes, held, corners| {
            lanes.set_leaf(corners, held.len(), [from, to])
        });
        self.fit = Fit::Motion { reach };
        widest
    }

    /// [`TriangleTree::fit_motion`] where only the motion of the triangles `changed`
    /// differs from the last fit's: only those and the nodes above them are fitted again
    /// (the whole tree where the last fit was not by the motion for `reach`). Returns the
    /// widest those triangles' particles span along an axis over the motion.
    pub(super) fn refit_motion(
        &mut self,
        changed: &[u32],
        [from, to]: [&[Vec3A]; 2],
        reach: f32,
    ) -> f32 {
        if self.fit != (Fit::Motion { reach }) || self.motion.len() != self.nodes.len() {
            return self.fit_motion([from, to], reach);
        }
        self.fit_some(changed, true, |lanes, lane, _, corners| {
            set_motion(lanes, lane, One::of(corners, [from, to]))
        })
    }

    /// Sets the lanes of the triangles `changed` by `set` (as [`TriangleTree::fit_all`]
    /// sets every triangle's) and fits the nodes that hold them. Returns the largest `set`
    /// returned.
    fn fit_some(
        &mut self,
        changed: &[u32],
        moving: bool,
        set: impl Fn(&mut Lanes, usize, usize, [u32; 3]) -> f32,
    ) -> f32 {
        let mut most = 0.0f32;
        for &t in changed {
            let (leaf, lane) = self.lane(self.place_of[t as usize] as usize);
            let corners = self.corners(leaf, lane);
            most = most.max(set(&mut self.lanes[leaf], lane, t as usize, corners));
            self.make_stale(self.leaves[leaf]);
        }
        self.fit_stale(moving);
        most
    }

    /// Whether nodes `a` and `b`'s boxes do not overlap.
    #[inline(always)]
    fn boxes_apart(&self, a: usize, b: usize) -> bool {
        boxes_apart(self.boxes[a], self.boxes[b])
    }

    /// Whether nodes `a` and `b` keep `reach` apart along their motion.
    #[inline(always)]
    fn moving_apart(&self, a: usize, b: usize, reach: f32) -> bool {
        let (a, b) = (
            (self.boxes[a], self.motion[a]),
            (self.boxes[b], self.motion[b]),
        );
        moving_apart(a, b, reach)
    }

    /// The frame in which two leaves' triangles are told apart by the motion (nodes `a`
    /// and `b`): their mean motion as the centres of their boxes of starts and ends
    /// measure it. Any frame keeps the test (a translation changes no distance); theirs
    /// keeps two leaves that move together from meeting in their boxes, and costs no
    /// mean motion fitted.
    #[inline(always)]
    fn frame(&self, a: usize, b: usize) -> Vec3A {
        let moved = |n: usize| {
            let ([lo, hi], [end_lo, end_hi]) = (self.boxes[n], self.motion[n]);
            (end_lo + end_hi) - (lo + hi)
        };
        0.25 * (moved(a) + moved(b))
    }

    /// The leaf and lane of the triangle at `place` in the tree's order.
    fn lane(&self, place: usize) -> (usize, usize) {
        let leaf = self.leaf_at[place] as usize;
        (
            leaf,
            place - self.nodes[self.leaves[leaf] as usize].first as usize,
        )
    }

    /// The corners of lane `lane`'s triangle of leaf `leaf`.
    #[inline(always)]
    fn corners(&self, leaf: usize, lane: usize) -> [u32; 3] {
        let [a, b, c] = &self.leaf_corners[leaf];
        [a[lane], b[lane], c[lane]]
    }

    /// Pieces a search of the whole tree is cut into, for a team to share.
    pub(super) fn pieces(&self) -> usize {
        self.tasks.len()
    }

    /// Calls `pair(a, b)` for each two triangles that share no corner, that the walk of
    /// piece `piece` does not tell apart (as the last fit tells them) and that no covered
    /// node holds both of; the pieces together call it once for every such two.
    #[inline(never)]
    pub(super) fn piece_pairs(&self, piece: usize, pair: impl FnMut(u32, u32)) {
        // One walk for each fit, each with its tests inlined.
        match self.fit {
            Fit::Motion { reach } => self.walk(
                piece,
                |a, b| self.moving_apart(a, b, reach),
                |[a, b], [la, lb]| {
                    let m = self.frame(a, b);
                    self.lanes[lb].moving_near_rows(&self.lanes[la], m, reach)
                },
                pair,
            ),
            Fit::Boxes => self.walk(
                piece,
                |a, b| self.boxes_apart(a, b),
                |_, [la, lb]| self.lanes[lb].boxes_meet_rows(&self.lanes[la]),
                pair,
            ),
        }
    }

    /// Calls `pair(t, b)` for each triangle `b` sharing no corner with `t` that `t`'s box
    /// is not told apart from (as the last fit tells them), not flagged by `searched`
    /// where `b < t`: a search of each flagged triangle so calls it once for each two of
    /// which one at least is flagged. By the boxes, the whole walk's tests of theirs and
    /// these tell the same two apart; by the motion, `t` is told apart from each node by
    /// its own boxes rather than from the node the whole walk pairs with it, and the
    /// leaves' rows (in the two leaves' frame, as the whole walk's) are not the nodes'
    /// test, so it may pass by a few pairs more, each of which keeps the reach apart.
    #[inline(never)]
    pub(super) fn triangle_pairs(&self, t: u32, searched: &[bool], pair: impl FnMut(u32, u32)) {
        match self.fit {
            Fit::Motion { reach } => self.query(
                t,
                searched,
                |a, one| {
                    let own = ([one.lo, one.hi], [one.end_lo, one.end_hi]);
                    moving_apart((self.boxes[a], self.motion[a]), own, reach)
                },
                |[a, b], lanes, one| lanes.moving_near(one, self.frame(a, b), reach),
                pair,
            ),
            Fit::Boxes => self.query(
                t,
                searched,
                |a, one| boxes_apart(self.boxes[a], [one.lo, one.hi]),
                |_, lanes, one| lanes.boxes_meet(one),
                pair,
            ),
        }
    }

    #[inline(always)]
    fn query(
        &self,
        t: u32,
        searched: &[bool],
        apart: impl Fn(usize, &One) -> bool,
        lanes_near: impl Fn([usize; 2], &Lanes, (&Lanes, usize)) -> u32,
        mut pair: impl FnMut(u32, u32),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let place = self.place_of[t as usize] as usize;
        let (leaf, k) = self.lane(place);
        let (lane, corners) = ((&self.lanes[leaf], k), self.corners(leaf, k));
        let (one, own) = (self.lanes[leaf].one(k), self.leaves[leaf] as usize);
        // As in the whole walk, a node goes on the stack only where it is not told apart.
        let mut stack = [0u32; STACK];
        let mut depth = 0;
        let push = |stack: &mut [u32; STACK], depth: &mut usize, a: u32| {
            stack[*depth] = a;
            *depth += usize::from(!apart(a as usize, &one));
        };
        push(&mut stack, &mut depth, 0);
        while depth > 0 {
            depth -= 1;
            let a = stack[depth];
            let node = self.nodes[a as usize];
            if Self::is_leaf(node) {
                let leaf = self.leaf_of[a as usize] as usize;
                let near = lanes_near([own, a as usize], &self.lanes[leaf], lane)
                    & share_none(corners, &self.leaf_corners[leaf]);
                for k in flagged(near & lanes_of(node)) {
                    let b = self.order[node.first as usize + k];
                    if b != t && !(b < t && searched[b as usize]) {
                        pair(t, b);
                    }
                }
            } else {
                push(&mut stack, &mut depth, node.second);
                push(&mut stack, &mut depth, a + 1);
            }
        }
    }

    #[inline(always)]
    fn walk(
        &self,
        piece: usize,
        apart: impl Fn(usize, usize) -> bool,
        lanes_near: impl Fn([usize; 2], [usize; 2]) -> [u32; 4],
        mut pair: impl FnMut(u32, u32),
    ) {
        // Each triangle of leaf node `a` against those of leaf node `b` (past its own,
        // where they are the same). The rows that hold a pair are flagged first, without a
        // branch a row (most hold none).
        let mut leaves = |a: usize, b: usize| {
            let (na, nb) = (self.nodes[a], self.nodes[b]);
            let (la, lb) = (self.leaf_of[a] as usize, self.leaf_of[b] as usize);
            let corners = &self.leaf_corners[lb];
            let mut rows = lanes_near([a, b], [la, lb]);
            let (lanes, same) = (lanes_of(nb), a == b);
            let mut held = 0;
            for (k, row) in rows.iter_mut().enumerate() {
                // Past its own, where the leaves are the same.
                let own = if same { (2 << k) - 1 } else { 0 };
                *row &= lanes & !own;
                held |= u32::from(*row != 0) << k;
            }
            for k in flagged(held & lanes_of(na)) {
                let p = na.first as usize + k;
                let near = share_none(self.corners(la, k), corners) & rows[k];
                for q in flagged(near) {
                    pair(self.order[p], self.order[nb.first as usize + q]);
                }
            }
        };
        // Only two nodes not told apart go on the stack: each two is tested as it is put
        // there, and the slot is kept only where the test fails, so no branch hangs on
        // the test (callgrind's branch model mispredicted that branch about every third
        // time); a node against itself goes on only where it is not covered.
        let open = |a: u32, b: u32| {
            if a == b {
                !self.covered.get(a as usize).copied().unwrap_or(false)
            } else {
                !apart(a as usize, b as usize)
            }
        };
        let mut stack = [(0u32, 0u32); STACK];
        let mut depth = 0;
        let push = |stack: &mut [Task; STACK], depth: &mut usize, (a, b): Task| {
            stack[*depth] = (a, b);
            *depth += usize::from(open(a, b));
        };
        push(&mut stack, &mut depth, self.tasks[piece]);
        while depth > 0 {
            depth -= 1;
            let (a, b) = stack[depth];
            let (na, nb) = (self.nodes[a as usize], self.nodes[b as usize]);
            if a == b {
                if Self::is_leaf(na) {
                    leaves(a as usize, a as usize);
                } else {
                    let (first, second) = (a + 1, na.second);
                    for task in [(first, second), (second, second), (first, first)] {
                        push(&mut stack, &mut depth, task);
                    }
                }
                continue;
            }
            match (Self::is_leaf(na), Self::is_leaf(nb)) {
                (true, true) => leaves(a as usize, b as usize),
                // The larger is split.
                (false, _) if na.count >= nb.count || Self::is_leaf(nb) => {
                    push(&mut stack, &mut depth, (na.second, b));
                    push(&mut stack, &mut depth, (a + 1, b));
                }
                _ => {
                    push(&mut stack, &mut depth, (a, nb.second));
                    push(&mut stack, &mut depth, (a, b + 1));
                }
            }
        }
    }
}

/// The lanes flagged in the bits of `flags`, in order.
#[inline(always)]
fn flagged(flags: u32) -> impl Iterator<Item = usize> {
    let mut left = flags;
    std::iter::from_fn(move || {
        let lane = left.trailing_zeros() as usize;
        left &= left.wrapping_sub(1);
        (lane < 32).then_some(lane)
    })
}

/// The lanes (as bits) that hold leaf `node`'s triangles.
#[inline(always)]
fn lanes_of(node: Split) -> u32 {
    (1 << node.count) - 1
}

/// Sets a leaf's lanes to the boxes of its triangles `held` (in the tree's order; their
/// corners `corners`, lane by lane); returns what the fit keeps the largest of (the widest
/// triangle by motion). (A trait of its own rather than a `dyn Fn`: each fit is compiled
/// with its own, inlined into the loop over the leaves.)
trait SetLane: Fn(&mut Lanes, &[u32], &Corners) -> f32 + Sync {}

impl<F: Fn(&mut Lanes, &[u32], &Corners) -> f32 + Sync> SetLane for F {}

/// Sets lane `lane` to a triangle's boxes by motion `one`; returns the widest its particles
/// span along an axis over the motion.
fn set_motion(lanes: &mut Lanes, lane: usize, one: One) -> f32 {
    lanes.set(lane, one);
    one.widest()
}

/// What fitting a node reads: the tree's nodes, each node's leaf, and whether by motion.
struct Fitting<'a> {
    nodes: &'a [Split],
    leaf_of: &'a [u32],
    moving: bool,
}

impl Fitting<'_> {
    /// Fits node `i`'s boxes around its parts': a leaf's around its triangles', another's
    /// around its two children's (fitted before). `boxes` and `motion` hold the nodes from
    /// node `base` on, `lanes` the leaves from leaf `first` on.
    #[inline(always)]
    fn node(
        &self,
        i: usize,
        (boxes, motion, base): (&mut [[Vec3A; 2]], &mut [[Vec3A; 2]], usize),
        (lanes, first): (&[Lanes], usize),
    ) {
        let node = self.nodes[i];
        if TriangleTree::is_leaf(node) {
            let leaf = &lanes[self.leaf_of[i] as usize - first];
            let (fitted, moved) = leaf.bounds(node.count as usize, self.moving);
            boxes[i - base] = fitted;
            if self.moving {
                motion[i - base] = moved;
            }
            return;
        }
        let parts = [i + 1, node.second as usize];
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for &k in &parts {
            let [l, h] = boxes[k - base];
            (lo, hi) = (lo.min(l), hi.max(h));
        }
        boxes[i - base] = [lo, hi];
        if self.moving {
            let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            for &k in &parts {
                let [l, h] = motion[k - base];
                (lo, hi) = (lo.min(l), hi.max(h));
            }
            motion[i - base] = [lo, hi];
        }
    }
}

/// A node that is not a leaf, in [`TriangleTree`]'s `leaf_of`.
const NOT_A_LEAF: u32 = u32::MAX;

/// The root's parent.
const NO_PARENT: u32 = u32::MAX;

/// Whether two boxes `[lo, hi]` do not overlap.
#[inline(always)]
fn boxes_apart([alo, ahi]: [Vec3A; 2], [blo, bhi]: [Vec3A; 2]) -> bool {
    !(alo.cmple(bhi).all() && blo.cmple(ahi).all())
}

/// Whether two boxes by motion (`[lo, hi]` of the starts and of the ends) keep `reach`
/// apart along their motion: where along one axis, in the same direction, the starts' boxes
/// lie `reach` apart and so do the ends' ([`super::gap`]). (The box of a node's starts and
/// ends in one frame takes in the node's motion against that frame: where two nodes move
/// alike with it the two tests agree, but where a node turns or stretches along the
/// motion, or moves otherwise than the frame, that box grows and this test does not.)
#[inline(always)]
fn moving_apart(
    (a, a_end): ([Vec3A; 2], [Vec3A; 2]),
    (b, b_end): ([Vec3A; 2], [Vec3A; 2]),
    reach: f32,
) -> bool {
    gap_at_both_ends([a, b], [a_end, b_end]).max_element() >= reach
}

#[cfg(test)]
mod tests;
