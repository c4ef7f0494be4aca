//! A bounding-volume tree over an obstacle's triangles: the nearest triangle to a point
//! within a distance, and the first triangle a segment crosses, each in about `log n` box
//! tests. Built once for a rigid obstacle (its queries move into the obstacle's frame).

use glam::Vec3;

use super::geometry::{
    box_distance_squared, closest_on_triangle, segment_crosses, segment_meets_box,
};

/// Triangles per leaf at most.
const LEAF: usize = 4;

/// A box and what it holds: `count` triangles from `first` (a leaf), or two children, the
/// first right after it and the second at `first` (`count` 0).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    first: u32,
    count: u32,
}

/// The tree, with the triangles' corners in leaf order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleTree {
    nodes: Vec<Node>,
    /// Corners of each triangle, in the tree's order.
    corners: Vec<[Vec3; 3]>,
    /// The triangle each place holds, as numbered when the tree was built.
    index: Vec<u32>,
}

/// A triangle near a query point ([`TriangleTree::within`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Near {
    /// Where the tree keeps its corners ([`TriangleTree::place`]).
    pub place: u32,
    /// The triangle, as numbered when the tree was built.
    pub triangle: u32,
    /// Its point nearest to the query point, and how far that is.
    pub point: Vec3,
    pub distance: f32,
}

/// The nearest point of a surface to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// The triangle, as numbered when the tree was built.
    pub triangle: u32,
    pub point: Vec3,
    pub distance: f32,
}

impl TriangleTree {
    /// The tree over `triangles` (corners); degenerate triangles are kept (they are found
    /// by nothing they do not touch).
    pub fn new(triangles: &[[Vec3; 3]]) -> Self {
        let (splits, order) = split_at_medians(triangles.len(), LEAF, |t| {
            let [a, b, c] = triangles[t as usize];
            (a + b + c) / 3.0
        });
        // An inner node keeps its second child where a leaf keeps its first place.
        let nodes = (splits.iter())
            .map(|s| {
                let (first, count) = if s.count as usize > LEAF {
                    (s.second, 0)
                } else {
                    (s.first, s.count)
                };
                let (lo, hi) = (Vec3::ZERO, Vec3::ZERO);
                Node {
                    lo,
                    hi,
                    first,
                    count,
                }
            })
            .collect();
        let corners = order.iter().map(|&t| triangles[t as usize]).collect();
        let mut tree = Self {
            nodes,
            corners,
            index: order,
        };
        tree.fit();
        tree
    }

    /// Moves each triangle to `triangle(number)` (the same triangles, numbered as when it
    /// was built, with new corners) and refits every box around them, keeping the tree's
    /// shape: linear in the triangles and allocating nothing, for a surface that deforms
    /// (an OBJ sequence) every substep.
    pub fn refit(&mut self, triangle: impl Fn(usize) -> [Vec3; 3]) {
        for (corners, &t) in self.corners.iter_mut().zip(&self.index) {
            *corners = triangle(t as usize);
        }
        self.fit();
    }

    /// Fits every box around the triangles' corners as they are.
    fn fit(&mut self) {
        // Children come after their parent, so boxes fill in from the last node back.
        for at in (0..self.nodes.len()).rev() {
            let node = self.nodes[at];
            let (lo, hi) = if node.count > 0 {
                let held = &self.corners[node.first as usize..(node.first + node.count) as usize];
                held.iter().flatten().fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), &c| (lo.min(c), hi.max(c)),
                )
            } else {
                let (a, b) = (self.nodes[at + 1], self.nodes[node.first as usize]);
                (a.lo.min(b.lo), a.hi.max(b.hi))
            };
            self.nodes[at].lo = lo;
            self.nodes[at].hi = hi;
        }
    }

    /// Its nodes in order, as (box low corner, high corner, first, count): a leaf holds
    /// `count` places from `first`; an inner node (`count` 0) has its children right after
    /// it and at `first`. For a walk of the tree elsewhere (the GPU's).
    pub fn nodes(&self) -> impl Iterator<Item = (Vec3, Vec3, u32, u32)> + '_ {
        self.nodes.iter().map(|n| (n.lo, n.hi, n.first, n.count))
    }

    /// Each place's corners and the triangle it holds (as numbered when the tree was
    /// built), in the tree's order.
    pub fn places(&self) -> impl Iterator<Item = ([Vec3; 3], u32)> + '_ {
        self.corners.iter().copied().zip(self.index.iter().copied())
    }

    /// How many triangles it holds.
    pub fn len(&self) -> usize {
        self.corners.len()
    }

    pub fn is_empty(&self) -> bool {
        self.corners.is_empty()
    }

    /// The box around every triangle (`None` when there is none).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.nodes.first().map(|n| (n.lo, n.hi))
    }

    /// The point of the surface nearest to `p`, if one is within `reach`.
    pub fn nearest(&self, p: Vec3, reach: f32) -> Option<Nearest> {
        let mut best: (Option<(usize, Vec3)>, f32) = (None, reach * reach);
        self.walk(
            &mut best,
            Some(p),
            true,
            |best, lo, hi| box_distance_squared(p, lo, hi) <= best.1,
            |best, place| {
                let q = closest_on_triangle(p, self.corners[place]);
                let d2 = p.distance_squared(q);
                if d2 <= best.1 {
                    *best = (Some((place, q)), d2);
                }
                true
            },
        );
        best.0.map(|(place, point)| Nearest {
            triangle: self.index[place],
            point,
            distance: best.1.sqrt(),
        })
    }

    /// Calls `visit` with every triangle within `reach` of `p` (its place in the tree, its
    /// number, the point of it nearest to `p`, and the distance), in no order, until
    /// `visit` returns `false`.
    pub fn within(&self, p: Vec3, reach: f32, mut visit: impl FnMut(Near) -> bool) {
        let reach2 = reach * reach;
        self.walk(
            &mut (),
            None,
            false,
            |_, lo, hi| box_distance_squared(p, lo, hi) <= reach2,
            |_, place| {
                // The triangle's own box first: most in a leaf are out of reach.
                let [a, b, c] = self.corners[place];
                if box_distance_squared(p, a.min(b).min(c), a.max(b).max(c)) > reach2 {
                    return true;
                }
                let q = closest_on_triangle(p, [a, b, c]);
                let d2 = p.distance_squared(q);
                d2 > reach2
                    || visit(Near {
                        place: place as u32,
                        triangle: self.index[place],
                        point: q,
                        distance: d2.sqrt(),
                    })
            },
        );
    }

    /// The corners of the triangle at `place` in the tree's order: the triangles near one
    /// another lie near one another there, each triangle's corners together (one read
    /// where the surface's own triangles and vertices take four).
    ///
    /// # Panics
    /// For a place past the last.
    #[inline]
    pub fn place(&self, place: u32) -> [Vec3; 3] {
        self.corners[place as usize]
    }

    /// The number of the triangle at `place` in the tree's order.
    ///
    /// # Panics
    /// For a place past the last.
    #[inline]
    pub fn number(&self, place: u32) -> u32 {
        self.index[place as usize]
    }

    /// The first triangle the segment from `from` to `to` crosses: its number and the
    /// fraction of the way at which it does.
    pub fn first_crossing(&self, from: Vec3, to: Vec3) -> Option<(u32, f32)> {
        let mut best: Option<(usize, f32)> = None;
        self.walk(
            &mut best,
            None,
            true,
            // Only the part of the segment before the best crossing so far matters.
            |best, lo, hi| {
                let end = best.map_or(to, |(_, t)| from + (to - from) * t);
                segment_meets_box(from, end, lo, hi)
            },
            |best, place| {
                if let Some(t) = segment_crosses(from, to, self.corners[place])
                    && best.is_none_or(|(_, b)| t < b)
                {
                    *best = Some((place, t));
                }
                true
            },
        );
        best.map(|(place, t)| (self.index[place], t))
    }

    /// Calls `visit` with the number of every triangle whose box meets the box `lo..hi`.
    pub fn overlapping(&self, lo: Vec3, hi: Vec3, mut visit: impl FnMut(u32)) {
        self.overlapping_while(lo, hi, |t| {
            visit(t);
            true
        });
    }

    /// As [`TriangleTree::overlapping`], stopping as soon as `visit` returns `false`.
    pub fn overlapping_while(&self, lo: Vec3, hi: Vec3, mut visit: impl FnMut(u32) -> bool) {
        let meets = move |a: Vec3, b: Vec3| a.cmple(hi).all() && b.cmpge(lo).all();
        self.walk(
            &mut (),
            None,
            false,
            |_, a, b| meets(a, b),
            |_, place| {
                let [a, b, c] = self.corners[place];
                !meets(a.min(b).min(c), a.max(b).max(c)) || visit(self.index[place])
            },
        );
    }

    /// Walks the tree depth first from its root: a node is entered where `enter(state, lo,
    /// hi)` (its box) says so, and each place of an entered leaf goes to `leaf(state,
    /// place)`, which ends the walk by returning `false`. Towards a point, the child whose
    /// box is nearer to it is walked first. A node is asked when it is found and, where
    /// what `enter` accepts `shrinks` as the walk goes, again when its turn comes.
    #[inline(always)]
    fn walk<S>(
        &self,
        state: &mut S,
        towards: Option<Vec3>,
        shrinks: bool,
        enter: impl Fn(&S, Vec3, Vec3) -> bool,
        mut leaf: impl FnMut(&mut S, usize) -> bool,
    ) {
        // Median splits keep the depth at about log₂(n / LEAF): 64 is never reached.
        let mut stack = [0u32; 64];
        let mut top = usize::from(self.nodes.first().is_some_and(|n| enter(state, n.lo, n.hi)));
        while top > 0 {
            top -= 1;
            let at = stack[top];
            let node = self.nodes[at as usize];
            if shrinks && !enter(state, node.lo, node.hi) {
                continue;
            }
            if node.count > 0 {
                for place in node.first as usize..(node.first + node.count) as usize {
                    if !leaf(state, place) {
                        return;
                    }
                }
                continue;
            }
            // The child pushed last is walked first.
            let (one, two) = (at + 1, node.first);
            let (last, first) = match towards {
                Some(p) if self.box_d2(one, p) > self.box_d2(two, p) => (one, two),
                _ => (two, one),
            };
            for child in [last, first] {
                let n = self.nodes[child as usize];
                if enter(state, n.lo, n.hi) {
                    stack[top] = child;
                    top += 1;
                }
            }
        }
    }

    fn box_d2(&self, node: u32, p: Vec3) -> f32 {
        let n = self.nodes[node as usize];
        box_distance_squared(p, n.lo, n.hi)
    }
}

/// A node of a tree over places `0..n` split at medians ([`split_at_medians`]): it holds
/// `count` places from `first` in the tree's order; one of more than the leaf's size has
/// its children right after it and at `second`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Split {
    pub first: u32,
    pub count: u32,
    pub second: u32,
}

/// [`split_at_medians`] over the triangles of a cloth, each at the centre of its corners'
/// `rest` positions (a corner past them at the origin).
pub(crate) fn split_triangles_at_medians(
    triangles: &[[u32; 3]],
    rest: &[Vec3],
    leaf: usize,
) -> (Vec<Split>, Vec<u32>) {
    split_at_medians(triangles.len(), leaf, |t| {
        let corner = |i: u32| rest.get(i as usize).copied().unwrap_or(Vec3::ZERO);
        triangles[t as usize]
            .iter()
            .map(|&i| corner(i))
            .sum::<Vec3>()
            / 3.0
    })
}

/// A balanced tree over `n` places, each at `centre(place)`: every node of more than
/// `leaf` places is halved at the median of their centres along the axis of their widest
/// spread. Returns the nodes, each parent before its children (so that a pass from the
/// last back meets children first), and the places in the tree's order.
pub(crate) fn split_at_medians(
    n: usize,
    leaf: usize,
    centre: impl Fn(u32) -> Vec3,
) -> (Vec<Split>, Vec<u32>) {
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut nodes: Vec<Split> = Vec::with_capacity(2 * n.div_ceil(leaf.max(1)));
    // Depth first: the second child is set aside until the first's subtree is built.
    let mut pending = if n == 0 {
        vec![]
    } else {
        vec![(0u32, n as u32, None)]
    };
    while let Some((first, count, parent)) = pending.pop() {
        let at = nodes.len() as u32;
        if let Some(parent) = parent {
            nodes[parent as usize].second = at;
        }
        nodes.push(Split {
            first,
            count,
            second: 0,
        });
        if count as usize <= leaf.max(1) {
            continue;
        }
        let held = &mut order[first as usize..(first + count) as usize];
        let (lo, hi) = (held.iter()).fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &t| {
            (lo.min(centre(t)), hi.max(centre(t)))
        });
        let spread = hi - lo;
        let axis = if spread.x >= spread.y && spread.x >= spread.z {
            0
        } else if spread.y >= spread.z {
            1
        } else {
            2
        };
        let mid = count / 2;
        held.select_nth_unstable_by(mid as usize, |&a, &b| {
            centre(a)[axis].total_cmp(&centre(b)[axis])
        });
        pending.push((first + mid, count - mid, Some(at)));
        pending.push((first, mid, None));
    }
    (nodes, order)
}
