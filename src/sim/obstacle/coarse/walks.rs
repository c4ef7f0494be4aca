//! The walks the bound takes over a surface's faces: from a vertex's (or an edge's) own
//! faces across the gentle edges, out to a reach, gathering the steepest turn of the faces
//! in each ring of distance ([`super`]); and several vertices' walks taken as one, over the
//! faces any of them reaches.

use glam::Vec3;
use wide::f32x8;

use super::super::edges::CREASE_COS;
use super::super::geometry::{face_normals, sides_by_edge};
use crate::sim::kernels::{LANES, Vec3x8};

/// A surface's faces as the bound reads them: each one's unit normal and box, and its
/// neighbours across its edges where the two meet neither at a crease nor at a border.
/// The bound follows the surface from a point through those alone: beyond a crease (a
/// table's rim, a drum's cap) the crease itself keeps the cloth off.
pub(super) struct Faces<'a> {
    pub(super) triangles: &'a [[u32; 3]],
    pub(super) normals: &'a [Vec3],
    /// What a walk reads of each face, side by side ([`walked_faces`]).
    pub(super) walked: &'a [Walked],
    /// Each vertex's first at its place.
    pub(super) same: &'a [u32],
}

/// A face as the walks read it: its box, its unit normal, and its neighbours across its
/// three edges.
#[derive(Clone, Copy)]
pub(super) struct Walked {
    pub(super) lo: Vec3,
    pub(super) hi: Vec3,
    pub(super) normal: Vec3,
    pub(super) across: [u32; 3],
}

/// A vertex whose walk is taken with others' ([`Faces::walk_together`]): the vertex (the
/// first at its place), its place, the direction its faces' turns are measured from, how
/// many rings it gathers, and its faces (by the vertex: `(vertex, face)`).
pub(super) struct Walker<'f> {
    pub(super) vertex: u32,
    pub(super) at: Vec3,
    pub(super) reference: Vec3,
    pub(super) rings: usize,
    pub(super) fan: &'f [(u32, u32)],
}

/// What the walks read of a surface's faces in one place: each face's unit normal, and
/// its box and neighbours ([`walked_faces`]).
pub(super) struct FacesAt {
    normals: Vec<Vec3>,
    walked: Vec<Walked>,
}

impl FacesAt {
    /// The faces `triangles` at `place`, `same` giving each vertex the first at its place.
    pub(super) fn of(place: &[Vec3], triangles: &[[u32; 3]], same: &[u32]) -> Self {
        let normals = face_normals(place, triangles);
        let walked = walked_faces(place, triangles, &normals, same);
        Self { normals, walked }
    }

    /// These faces as the walks read them.
    pub(super) fn faces<'a>(&'a self, triangles: &'a [[u32; 3]], same: &'a [u32]) -> Faces<'a> {
        Faces {
            triangles,
            normals: &self.normals,
            walked: &self.walked,
            same,
        }
    }
}

/// No neighbour across an edge.
pub(super) const NONE: u32 = u32::MAX;

/// The scratch of the bound's walks over a surface's faces: each face's last walk, the
/// walks so far, and the faces met in the current one, in order.
pub(super) struct Walk {
    seen: Vec<u32>,
    walks: u32,
    met: Vec<u32>,
}

impl Walk {
    pub(super) fn over(faces: &Faces<'_>) -> Self {
        Walk {
            seen: vec![0; faces.normals.len()],
            walks: 0,
            met: Vec::new(),
        }
    }
}

/// What the bound's walks read of each of the faces `triangles` over `vertices`, each
/// with its unit normal in `normals` (zero for a degenerate one, which has no
/// neighbours); `same` gives each vertex the first at its place (`welded`), which is one
/// vertex with it.
fn walked_faces(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    normals: &[Vec3],
    same: &[u32],
) -> Vec<Walked> {
    // The sides of the faces along each edge; a degenerate face has none.
    let sides = sides_by_edge(triangles, same, |t| normals[t] != Vec3::ZERO);
    let mut across = vec![[NONE; 3]; triangles.len()];
    for sides in sides.chunk_by(|x, y| x.0 == y.0) {
        if let [(_, one), (_, two)] = *sides {
            let ([s, j], [t, k]) = ([one / 3, one % 3], [two / 3, two % 3]);
            if normals[s as usize].dot(normals[t as usize]).abs() >= CREASE_COS {
                across[s as usize][j as usize] = t;
                across[t as usize][k as usize] = s;
            }
        }
    }
    (triangles.iter().zip(normals).zip(across))
        .map(|((t, &normal), across)| {
            let [p, q, r] = t.map(|i| vertices[i as usize]);
            let (lo, hi) = (p.min(q).min(r), p.max(q).max(r));
            Walked {
                lo,
                hi,
                normal,
                across,
            }
        })
        .collect()
}

impl Faces<'_> {
    /// The cosine of the angle between the faces `s` and `t` (unsigned).
    pub(super) fn turn(&self, [s, t]: [u32; 2]) -> f32 {
        self.normals[s as usize].dot(self.normals[t as usize]).abs()
    }

    /// Each vertex's faces (the vertex first at its place, a face), by vertex.
    pub(super) fn fans(&self) -> Vec<(u32, u32)> {
        let mut fans: Vec<(u32, u32)> = (self.triangles.iter().enumerate())
            .filter(|&(t, _)| self.normals[t] != Vec3::ZERO)
            .flat_map(|(t, tri)| tri.map(|i| (self.same[i as usize], t as u32)))
            .collect();
        fans.sort_unstable();
        fans
    }

    /// Walks from the faces `starts` across gentle and flat edges (nearest first) the
    /// faces whose boxes lie within `reach` of the box `lo..hi`, handing each to `visit`
    /// with that distance; a face farther is neither handed on nor walked through.
    #[inline(always)]
    fn walk_within(
        &self,
        walk: &mut Walk,
        (starts, (lo, hi), reach): (impl IntoIterator<Item = u32>, (Vec3, Vec3), f32),
        mut visit: impl FnMut(&Walked, f32),
    ) {
        walk.walks += 1;
        let walked = walk.walks;
        walk.met.clear();
        for s in starts {
            if walk.seen[s as usize] != walked {
                walk.seen[s as usize] = walked;
                walk.met.push(s);
            }
        }
        let mut at = 0;
        while let Some(&t) = walk.met.get(at) {
            at += 1;
            let face = &self.walked[t as usize];
            let apart = (face.lo - hi).max(lo - face.hi).max(Vec3::ZERO).length();
            if apart > reach {
                continue;
            }
            visit(face, apart);
            for u in face.across {
                if u != NONE && walk.seen[u as usize] != walked {
                    walk.seen[u as usize] = walked;
                    walk.met.push(u);
                }
            }
        }
    }

    /// Walks from the faces `starts` across gentle and flat edges (nearest first) the
    /// faces whose boxes lie within `least.len()` rings of `width` of the box `lo..hi`,
    /// keeping each ring's least cosine (unsigned) to `reference` in `least`.
    pub(super) fn walk_rings(
        &self,
        walk: &mut Walk,
        starts: impl IntoIterator<Item = u32>,
        (place, reference): ((Vec3, Vec3), Vec3),
        (width, least): (f32, &mut [f32]),
    ) {
        let rings = least.len();
        least.fill(1.0);
        let walk_from = (starts, place, width * rings as f32);
        self.walk_within(walk, walk_from, |face, apart| {
            let ring = ((apart / width) as usize).min(rings - 1);
            least[ring] = least[ring].min(face.normal.dot(reference).abs());
        });
    }

    /// The walks of `walkers` (at most [`LANES`]) taken as one: from all their faces, over
    /// the faces within the reach of the box round their places, each face gathered into
    /// the rings (of `width`) of every walker it lies within the reach of, as that
    /// walker's own walk ([`Faces::walk_rings`] from its place, as many rings as it asks)
    /// gathers it; `least[k]` takes walker `k`'s least cosine in each ring. Every face a
    /// walker's own walk meets, this one meets (that face, and each on the way to it, lies
    /// within the walker's reach, so within the box's); it may meet more (one the walker's
    /// own walk reaches only round a hole, beyond its reach), which only raises a bound
    /// from above. The walkers go a lane each, each lane doing its own walk's IEEE
    /// operations in their order: the same bits.
    pub(super) fn walk_together<const N: usize>(
        &self,
        walk: &mut Walk,
        walkers: &[Walker<'_>],
        width: f32,
        least: &mut [[f32; N]],
    ) {
        crate::parallel::wide(
            #[inline(always)]
            || self.walk_in_lanes(walk, walkers, width, least),
        );
    }

    /// [`Faces::walk_together`], inlined into the caller's lanes.
    #[inline(always)]
    fn walk_in_lanes<const N: usize>(
        &self,
        walk: &mut Walk,
        walkers: &[Walker<'_>],
        width: f32,
        least: &mut [[f32; N]],
    ) {
        assert!(walkers.len() <= LANES && least.len() >= walkers.len());
        let (mut lo, mut hi, mut reach) = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0.0f32);
        let (mut at, mut towards) = ([Vec3::ZERO; LANES], [Vec3::ZERO; LANES]);
        // Lanes past the walkers reach nothing.
        let (mut reaches, mut last) = ([-1.0f32; LANES], [0usize; LANES]);
        for (k, w) in walkers.iter().enumerate() {
            (lo, hi) = (lo.min(w.at), hi.max(w.at));
            reaches[k] = width * w.rings as f32;
            reach = reach.max(reaches[k]);
            (at[k], towards[k], last[k]) = (w.at, w.reference, w.rings - 1);
        }
        let (at, towards) = (Vec3x8::pack(at), Vec3x8::pack(towards));
        let (reaches, across) = (f32x8::from(reaches), f32x8::splat(width));
        least.iter_mut().for_each(|l| l.fill(1.0));
        let starts = walkers.iter().flat_map(|w| w.fan.iter().map(|&(_, f)| f));
        let walk_from = (starts, (lo, hi), reach);
        self.walk_within(
            walk,
            walk_from,
            #[inline(always)]
            |face: &Walked, _| {
                let (flo, fhi) = (Vec3x8::splat(face.lo), Vec3x8::splat(face.hi));
                let gap = (flo - at).max(at - fhi).max(Vec3x8::splat(Vec3::ZERO));
                let apart = gap.dot(gap).sqrt();
                let within = apart.simd_gt(reaches).to_bitmask() ^ 0xff;
                if within == 0 {
                    return;
                }
                let ring = (apart / across).trunc_int().to_array();
                let cos = Vec3x8::splat(face.normal).dot(towards).abs().to_array();
                for (k, least) in least.iter_mut().enumerate().take(walkers.len()) {
                    if within & (1 << k) != 0 {
                        let ring = (ring[k] as usize).min(last[k]);
                        least[ring] = least[ring].min(cos[k]);
                    }
                }
            },
        );
    }

    /// Each face's piece (a face's number): the faces joined across gentle and flat edges
    /// share one; a walk never leaves its starts' pieces.
    pub(super) fn pieces(&self) -> Vec<u32> {
        let mut piece = vec![NONE; self.walked.len()];
        let mut stack = Vec::new();
        for f in 0..piece.len() {
            if piece[f] != NONE {
                continue;
            }
            piece[f] = f as u32;
            stack.push(f as u32);
            while let Some(t) = stack.pop() {
                for u in self.walked[t as usize].across {
                    if u != NONE && piece[u as usize] == NONE {
                        piece[u as usize] = f as u32;
                        stack.push(u);
                    }
                }
            }
        }
        piece
    }
}
