//! An obstacle's sharp edges (its creases and its open borders), where a cloth edge can
//! rest across it with both ends clear of its faces: a table's rim under a tablecloth.

use glam::{Vec3, Vec3A};

use super::geometry::{less_by_move, rounding_near, segments_closest, sides_by_edge, welded};
use super::tree::TriangleTree;

/// Two faces meeting at less than this cosine between their normals (about 10°) make a
/// sharp edge; flatter ones are covered by their faces. Unsigned: a mesh whose faces are
/// not all wound the same way has no false creases.
pub(super) const CREASE_COS: f32 = 0.985;

/// The sharp edges of a surface and a tree over them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SharpEdges {
    /// Each edge's two vertices.
    ends: Vec<[u32; 2]>,
    edges: Vec<[Vec3; 2]>,
    tree: TriangleTree,
}

/// How far beyond the reach asked for, as a share of it, a question that must walk the
/// tree looks for sharp edges, so that its answer lets the same cloth edge move that much
/// before it is asked again: where the edges are fixed in the frame (a rigid obstacle's).
pub const LOOK: f32 = 4.0;

/// [`LOOK`] where the edges deform: their own move wears the clearance down every substep,
/// so a longer look pays less than the larger walks it costs (`arm` at 32² under XPBD,
/// the obstacle phase: 1.05–1.14 s for half a simulated second at 0.5, 1.18 at 1, 1.39
/// at 2, 2.05 at 4, against 1.44–1.48 walking the tree for every question).
pub const LOOK_DEFORMING: f32 = 0.5;

/// Sharp edges a [`Clearance`] holds by number (more: it holds none).
const NEAR_EDGES: usize = 3;

/// What the last question about one cloth edge measured
/// ([`SharpEdges::nearest_remembering`]): where its ends were (in the surface's frame), how
/// near at least any sharp edge lay to it then, and the sharp edges found within the
/// distance it looked to, where they were few. A fact of the surface alone, as
/// [`super::Gathered`] is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    ends: [Vec3A; 2],
    /// Metres, less a margin for the rounding; `-∞`: nothing measured.
    clear: f32,
    /// How far from the segment measured every sharp edge was looked for, m, less a
    /// margin for the rounding; each one found within it is in `near` (`-∞`: none held).
    looked: f32,
    /// How many of `near` are held, in the order the tree gives them.
    count: u8,
    near: [u32; NEAR_EDGES],
}

impl Clearance {
    /// Nothing measured.
    pub const NONE: Clearance = Clearance {
        ends: [Vec3A::ZERO; 2],
        clear: f32::NEG_INFINITY,
        looked: f32::NEG_INFINITY,
        count: 0,
        near: [0; NEAR_EDGES],
    };

    /// The same measure after the sharp edges moved by up to `by` metres (a deforming
    /// surface's largest vertex move: every point of an edge moves at most as far as the
    /// farther of its ends): the clearance is that much less (`less_by_move`). Nothing
    /// measured stays so.
    #[inline]
    pub fn surface_moved(&mut self, by: f32) {
        self.clear = less_by_move(self.clear, by);
        self.looked = less_by_move(self.looked, by);
    }

    /// Whether the segment from `a` to `b` is told farther than `reach` from every sharp
    /// edge: its ends have moved less than the clearance less the reach (and a
    /// ten-thousandth of it, for the rounding) since it was measured.
    #[inline]
    fn clears(&self, [a, b]: [Vec3A; 2], reach: f32) -> bool {
        let room = self.clear - reach * (1.0 + 1e-4);
        let moved = self.moved_squared([a, b]);
        room > 0.0 && moved < room * room
    }

    /// How much of the clearance is left with the segment's ends at `a` and `b`: the
    /// clearance less the farther of the ends' moves since it was measured, m (`-∞`:
    /// nothing measured).
    #[inline]
    pub fn left(&self, ends: [Vec3A; 2]) -> f32 {
        self.clear - self.moved_squared(ends).sqrt()
    }

    /// The square of the farther of the ends' moves, from where it was measured to `a`
    /// and `b`.
    #[inline]
    fn moved_squared(&self, [a, b]: [Vec3A; 2]) -> f32 {
        a.distance_squared(self.ends[0])
            .max(b.distance_squared(self.ends[1]))
    }
}

/// The nearest points of a segment and a sharp edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeHit {
    /// Where along the segment, 0 at its start and 1 at its end.
    pub along: f32,
    pub on_segment: Vec3,
    pub on_edge: Vec3,
    pub distance: f32,
}

impl SharpEdges {
    /// The edges of `triangles` over `vertices` that border one triangle, or two whose
    /// normals (`normals`, per triangle) differ by more than about 10°. Vertices at the
    /// same place are one vertex here: a surface written with its faces apart (each face of
    /// a box with its own corners, a sphere cut along seams) has its creases where its
    /// faces bend, not a border wherever a vertex was written twice.
    pub fn of(vertices: &[Vec3], triangles: &[[u32; 3]], normals: &[Vec3]) -> Self {
        Self::of_or(vertices, triangles, normals, |_, _| false)
    }

    /// As [`SharpEdges::of`], and also every edge between two faces that `also` says is
    /// one (given its two vertices, welded, and its two faces).
    pub fn of_or(
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        normals: &[Vec3],
        also: impl Fn([u32; 2], [usize; 2]) -> bool,
    ) -> Self {
        let same = welded(vertices);
        // Each edge (its welded ends) with the sides of the faces it borders.
        let sides = sides_by_edge(triangles, &same, |_| true);
        let keys: Vec<[u32; 2]> = (sides.chunk_by(|x, y| x.0 == y.0))
            .filter(|sides| match *sides {
                [(ends, one), (_, two)] => {
                    let [one, two] = [*one as usize / 3, *two as usize / 3];
                    normals[one].dot(normals[two]).abs() < CREASE_COS || also(*ends, [one, two])
                }
                _ => true,
            })
            .map(|sides| sides[0].0)
            .collect();
        let ends: Vec<[u32; 2]> = (keys.into_iter())
            .filter(|[a, b]| vertices[*a as usize] != vertices[*b as usize])
            .collect();
        let edges: Vec<[Vec3; 2]> = ends
            .iter()
            .map(|e| e.map(|i| vertices[i as usize]))
            .collect();
        Self {
            tree: TriangleTree::new(&edges.iter().map(|&e| as_triangle(e)).collect::<Vec<_>>()),
            ends,
            edges,
        }
    }

    /// The same edges over moved `vertices` (which edges are sharp stays as first found).
    pub fn refit(&mut self, vertices: &[Vec3]) {
        for (edge, ends) in self.edges.iter_mut().zip(&self.ends) {
            *edge = ends.map(|i| vertices[i as usize]);
        }
        let edges = &self.edges;
        self.tree.refit(|e| as_triangle(edges[e]));
    }

    /// The tree over the edges (each a triangle with its second end twice).
    pub fn tree(&self) -> &TriangleTree {
        &self.tree
    }

    /// Each edge's two vertices.
    pub fn ends(&self) -> &[[u32; 2]] {
        &self.ends
    }

    /// Whether the edge between the vertices `a < b` (welded: each the first at its place)
    /// is one of these.
    pub fn has(&self, [a, b]: [u32; 2]) -> bool {
        self.ends.binary_search(&[a, b]).is_ok()
    }

    pub fn len(&self) -> usize {
        self.edges.len()
    }

    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Whether a segment moving from `before` to `after` (each end in a straight line) passes
    /// through a sharp edge on the way: the first such edge, and the unit direction from it
    /// to the segment where the move began (the side the segment must stay on).
    pub fn crossed(&self, before: [Vec3; 2], after: [Vec3; 2]) -> Option<([Vec3; 2], Vec3)> {
        let lo = before[0].min(before[1]).min(after[0]).min(after[1]);
        let hi = before[0].max(before[1]).max(after[0]).max(after[1]);
        let mut first: Option<(f32, [Vec3; 2], Vec3)> = None;
        self.tree.overlapping(lo, hi, |e| {
            let [p, q] = self.edges[e as usize];
            let Some(t) = sweep_meets(before, after, p, q) else {
                return;
            };
            if first.is_some_and(|(f, _, _)| f <= t) {
                return;
            }
            let start = closest_between(before[0], before[1], p, q);
            if start.distance > 0.0 {
                let side = (start.on_segment - start.on_edge) / start.distance;
                first = Some((t, [p, q], side));
            }
        });
        first.map(|(_, edge, side)| (edge, side))
    }

    /// The nearest points of the segment from `a` to `b` and the sharp edge `edge`.
    pub fn between(a: Vec3, b: Vec3, edge: [Vec3; 2]) -> EdgeHit {
        closest_between(a, b, edge[0], edge[1])
    }

    /// The sharp edge nearest to the segment from `a` to `b`, if one is within `reach`.
    pub fn nearest(&self, a: Vec3, b: Vec3, reach: f32) -> Option<EdgeHit> {
        self.nearest_with(a, b, reach, |_| {})
    }

    /// [`SharpEdges::nearest`], calling `within` with each sharp edge within `reach` (by
    /// number, in the order the tree gives them).
    fn nearest_with(
        &self,
        a: Vec3,
        b: Vec3,
        reach: f32,
        mut within: impl FnMut(u32),
    ) -> Option<EdgeHit> {
        let pad = Vec3::splat(reach);
        let mut best: Option<EdgeHit> = None;
        self.tree.overlapping(a.min(b) - pad, a.max(b) + pad, |e| {
            let [p, q] = self.edges[e as usize];
            if keep_nearest(&mut best, closest_between(a, b, p, q), reach) {
                within(e);
            }
        });
        best
    }

    /// [`SharpEdges::nearest`] for the segment between the two `segment` ends, with what
    /// the last question about the same cloth edge measured (kept in `memory`, which this
    /// one updates). Every point of the segment lies within the farther of its ends' moves
    /// of a point of the segment measured, so no sharp edge comes nearer to it than the
    /// clearance less that move: while that exceeds `reach` (with a margin for the
    /// rounding), the answer is `None` without a walk of the tree. Otherwise the tree is
    /// walked for `look` times the reach more ([`LOOK`], [`LOOK_DEFORMING`]), and what it
    /// finds is remembered; the answer
    /// is the same as [`SharpEdges::nearest`]'s (the nearest within the longer reach,
    /// where it lies within `reach`: the same edge found in the same order).
    #[inline]
    pub fn nearest_remembering(
        &self,
        segment: [Vec3A; 2],
        [reach, look]: [f32; 2],
        memory: &mut Clearance,
    ) -> Option<EdgeHit> {
        if memory.clears(segment, reach) {
            return None;
        }
        if memory.count > 0
            && let Some(hit) = self.among_held(segment, reach, memory)
        {
            return Some(hit);
        }
        self.measure(segment, [reach, look], memory)
    }

    /// The nearest of the sharp edges `memory` holds to the segment between `ends`, where
    /// the ends have moved so little since it was measured that every sharp edge within
    /// `reach` of it now was within the distance looked to then, and one of them is within
    /// the reach (`None`: else, and the tree is asked; a segment clear of them all is
    /// measured again, so that its clearance is measured from where it is). Those are in
    /// the same order as the tree gives them, so the nearest of them is the walk's.
    #[inline(never)]
    fn among_held(&self, ends: [Vec3A; 2], reach: f32, memory: &Clearance) -> Option<EdgeHit> {
        let [a, b] = ends.map(Vec3::from);
        let rounding = rounding_near(a.abs().max(b.abs()));
        let room = memory.looked - reach * (1.0 + 1e-4) - rounding;
        if !(room > 0.0 && memory.moved_squared(ends) < room * room) {
            return None;
        }
        // As the walk does: only an edge whose box meets the segment's grown by the reach.
        let pad = Vec3::splat(reach);
        let (lo, hi) = (a.min(b) - pad, a.max(b) + pad);
        let mut best: Option<EdgeHit> = None;
        for &e in &memory.near[..usize::from(memory.count)] {
            let [p, q] = self.edges[e as usize];
            if !(p.min(q).cmple(hi).all() && p.max(q).cmpge(lo).all()) {
                continue;
            }
            keep_nearest(&mut best, closest_between(a, b, p, q), reach);
        }
        best
    }

    /// [`SharpEdges::nearest_remembering`] where the memory does not tell.
    #[inline(never)]
    fn measure(
        &self,
        ends: [Vec3A; 2],
        [reach, look]: [f32; 2],
        memory: &mut Clearance,
    ) -> Option<EdgeHit> {
        let [a, b] = ends.map(Vec3::from);
        let far = (1.0 + look) * reach;
        let (mut near, mut count) = ([0; NEAR_EDGES], 0);
        let best = self.nearest_with(a, b, far, |e| {
            if let Some(slot) = near.get_mut(count) {
                *slot = e;
            }
            count += 1;
        });
        let rounding = rounding_near(a.abs().max(b.abs()));
        let held = count <= NEAR_EDGES;
        *memory = Clearance {
            ends,
            clear: best.map_or(far, |hit| hit.distance) - rounding,
            looked: if held {
                far - rounding
            } else {
                f32::NEG_INFINITY
            },
            count: if held { count as u8 } else { 0 },
            near,
        };
        best.filter(|hit| hit.distance <= reach)
    }
}

/// The first time in `0..=1` at which the segment moving from `before` to `after` meets the
/// segment `p`–`q`: where the four points are coplanar (a quadratic in time) and the two
/// segments then touch.
fn sweep_meets(before: [Vec3; 2], after: [Vec3; 2], p: Vec3, q: Vec3) -> Option<f32> {
    let u = q - p;
    let (a, da) = (before[0] - p, after[0] - before[0]);
    let (c, dc) = (before[1] - before[0], (after[1] - before[1]) - da);
    // (a + t·da) · ((c + t·dc) × u) = k0 + k1·t + k2·t².
    let (k0, k1, k2) = (
        a.dot(c.cross(u)),
        a.dot(dc.cross(u)) + da.dot(c.cross(u)),
        da.dot(dc.cross(u)),
    );
    let scale = (c.length() + dc.length() + da.length()) * u.length();
    let mut roots = [f32::NAN; 2];
    if k2.abs() > 1e-9 * scale * scale.max(1e-12) {
        let disc = k1 * k1 - 4.0 * k2 * k0;
        if disc >= 0.0 {
            let s = disc.sqrt();
            roots = [(-k1 - s) / (2.0 * k2), (-k1 + s) / (2.0 * k2)];
        }
    } else if k1.abs() > 0.0 {
        roots[0] = -k0 / k1;
    }
    roots.sort_by(f32::total_cmp);
    let touch = 1e-5 * (c.length() + u.length());
    roots
        .into_iter()
        .filter(|t| (0.0..=1.0).contains(t))
        .find(|&t| {
            let (x, y) = (before[0] + da * t, before[1] + (after[1] - before[1]) * t);
            closest_between(x, y, p, q).distance <= touch
        })
}

/// Whether `hit` is within `reach`; if so, and nearer than `best` (the first of equals
/// stays), it is the best now.
fn keep_nearest(best: &mut Option<EdgeHit>, hit: EdgeHit, reach: f32) -> bool {
    let within = hit.distance <= reach;
    if within && best.is_none_or(|b| hit.distance < b.distance) {
        *best = Some(hit);
    }
    within
}

/// An edge as a degenerate triangle, for the tree.
fn as_triangle([a, b]: [Vec3; 2]) -> [Vec3; 3] {
    [a, b, b]
}

/// The nearest points of the segments `a`–`b` and `p`–`q`.
fn closest_between(a: Vec3, b: Vec3, p: Vec3, q: Vec3) -> EdgeHit {
    let [a64, b64, p64, q64] = [a, b, p, q].map(|v| v.as_dvec3());
    let (s, t) = segments_closest(a64, b64, p64, q64);
    let (s, t) = (s as f32, t as f32);
    let (on_segment, on_edge) = (a + (b - a) * s, p + (q - p) * t);
    EdgeHit {
        along: s,
        on_segment,
        on_edge,
        distance: on_segment.distance(on_edge),
    }
}

/// The unit cube's corners and its faces' triangles, with their normals (twelve sharp
/// edges): for tests.
#[cfg(test)]
pub(crate) fn unit_cube() -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<Vec3>) {
    let v: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
        .collect();
    let quads = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    let t: Vec<[u32; 3]> = (quads.iter())
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    let normals: Vec<Vec3> = (t.iter())
        .map(|t| {
            let [a, b, c] = t.map(|i| v[i as usize]);
            (b - a).cross(c - a).normalize()
        })
        .collect();
    (v, t, normals)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest points of two segments agree with a fine search along both.
    #[test]
    fn the_nearest_points_of_two_segments_are_the_nearest() {
        let mut rnd = crate::test_rng::uniform(21);
        let mut v = || Vec3::new(rnd(), rnd(), rnd());
        for _ in 0..300 {
            let (a, b, p, q) = (v(), v(), v(), v());
            let hit = closest_between(a, b, p, q);
            let n = 200;
            let mut best = f32::INFINITY;
            for i in 0..=n {
                for j in 0..=n {
                    let (s, t) = (i as f32 / n as f32, j as f32 / n as f32);
                    best = best.min((a + (b - a) * s).distance(p + (q - p) * t));
                }
            }
            assert!(hit.distance <= best + 1e-5, "{hit:?} vs {best}");
            assert!(hit.distance >= best - 0.02, "{hit:?} vs {best}");
        }
    }

    /// A box's twelve edges are sharp; the diagonals that split its square faces are not;
    /// a lone triangle's three borders are.
    #[test]
    fn creases_and_borders_are_sharp_and_flat_diagonals_are_not() {
        let (v, t, normals) = unit_cube();
        assert_eq!(SharpEdges::of(&v, &t, &normals).len(), 12);
        assert_eq!(SharpEdges::of(&v, &t[..1], &normals[..1]).len(), 3);
    }

    /// A box written with each face's corners apart (as for flat shading; a corner at the
    /// origin once as −0) has the same twelve creases as one whose faces share corners:
    /// not a border around every face, nor at the diagonals that split them.
    #[test]
    fn corners_written_twice_are_one_corner() {
        let (v, t, normals) = unit_cube();
        let mut apart = Vec::new();
        let faces: Vec<[u32; 3]> = (t.iter())
            .map(|tri| {
                tri.map(|i| {
                    apart.push(v[i as usize]);
                    apart.len() as u32 - 1
                })
            })
            .collect();
        if let Some(origin) = apart.iter_mut().find(|c| **c == Vec3::ZERO) {
            *origin = Vec3::new(-0.0, 0.0, -0.0);
        }
        let edges = SharpEdges::of(&apart, &faces, &normals);
        let whole = SharpEdges::of(&v, &t, &normals);
        // Twelve, each one of the box's (either way round; −0 equals +0).
        assert_eq!(edges.len(), 12);
        for &[p, q] in &whole.edges {
            let found = (edges.edges.iter()).any(|&e| e == [p, q] || e == [q, p]);
            assert!(found, "{p} – {q} missing");
        }
    }

    /// Questions a cloth edge remembering its clearance asked: those answered `None`, those
    /// of them that walked the tree, and the others, and those of them that walked it.
    #[derive(Default)]
    struct Asked {
        clear: usize,
        walks: usize,
        near: usize,
        near_walks: usize,
    }

    impl Asked {
        /// Asks `edges` about the cloth edge at `ends` with `memory`, checks the answer
        /// against a walk of the tree, and counts it.
        fn ask(
            &mut self,
            edges: &SharpEdges,
            ends: [Vec3A; 2],
            [reach, look]: [f32; 2],
            memory: &mut Clearance,
        ) {
            let before = *memory;
            let remembered = edges.nearest_remembering(ends, [reach, look], memory);
            let [a, b] = ends.map(Vec3::from);
            assert_eq!(remembered, edges.nearest(a, b, reach), "{a} – {b}");
            if remembered.is_some() {
                self.near += 1;
                self.near_walks += usize::from(*memory != before);
            } else {
                self.clear += 1;
                self.walks += usize::from(*memory != before);
            }
        }
    }

    /// Where the sharp edges move (a box sweeping through a cloth edge 5 cm off one of its
    /// edges at 1 mm a step, each corner up to 0.9 mm more in a direction of its own), a
    /// cloth edge that barely moves (0.2 mm a step), remembering its clearance made less at
    /// each step by the corners' largest move, gets the answer a walk of the tree gives,
    /// bit for bit, as the edge comes within reach and goes; and walks the tree for fewer
    /// than one question in three of those answered clear. Made less by half the move, it
    /// answers clear where an edge is within reach.
    #[test]
    fn a_clearance_made_less_by_the_surfaces_move_changes_nothing() {
        let (v, t, normals) = unit_cube();
        let mut edges = SharpEdges::of(&v, &t, &normals);
        let mut rnd = crate::test_rng::uniform(23);
        let mut step = || Vec3A::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
        let mut asked = Asked::default();
        for k in 0..40 {
            let mut corners = v.clone();
            edges.refit(&corners);
            let [p, q] = edges.edges[k % 12].map(Vec3A::from);
            // Out from the box's middle through the edge, 5 cm beyond it, and the box
            // sweeping that way, on past the cloth edge.
            let away = ((p + q) * 0.5 - Vec3A::splat(0.5)).normalize();
            let middle = p + (q - p) * (0.5 + 0.8 * step().x) + away * 0.05;
            let mut ends = [middle - step() * 0.04, middle + step() * 0.04];
            let mut memory = Clearance::NONE;
            let sweep = Vec3::from(away) * 1e-3;
            for _ in 0..120 {
                let moves: Vec<Vec3> = (0..corners.len())
                    .map(|_| sweep + Vec3::from(step()) * 1e-3)
                    .collect();
                for (c, m) in corners.iter_mut().zip(&moves) {
                    *c += *m;
                }
                edges.refit(&corners);
                memory.surface_moved(moves.iter().map(|m| m.length()).fold(0.0, f32::max));
                ends = ends.map(|e| e + step() * 2e-4);
                asked.ask(&edges, ends, [0.01, LOOK_DEFORMING], &mut memory);
            }
        }
        let Asked {
            clear, walks, near, ..
        } = asked;
        assert!(
            near * 10 > clear && near < clear,
            "{near} near, {clear} clear"
        );
        assert!(
            walks * 3 < clear,
            "{walks} walks in {clear} questions answered clear"
        );
    }

    /// A cloth edge carried across a box's top, 5 mm above it, from one of its edges to the
    /// opposite one at 2 mm a step, gets the answer a walk of the tree gives at every step,
    /// bit for bit: the sharp edges it held near the first do not answer for the second.
    #[test]
    fn held_edges_answer_only_as_far_as_they_were_looked_for() {
        let (v, t, normals) = unit_cube();
        let edges = SharpEdges::of(&v, &t, &normals);
        let mut asked = Asked::default();
        let mut memory = Clearance::NONE;
        for k in 0..=520 {
            let x = -0.01 + 0.002 * k as f32;
            let ends = [Vec3A::new(x, 1.005, 0.4), Vec3A::new(x, 1.005, 0.45)];
            asked.ask(&edges, ends, [0.01, LOOK], &mut memory);
        }
        let Asked { clear, near, .. } = asked;
        assert!(near >= 12 && clear > 450, "{near} near, {clear} clear");
    }

    /// A cloth edge remembering its clearance gets the answer a walk of the tree gives,
    /// bit for bit, at every step as it wanders in and out of reach of a box's edges, its
    /// ends moving up to 1 mm a step and its reach changing; and where no edge is within
    /// reach, walks the tree for fewer than one question in four. Where one is, it asks
    /// the few sharp edges the last walk found, and walks the tree for fewer than one
    /// question in ten.
    #[test]
    fn remembering_the_clearance_changes_nothing() {
        let (v, t, normals) = unit_cube();
        let edges = SharpEdges::of(&v, &t, &normals);
        let mut rnd = crate::test_rng::uniform(17);
        let mut step = || Vec3A::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
        let mut asked = Asked::default();
        for k in 0..60 {
            // Beside one of the box's edges, 4 cm long.
            let [p, q] = edges.edges[k % 12].map(Vec3A::from);
            let middle = p + (q - p) * (0.5 + 0.8 * step().x) + step() * 0.06;
            let mut ends = [middle - step() * 0.04, middle + step() * 0.04];
            let mut memory = Clearance::NONE;
            for _ in 0..400 {
                ends = ends.map(|e| e + step() * 2e-3);
                let reach = 0.01 + 0.01 * (step().x + 0.5);
                asked.ask(&edges, ends, [reach, LOOK], &mut memory);
            }
        }
        let Asked {
            clear,
            walks,
            near,
            near_walks,
        } = asked;
        assert!(
            near * 5 > clear && near < clear,
            "{near} near, {clear} clear"
        );
        assert!(
            walks * 4 < clear,
            "{walks} walks in {clear} questions answered clear"
        );
        assert!(
            near_walks * 10 < near,
            "{near_walks} walks in {near} questions answered near"
        );
    }
}
