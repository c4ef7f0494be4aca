//! An obstacle's surface in its own frame: its triangles, their normals and the tree over
//! them, and where a particle's move across it ends.

use std::collections::HashSet;
use std::sync::Arc;

use glam::Vec3;

use super::coarse::{ClothSpan, Dips, FLAT_COS, Reached};
use super::edges::SharpEdges;
use super::geometry::{
    closest_on_triangle, face_normals, less_by_move, rounding_near, segment_crosses, welded,
};
use super::tips::Tips;
use super::tree::{Near, Nearest, TriangleTree};

/// How many crossings one move may be caught at (a move that slides on into a second face
/// after the first, as in a concave corner).
const CROSSINGS: usize = 3;
/// How many times the end of a move is pushed out of the thickness (two faces of a corner
/// can each hold it within).
const PUSHES: usize = 3;
/// Triangles near one move that a catch holds at once (more: it walks the tree for each
/// question instead).
const NEAR: usize = 48;
/// How far beyond the thickness a short move's end gathers triangles (as a share of the
/// thickness): pushes that move the end less than this stay among what was gathered.
const SLACK: f32 = 0.05;
/// Triangles a short move's end holds at once (more: the general catch).
const NEAR_END: usize = 24;

/// How far a remembered gathering lets an end drift (as a share of the thickness) before
/// the tree is walked again.
const DRIFT: f32 = 0.1;

/// How far out (as a multiple of the reach) a gathering that finds nothing near looks for
/// the nearest triangle, to remember a ball with none in it.
const CLEAR: f32 = 2.0;

/// The triangles near one point, remembered from one substep to the next: every triangle
/// within `radius` of `centre`, by its place in the tree (where its corners are read
/// from) in order of its number, with its distance from `centre`. A fact of the surface
/// alone (in its own frame; where it deforms, made less by its move since:
/// [`Gathered::surface_moved`]), so an end whose reach lies inside that ball needs no walk of
/// the tree; and a triangle farther from the centre than the reach and the end's move
/// from it together is out of the end's reach without being measured again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gathered {
    centre: Vec3,
    /// Negative: nothing remembered.
    radius: f32,
    count: u8,
    places: [u32; NEAR_END],
    distances: [f32; NEAR_END],
}

impl Gathered {
    /// Nothing remembered.
    pub const NONE: Gathered = Gathered {
        centre: Vec3::ZERO,
        radius: -1.0,
        count: 0,
        places: [0; NEAR_END],
        distances: [0.0; NEAR_END],
    };

    /// Whether the ball holds no triangle and holds `reach` of `p` (then no triangle
    /// lies within `reach` of `p`).
    #[inline]
    fn clears(&self, p: Vec3, reach: f32) -> bool {
        self.count == 0 && self.radius >= reach + p.distance(self.centre)
    }

    /// The same gathering after the surface deformed, no point of it moving farther than
    /// `by` metres: a triangle now within the radius less `by` of the centre was within the
    /// radius, and none is nearer than its distance less `by`. Both lowered that much
    /// (`less_by_move`). The triangles' places in the tree stay theirs (a refit keeps its
    /// shape).
    pub fn surface_moved(&mut self, by: f32) {
        self.radius = less_by_move(self.radius, by);
        let count = usize::from(self.count);
        (self.distances.iter_mut().take(count)).for_each(|d| *d = less_by_move(*d, by));
    }
}

/// What [`Surface::catch_short`] can tell.
enum Short {
    Clear,
    Caught(Caught),
    /// A long move, or one too near the surface or among too many triangles to tell.
    Unsure,
}

/// A triangle surface, fixed in its own frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Surface {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// Unit normal of each triangle (zero for a degenerate one).
    normals: Vec<Vec3>,
    tree: TriangleTree,
    edges: SharpEdges,
    tips: Tips,
    /// Whether two of its faces meet at an edge neither flat nor a crease (a cloth coarse
    /// enough may reach it: [`ClothSpan`]).
    gentle: bool,
}

/// Where a caught move ends and the surface's normal there (pointing to the side the
/// particle is kept on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Caught {
    pub at: Vec3,
    pub normal: Vec3,
    /// The triangle that last held it and the point of it that did (where its velocity
    /// is the surface's, for a surface that deforms).
    pub triangle: u32,
    pub on_surface: Vec3,
}

/// What fitting a surface to a cloth measured and gave last: the walks over it for the
/// last reach asked for ([`Dips`]; by default, else none: [`Fitted::passing`]), and the
/// last span asked for with what it reached and the answer made of that (a mesh
/// obstacle's placement that keeps the cloth off it).
#[derive(Debug)]
pub struct Fitted<T> {
    keeps: bool,
    dips: Option<Dips>,
    last: Option<(ClothSpan, Reached, Option<Arc<T>>)>,
}

impl<T> Default for Fitted<T> {
    fn default() -> Self {
        Self {
            keeps: true,
            dips: None,
            last: None,
        }
    }
}

impl<T> Fitted<T> {
    /// One that keeps no walks, only its last answer: for a surface fitted already, which
    /// is fitted again only as the cloth outgrows it (each time to a new reach), never to
    /// another thickness (that fits the scene's own surface again).
    pub fn passing() -> Self {
        Self {
            keeps: false,
            ..Self::default()
        }
    }

    /// Whether it holds walks now.
    #[cfg(test)]
    pub(crate) fn holds_walks(&self) -> bool {
        self.dips.is_some()
    }

    /// What `surface` (taking the places `frames` too: [`Surface::reached_over`]) keeps
    /// off a cloth of `span`, made into an answer by `answer` (`None` where it adds
    /// nothing): the last answer where the span is the last one's, or where it reaches
    /// what the last one did (a thickness changed that changes nothing reached), the walks
    /// taken for the last reach read again where they serve.
    pub fn answer<'f>(
        &mut self,
        (surface, frames): (&Surface, impl IntoIterator<Item = &'f [Vec3]>),
        span: &ClothSpan,
        answer: impl FnOnce(&Reached) -> Option<T>,
    ) -> Option<Arc<T>> {
        if let Some((asked, _, answered)) = &self.last
            && asked == span
        {
            return answered.clone();
        }
        let mut passing = None;
        let dips = if self.keeps {
            &mut self.dips
        } else {
            &mut passing
        };
        let reached = surface.reached_over(span, frames, dips);
        let answered = match self.last.take() {
            Some((_, last, answered)) if last == reached => answered,
            _ => answer(&reached).map(Arc::new),
        };
        self.last = Some((*span, reached, answered.clone()));
        answered
    }
}

impl Surface {
    /// The surface of `triangles` over `vertices` (every index must be in range).
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        let corners: Vec<[Vec3; 3]> = (triangles.iter())
            .map(|t| t.map(|i| vertices[i as usize]))
            .collect();
        let normals = face_normals(&vertices, &triangles);
        let tree = TriangleTree::new(&corners);
        let gentle = std::cell::Cell::new(false);
        let edges = SharpEdges::of_or(&vertices, &triangles, &normals, |_, [n, m]| {
            gentle.set(gentle.get() || normals[n].dot(normals[m]).abs() < FLAT_COS);
            false
        });
        let tips = Tips::of(
            &vertices,
            &triangles,
            &normals,
            edges.ends().iter().copied(),
        );
        Self {
            vertices,
            triangles,
            normals,
            tree,
            edges,
            tips,
            gentle: gentle.get(),
        }
    }

    /// An OBJ sequence's surface: frame 0's (`vertices` over `triangles`), with every edge
    /// where the faces crease in any of `frames` (each as many vertices) a sharp edge, every
    /// vertex where they meet at a point in any a tip, and each smooth vertex's curvature
    /// the largest it has in any: a ridge that rises later in the sequence is kept off
    /// from the start.
    pub fn of_frames(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>, frames: &[Vec<Vec3>]) -> Self {
        let surface = Self::new(vertices, triangles);
        let (vertices, triangles) = (&surface.vertices, &surface.triangles);
        // Vertices at one place are one, by where frame 0 has them.
        let same = welded(vertices);
        let one = |v: &u32| same[*v as usize];
        let (mut creased, mut pointed, mut others) = (HashSet::new(), HashSet::new(), Vec::new());
        for frame in frames.iter().filter(|&f| f != vertices) {
            let normals = face_normals(frame, triangles);
            let edges = SharpEdges::of(frame, triangles, &normals);
            creased.extend(edges.ends().iter().map(|[a, b]| {
                let (a, b) = (one(a), one(b));
                (a.min(b), a.max(b))
            }));
            let tips = Tips::of(frame, triangles, &normals, edges.ends().iter().copied());
            pointed.extend(tips.vertices().iter().map(one));
            others.push(tips);
        }
        let normals = &surface.normals;
        let edges = SharpEdges::of_or(vertices, triangles, normals, |[a, b], _| {
            creased.contains(&(a, b))
        });
        let sharp = edges.ends().iter().copied();
        let tips = Tips::of_or(vertices, triangles, normals, sharp, |v| {
            pointed.contains(&v)
        });
        let tips = tips.curving_as_much_as(&others);
        Self {
            edges,
            tips,
            ..surface
        }
    }

    /// This surface with every gentle edge and vertex that a cloth of `span` can reach
    /// kept off as its creases and tips are ([`ClothSpan`]: a coarse cloth over a rail of
    /// narrow faces); `None` where that adds none.
    pub fn reaching(&self, span: &ClothSpan) -> Option<Surface> {
        self.keeping_off(&self.reached_over(span, std::iter::empty(), &mut None))
    }

    /// The gentle edges and vertices that a cloth of `span` can reach, where the surface
    /// also takes the places `frames` (the frames of a sequence, each as many vertices as
    /// the surface): what it can reach in any of them, each in order. `measured` keeps the
    /// walks over the surface and those frames ([`Dips`]; given again, always with the same
    /// frames): where it holds walks for `span`'s reach they are read, not taken again, so
    /// a cloth of another thickness is answered at once; else they are taken and left
    /// there.
    pub fn reached_over<'f>(
        &self,
        span: &ClothSpan,
        frames: impl IntoIterator<Item = &'f [Vec3]>,
        measured: &mut Option<Dips>,
    ) -> Reached {
        // A frame where the surface already is (a sequence's frame 0) tells nothing more.
        let others: Vec<&[Vec3]> = (frames.into_iter())
            .filter(|&f| f != self.vertices.as_slice())
            .collect();
        let places = || std::iter::once(&self.vertices[..]).chain(others.iter().copied());
        let triangles = &self.triangles;
        let dips = match measured {
            Some(dips) if dips.measures(span) => dips,
            // Vertices at one place are one, by where the surface has them.
            _ => measured.insert(Dips::measure(
                places(),
                triangles,
                welded(&self.vertices),
                span,
            )),
        };
        let (edges, vertices) = dips.reached(places(), triangles, span);
        Reached { edges, vertices }
    }

    /// This surface with the edges and vertices `reached` kept off as its creases and tips
    /// are, besides those it keeps off already; `None` where that adds none.
    pub fn keeping_off(&self, reached: &Reached) -> Option<Surface> {
        let Reached { edges, vertices } = reached;
        let new_edge = |&[a, b]: &[u32; 2]| !self.edges.has([a, b]);
        if !edges.iter().any(new_edge) && !vertices.iter().any(|&v| !self.tips.has(v)) {
            return None;
        }
        let (triangles, normals) = (&self.triangles, &self.normals);
        let edges = SharpEdges::of_or(&self.vertices, triangles, normals, |[a, b], _| {
            edges.binary_search(&[a.min(b), a.max(b)]).is_ok() || self.edges.has([a, b])
        });
        let sharp = edges.ends().iter().copied();
        let tips = Tips::of_or(&self.vertices, triangles, normals, sharp, |v| {
            vertices.binary_search(&v).is_ok() || self.tips.has(v)
        })
        .curving_as_much_as([&self.tips]);
        (edges != self.edges || tips != self.tips).then(|| Surface {
            edges,
            tips,
            ..self.clone()
        })
    }

    /// The same triangles over moved `vertices` (as many as before): normals, tree and
    /// sharp edges and tips refitted, in time linear in the triangles.
    ///
    /// # Panics
    /// When `vertices` is not as long as before.
    pub fn refit(&mut self, vertices: &[Vec3]) {
        assert_eq!(
            vertices.len(),
            self.vertices.len(),
            "refit with other vertices"
        );
        self.vertices.copy_from_slice(vertices);
        let triangles = &self.triangles;
        let corners = |t: usize| triangles[t].map(|i| vertices[i as usize]);
        for (t, n) in self.normals.iter_mut().enumerate() {
            let [a, b, c] = corners(t);
            *n = (b - a).cross(c - a).normalize_or_zero();
        }
        self.tree.refit(corners);
        self.edges.refit(vertices);
        self.tips.refit(vertices);
    }

    /// Each triangle's unit normal (zero for a degenerate one).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// The tree over its triangles.
    pub fn tree(&self) -> &TriangleTree {
        &self.tree
    }

    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Its creases and borders.
    pub fn sharp_edges(&self) -> &SharpEdges {
        &self.edges
    }

    /// Whether two of its faces meet at an edge neither flat nor a crease.
    pub fn is_gentle(&self) -> bool {
        self.gentle
    }

    /// Its tips: where its faces meet at a point.
    pub fn tips(&self) -> &Tips {
        &self.tips
    }

    /// The box around the surface (`None` without triangles).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.tree.bounds()
    }

    /// The nearest point of the surface to `p` within `reach`.
    pub fn nearest(&self, p: Vec3, reach: f32) -> Option<Nearest> {
        self.tree.nearest(p, reach)
    }

    /// The first triangle the segment from `a` to `b` crosses, and where along it.
    pub fn first_crossing(&self, a: Vec3, b: Vec3) -> Option<(u32, f32)> {
        self.tree.first_crossing(a, b)
    }

    /// Where a particle moving from `from` to `to` ends, if its path crosses the surface or
    /// ends within `thickness` of it: caught at its first crossing, `thickness` off the
    /// surface on the side it came from, with the part of the rest of the move along the
    /// surface kept (so it slides) and the part into it dropped; then pushed out to
    /// `thickness` from the nearest point. `None`: the move stays clear.
    pub fn catch(&self, from: Vec3, to: Vec3, thickness: f32) -> Option<Caught> {
        self.catch_remembering(from, to, thickness, None)
    }

    /// [`Surface::catch`], with what the last catch of the same particle gathered (kept in
    /// `memory`, which this one updates): an end still well inside it walks no tree.
    pub fn catch_remembering(
        &self,
        from: Vec3,
        to: Vec3,
        thickness: f32,
        memory: Option<&mut Gathered>,
    ) -> Option<Caught> {
        match self.catch_short(from, to, thickness, memory) {
            Short::Clear => return None,
            Short::Caught(caught) => return Some(caught),
            Short::Unsure => {}
        }
        // One walk of the tree for the triangles near the whole move; the tree is walked
        // again for each question only when they are too many to hold, or the move ends
        // less than the thickness inside the box they were gathered from (triangles
        // outside it could then be within the thickness of the end).
        let pad = Vec3::splat(1.25 * thickness);
        let (lo, hi) = (from.min(to) - pad, from.max(to) + pad);
        let mut found = [0u32; NEAR];
        let mut count = 0;
        // Past NEAR triangles the walk stops: the tree answers each question instead.
        self.tree.overlapping_while(lo, hi, |t| {
            if let Some(slot) = found.get_mut(count) {
                *slot = t;
            }
            count += 1;
            count <= NEAR
        });
        if count == 0 {
            return None;
        }
        let few = (count <= NEAR).then_some(&found[..count.min(NEAR)]);
        let caught = self.catch_among(few, from, to, thickness);
        match (few, caught) {
            (Some(_), Some(c))
                if c.at.cmplt(lo + pad * 0.8).any() || c.at.cmpgt(hi - pad * 0.8).any() =>
            {
                self.catch_among(None, from, to, thickness)
            }
            _ => caught,
        }
    }

    /// Whether a move from `from` to `to` is told clear of every triangle by `memory` alone
    /// (what the last catch of the same particle gathered): then [`Surface::catch`] finds
    /// nothing either, and no tree is walked.
    #[inline]
    pub fn clears(from: Vec3, to: Vec3, thickness: f32, memory: &Gathered) -> bool {
        let reach = (1.0 + SLACK) * thickness;
        from.distance(to) < reach && memory.clears(to, reach)
    }

    /// [`Surface::catch`] for a move shorter than the distance from its end to the surface,
    /// which therefore crossed nothing (a resting or slow particle: nearly all of them), in
    /// one walk of the tree: the triangles within a little more than the thickness of the
    /// end are gathered, and the end is pushed out among them alone.
    fn catch_short(
        &self,
        from: Vec3,
        to: Vec3,
        thickness: f32,
        memory: Option<&mut Gathered>,
    ) -> Short {
        let reach = (1.0 + SLACK) * thickness;
        let moved = from.distance(to);
        if moved >= reach {
            return Short::Unsure;
        }
        // A remembered ball with no triangle in it that holds the end's reach: the move
        // lies within the reach of its end, so it meets nothing.
        if memory.as_ref().is_some_and(|m| m.clears(to, reach)) {
            return Short::Clear;
        }
        let mut near = [Near::default(); NEAR_END];
        let Some(count) = self.gather(to, reach, memory, DRIFT * thickness, &mut near) else {
            return Short::Unsure;
        };
        let near = &near[..count];
        // At the end itself, the points and distances the gathering found.
        let first = nearest_of(near.iter().copied());
        // Elsewhere, measured: but a triangle `d` from the end is at least `d` less how far
        // the end was pushed from the point asked about, and where that is beyond what
        // would push it (by more than the distances' rounding), it is not measured (it
        // could not be the nearest of those that push).
        let pushes = thickness * (1.0 - 1e-4);
        let rounding = rounding_near(to);
        let nearest = |end: Vec3| {
            let beyond = pushes + rounding + end.distance(to);
            let measured = (near.iter()).filter(|n| n.distance <= beyond).map(|n| {
                let point = closest_on_triangle(end, self.tree.place(n.place));
                let distance = end.distance(point);
                Near {
                    point,
                    distance,
                    ..*n
                }
            });
            nearest_of(measured)
        };
        // The move lies within `moved` of its end: with no surface that near, it crossed
        // nothing.
        if first.is_some_and(|n| moved >= n.distance) {
            return Short::Unsure;
        }
        let mut end = to;
        let mut held = None;
        for push in 0..PUSHES {
            let found = if push == 0 { first } else { nearest(end) };
            let Some(Near {
                triangle,
                point,
                distance,
                ..
            }) = found
            else {
                break;
            };
            if distance >= pushes {
                break;
            }
            let n = self.away(triangle, point, distance, end, from, thickness);
            end = point + n * thickness;
            held = Some((n, triangle, point));
        }
        // Pushed further than the gathering reached: triangles not gathered could hold it.
        if end.distance(to) > reach - thickness {
            return Short::Unsure;
        }
        match held {
            None => Short::Clear,
            Some((normal, triangle, on_surface)) => Short::Caught(Caught {
                at: end,
                normal,
                triangle,
                on_surface,
            }),
        }
    }

    /// Every triangle within `reach` of `p`, by number, with its point nearest to `p` and
    /// the distance to it, written to `near`; returns how many (`None`: more than
    /// [`NEAR_END`]). From `memory` when `p`'s reach lies inside what it holds; else from a
    /// walk of the tree that gathers `drift` further and is remembered there (where that
    /// finds none, as a ball with none in it out to the nearest triangle, up to [`CLEAR`]
    /// times the reach).
    fn gather(
        &self,
        p: Vec3,
        reach: f32,
        memory: Option<&mut Gathered>,
        drift: f32,
        near: &mut [Near; NEAR_END],
    ) -> Option<usize> {
        let mut count = 0;
        let Some(memory) = memory else {
            self.tree.within(p, reach, |n| {
                if let Some(slot) = near.get_mut(count) {
                    *slot = n;
                }
                count += 1;
                count <= NEAR_END
            });
            let found = near.get_mut(..count)?;
            found.sort_unstable_by_key(|n| n.triangle);
            return Some(count);
        };
        let mut moved = p.distance(memory.centre);
        if memory.radius < reach + moved {
            let radius = reach + drift;
            let mut all = [Near::default(); NEAR_END];
            let mut n = 0;
            self.tree.within(p, radius, |found| {
                if let Some(slot) = all.get_mut(n) {
                    *slot = found;
                }
                n += 1;
                n <= NEAR_END
            });
            let Some(found) = all.get_mut(..n) else {
                // Too many to remember: this end alone, from the tree.
                *memory = Gathered::NONE;
                return self.gather(p, reach, None, drift, near);
            };
            found.sort_unstable_by_key(|n| n.triangle);
            // Nothing that near: the ball is as wide as the nearest triangle's distance
            // (up to `CLEAR` times the reach), less its rounding, so that an end which
            // keeps away walks no tree for many substeps.
            let radius = if n == 0 {
                let look = CLEAR * reach;
                let nearest = self.tree.nearest(p, look).map_or(look, |q| q.distance);
                (nearest - rounding_near(p)).max(radius)
            } else {
                radius
            };
            *memory = Gathered {
                centre: p,
                radius,
                count: n as u8,
                places: all.map(|n| n.place),
                distances: all.map(|n| n.distance),
            };
            moved = 0.0;
        }
        // A triangle `d` from the centre is at least `d − moved` from `p`: beyond the
        // reach by more than the distances' rounding, it is not measured, and would not
        // have been kept.
        let beyond = reach + moved + rounding_near(p);
        let remembered = &memory.places[..usize::from(memory.count)];
        for (&place, &d) in remembered.iter().zip(&memory.distances) {
            if d > beyond {
                continue;
            }
            let point = closest_on_triangle(p, self.tree.place(place));
            let d2 = p.distance_squared(point);
            if d2 <= reach * reach {
                near[count] = Near {
                    place,
                    triangle: self.tree.number(place),
                    point,
                    distance: d2.sqrt(),
                };
                count += 1;
            }
        }
        Some(count)
    }

    /// The way out of the surface for `end`, `distance` from `point` of `triangle`: away
    /// from the point, or, on the surface, off it on the side of `start`.
    fn away(
        &self,
        triangle: u32,
        point: Vec3,
        distance: f32,
        end: Vec3,
        start: Vec3,
        thickness: f32,
    ) -> Vec3 {
        if distance > thickness * 1e-3 {
            (end - point) / distance
        } else {
            let face = self.normals[triangle as usize];
            if (start - point).dot(face) >= 0.0 {
                face
            } else {
                -face
            }
        }
    }

    /// [`Surface::catch`] over the triangles `few` (all of them, through the tree, when
    /// `None`).
    fn catch_among(
        &self,
        few: Option<&[u32]>,
        from: Vec3,
        to: Vec3,
        thickness: f32,
    ) -> Option<Caught> {
        let corners = |t: u32| self.triangles[t as usize].map(|i| self.vertices[i as usize]);
        let first_crossing = |a: Vec3, b: Vec3| match few {
            None => self.tree.first_crossing(a, b),
            Some(few) => (few.iter())
                .filter_map(|&t| segment_crosses(a, b, corners(t)).map(|at| (t, at)))
                .min_by(|x, y| x.1.total_cmp(&y.1)),
        };
        let nearest = |p: Vec3| match few {
            None => self.tree.nearest(p, thickness),
            Some(few) => (few.iter())
                .map(|&t| (t, closest_on_triangle(p, corners(t))))
                .map(|(t, q)| (t, q, p.distance(q)))
                .filter(|(_, _, d)| *d <= thickness)
                .min_by(|x, y| x.2.total_cmp(&y.2))
                .map(|(triangle, point, distance)| Nearest {
                    triangle,
                    point,
                    distance,
                }),
        };
        let (mut start, mut end) = (from, to);
        let mut normal = None;
        let mut held = (0, Vec3::ZERO);
        for _ in 0..CROSSINGS {
            let Some((triangle, t)) = first_crossing(start, end) else {
                break;
            };
            let face = self.normals[triangle as usize];
            let hit = start + (end - start) * t;
            // The side it came from: where the move's start is, or against the move.
            let side = match (start - hit).dot(face) {
                s if s > 0.0 => 1.0,
                s if s < 0.0 => -1.0,
                _ => -(end - start).dot(face).signum(),
            };
            let n = face * side;
            let rest = end - hit;
            let along = rest - rest.dot(n).min(0.0) * n;
            start = hit + n * thickness;
            end = start + along;
            normal = Some(n);
            held = (triangle, hit);
        }
        for _ in 0..PUSHES {
            let Some(near) = nearest(end) else {
                break;
            };
            if near.distance >= thickness * (1.0 - 1e-4) {
                break;
            }
            let n = self.away(
                near.triangle,
                near.point,
                near.distance,
                end,
                start,
                thickness,
            );
            end = near.point + n * thickness;
            normal = Some(n);
            held = (near.triangle, near.point);
        }
        normal.map(|normal| Caught {
            at: end,
            normal,
            triangle: held.0,
            on_surface: held.1,
        })
    }
}

/// Of the triangles near some end (each with its point nearest to it and the distance),
/// the nearest (the first of equals).
fn nearest_of(near: impl Iterator<Item = Near>) -> Option<Near> {
    near.min_by(|x, y| x.distance.total_cmp(&y.distance))
}

#[cfg(test)]
mod tests;
