//! How the pairs are found: each particle's box and path, the whole search of the tree
//! (fitted to the boxes or to the motion, with the patches and the corners decided for
//! it), and the refresh of the triangles whose particles left their boxes.

use glam::{Vec3, Vec3A};

use crate::parallel::fold_parts;
use crate::sim::self_contacts::costs::few_refreshed_cheaper;

use super::*;

/// The particles' boxes are given room for later substeps only while none moves more
/// than this share of the thickness in a substep in the moving frame, or so few do that
/// refreshing their triangles costs less than the whole searches by the motion
/// ([`few_refreshed_cheaper`]: in `layers` 10 of 3 125 particles held the whole cloth to
/// a whole search every other substep). Room for the slow particles alone was tried:
/// where `crumple` piles up, it kept 15 000–20 000 pairs at 64² against a few hundred, and
/// cost more than the searches it saved.
const REUSE_BELOW: f32 = 0.5;

/// How far, as a share of the thickness, a particle may stray from the path a window
/// foresaw for it before its triangles are searched again (the pairs are kept for twice
/// as much more than the thickness).
const ALLOWANCE: f32 = 0.2;

/// A triangle's box may be at most this many times the cloth's cell (twice its longest
/// edge, or twice the thickness): wider, the state has blown up, and is refused rather
/// than searched (every pair of the cloth could be near).
const WIDEST: f32 = 1e6;

/// Judged by the boxes alone (the cloth slow in the moving frame), each particle's box
/// holds its motion carried on at the same velocity for some substeps more, up to some
/// share of the thickness, as `(substeps, share)`: a particle that creeps (cloth sliding
/// slowly off a sphere) stays in it that much longer before its triangles are searched
/// again. This one where the pairs last found are few (fewer than one a particle: a cloth
/// creeping on its own): where `crumple` creeps over the sphere at 64², it left half as
/// many particles out of their boxes a substep as [`AHEAD_MANY`] (167 → 88); 48 substeps
/// up to two thicknesses kept ten times the pairs.
const AHEAD_FEW: (f32, f32) = (24.0, 1.0);

/// [`AHEAD_FEW`] where the pairs are many: a particle pushed about every substep (a stack
/// of cloths pressed together in `layers`, 46 pairs a particle) gets a box no longer than
/// a quarter of the thickness, not as long as its pushes carried on (with [`AHEAD_FEW`]
/// there, `layers` ran 4–5 % slower).
const AHEAD_MANY: (f32, f32) = (12.0, 0.25);

/// Triangles from which the search shares its work out between the team's members.
const PARALLEL_TRIANGLES: usize = 2048;

impl SelfContacts {
    /// Where the pairs are judged by the motion, decides which corners' pairs the search
    /// tests ([`Certificates::decide`], for the motion the boxes were made for); after a
    /// refresh (`refreshed`), only the corners of the triangles searched again.
    pub(super) fn decide_corners(
        &mut self,
        triangles: &[[u32; 3]],
        thickness: f32,
        refreshed: bool,
    ) {
        if self.boxes.swept {
            let (motion, lanes) = (self.boxes.paths(), self.boxes.motion());
            // Closed as they are: in a whole search the corners the patches cover (a
            // refresh decides those whose motion changed, covered or not), and those whose
            // reference fails but whose ring keeps near its rest shape.
            let (patches, tree, reach) = (&self.patches, &self.tree, self.reach(thickness));
            let only = refreshed.then_some(&self.touched[..]);
            let covered = |c: usize| !refreshed && patches.covers(tree, c);
            let rings = &self.owners.rings;
            let near_rest =
                |c: usize| patches.ring_holds(c, (triangles, rings.triangles_of(c)), lanes, reach);
            let settled: [&(dyn Fn(usize) -> bool + Sync); 2] = [&covered, &near_rest];
            let certificates = &mut self.certificates;
            self.work.retaken +=
                certificates.decide(&self.owners, triangles, motion, reach, only, settled);
        }
    }

    /// How far a particle may stray from its path in the window, m: none in a window of
    /// one substep, whose paths are the motion itself.
    pub(super) fn allowance(&self, thickness: f32) -> f32 {
        if self.window.len > 1 {
            ALLOWANCE * thickness
        } else {
            0.0
        }
    }

    /// How near along their paths the pairs judged by the motion are kept, m: the
    /// thickness and twice the allowance.
    pub(super) fn reach(&self, thickness: f32) -> f32 {
        thickness + 2.0 * self.allowance(thickness)
    }

    /// What a search of the cloth of `triangles` for `thickness` reads: the owners, the
    /// boxes, the reach, and which corners the certificates left open. (The pairs it
    /// finds are taken out of the solver meanwhile, to be filled while this is read.)
    pub(super) fn search<'a>(&'a self, triangles: &'a [[u32; 3]], thickness: f32) -> Search<'a> {
        Search {
            owners: &self.owners,
            triangles,
            boxes: &self.boxes,
            thickness: self.reach(thickness),
            open: &self.certificates.open,
        }
    }

    /// How much each particle's box is grown around its motion, m: half the thickness and
    /// the allowance where the pairs are judged by the motion, three quarters of the
    /// thickness where by the boxes (room to reuse them).
    pub(super) fn grow(&self, thickness: f32) -> f32 {
        if self.boxes.swept {
            0.5 * thickness + self.allowance(thickness)
        } else {
            0.75 * thickness
        }
    }

    /// How far each particle's box reaches beyond its motion, as `(substeps, share of the
    /// thickness at most)`: [`AHEAD_FEW`] or [`AHEAD_MANY`] by the pairs found last, where
    /// the pairs are judged by the boxes alone; none (`None`) where by the motion (the
    /// window carries it on).
    pub(super) fn look_ahead(&self) -> Option<(f32, f32)> {
        if self.boxes.swept {
            return None;
        }
        Some(if self.found.len() < self.from.len() {
            AHEAD_FEW
        } else {
            AHEAD_MANY
        })
    }

    /// The box that holds a particle's motion from `s` to `p`, grown by `grow` each way.
    pub(super) fn vertex_box(s: Vec3, p: Vec3, grow: f32) -> (Vec3, Vec3) {
        (s.min(p) - Vec3::splat(grow), s.max(p) + Vec3::splat(grow))
    }

    /// Triangle `n`'s box (its corners `t`): its corners' boxes together.
    ///
    /// # Errors
    /// [`ContactError::Extent`] for a box wider than [`WIDEST`] times the cloth's cell
    /// (twice its longest edge, or twice the thickness): a state that has blown up.
    pub(super) fn triangle_box(
        &self,
        n: usize,
        t: [u32; 3],
        thickness: f32,
    ) -> Result<(Vec3, Vec3), ContactError> {
        let [a, b, c] = t.map(|i| i as usize);
        let (lo, hi) = (&self.boxes.vertex_lo, &self.boxes.vertex_hi);
        let (lo, hi) = (lo[a].min(lo[b]).min(lo[c]), hi[a].max(hi[b]).max(hi[c]));
        let (extent, cell) = ((hi - lo).max_element(), self.owners.cell(thickness));
        if extent > WIDEST * cell {
            return Err(ContactError::Extent {
                triangle: n,
                extent,
                cell,
            });
        }
        Ok((lo, hi))
    }

    /// The particles that [`SelfContacts::update_pairs`] found out of their boxes get new
    /// ones; the pairs of every triangle they are corners of are dropped and searched
    /// again against the whole tree, fitted again where those triangles lie. The pairs of
    /// two triangles neither of which moved out stand: their boxes are the same.
    pub(super) fn refresh(
        &mut self,
        model: &ClothModel,
        thickness: f32,
    ) -> Result<(), ContactError> {
        // Until the pairs are whole again (an error on the way leaves them not).
        self.found_for = None;
        let (window, grow, look) = (self.window, self.grow(thickness), self.look_ahead());
        // The triangles searched again: those a particle that left is a corner of, in
        // order; and the corners whose pairs lie on them: those particles and their rings.
        let (n, rings) = (model.triangles.len(), &self.owners.rings);
        self.dirty.clear();
        self.dirty.resize(n, false);
        self.touched.clear();
        self.touched.resize(self.left.len(), false);
        self.searched.clear();
        for (i, _) in self.left.iter().enumerate().filter(|(_, l)| **l) {
            let (mut s, mut p) = (self.from[i], self.to[i]);
            if self.boxes.swept {
                // The particle's path in the window from its motion now, carried on both
                // ways at its velocity.
                if window.len > 1 {
                    let v = p - s;
                    (s, p) = (
                        s - v * window.at as f32,
                        s + v * (window.len - window.at) as f32,
                    );
                }
                self.boxes.set_path(i, s, p);
            }
            let ahead = ahead(look, s, p, thickness);
            (self.boxes.vertex_lo[i], self.boxes.vertex_hi[i]) = Self::vertex_box(s, ahead, grow);
            self.touched[i] = true;
            for &j in &rings.ring[rings.range(i)] {
                self.touched[j as usize] = true;
            }
            for &t in rings.triangles_of(i) {
                if !std::mem::replace(&mut self.dirty[t as usize], true) {
                    self.searched.push(t);
                }
            }
        }
        self.searched.sort_unstable();
        if !self.boxes.swept {
            for &t in &self.searched {
                let (t, corners) = (t as usize, model.triangles[t as usize]);
                (self.boxes.lo[t], self.boxes.hi[t]) = self.triangle_box(t, corners, thickness)?;
            }
        }
        self.fit_tree(model, thickness, true)?;
        // Only the corners with a triangle searched again are decided again. One that was
        // closed and is open now still leaves out the pairs of its triangles that stayed:
        // it held for their motion, which has not changed.
        self.decide_corners(&model.triangles, thickness, true);
        if !self.boxes.swept {
            // The patches' certificate held for the places the boxes allowed: not for the
            // particles that left theirs, nor for the corners whose pairs they are on.
            self.certificates.reopen(&self.touched);
        }
        let (tree, dirty, touched) = (&self.tree, &self.dirty, &self.touched);
        let owner = &self.owners.vertex_owner;
        let mut found = std::mem::take(&mut self.found);
        found.retain(|p| p.triangles(owner).iter().all(|&t| !dirty[t as usize]));
        let search = self.search(&model.triangles, thickness);
        let searched = &self.searched;
        let pieces = searched.len().div_ceil(REFRESHED_PER_PIECE);
        let work = |piece: usize, out: &mut Vec<StoredPair>| {
            if piece >= pieces {
                // The pairs of triangles sharing a corner, where either is one of those.
                return search.neighbours(piece - pieces, Some([dirty, touched]), out);
            }
            let (first, mut tested) = (piece * REFRESHED_PER_PIECE, 0);
            for &t in &searched[first..(first + REFRESHED_PER_PIECE).min(searched.len())] {
                tree.triangle_pairs(t, dirty, |a, b| {
                    tested += 1;
                    search.pairs_of(a as usize, b as usize, out);
                });
            }
            tested
        };
        let refreshed = searched.len();
        let parallel = refreshed >= PARALLEL_REFRESHED;
        let tested = found.extend(pieces + search.neighbour_pieces(), parallel, &work);
        self.found = found;
        (self.costs).refreshed(refreshed, tested);
        self.work.refreshes += 1;
        self.work.refreshed += refreshed as u64;
        self.found_for = Some(thickness);
        Ok(())
    }

    /// Where the pairs are judged by the boxes, covers the patches certified for every
    /// place their particles may take while the pairs hold: a particle's motion keeps
    /// within its box less half the thickness, so within that room's half-diagonal of the
    /// box's middle, and so does every point of its triangles of the one where the
    /// middles put it. A patch certified (by either certificate) to keep its pairs `reach`
    /// apart with its particles at the middles, `reach` the thickness and twice the
    /// widest room of its own particles, keeps them the thickness apart wherever in their
    /// rooms they go. The corners whose ring a covered patch holds are closed, the others
    /// open. A patch whose widest room leaves the rest gap nothing to certify (a particle
    /// whose box looks far ahead) is not covered; the others still are.
    pub(super) fn cover_boxes(&mut self, triangles: &[[u32; 3]], thickness: f32) {
        let half = Vec3::splat(0.5 * thickness);
        let (lo, hi) = (&self.boxes.vertex_lo, &self.boxes.vertex_hi);
        self.middles.clear();
        self.middles.extend(
            lo.iter()
                .zip(hi)
                .map(|(&lo, &hi)| Vec3A::from(0.5 * (lo + hi))),
        );
        self.rooms.clear();
        (self.rooms).extend(
            (lo.iter().zip(hi)).map(|(&lo, &hi)| (0.5 * (hi - lo) - half).max(Vec3::ZERO).length()),
        );
        let (tree, backoff) = (&mut self.tree, &mut self.backoff);
        let rooms = (thickness, &self.rooms[..]);
        (self.patches).decide_in_rooms(tree, triangles, &self.middles, rooms, backoff);
        let (patches, tree) = (&self.patches, &self.tree);
        (self.certificates).open_unless(lo.len(), |c| patches.covers(tree, c));
    }

    /// Fits the tree to the boxes, or where the pairs are judged by the motion, to the
    /// motion the boxes were made for (told apart by the thickness); `refreshed`, only the
    /// triangles searched again (the others' stand as the last fit left them).
    ///
    /// # Errors
    /// As [`SelfContacts::triangle_box`], where the pairs are judged by the motion (the
    /// triangles' boxes are not kept then: the fit tells how wide the widest is, and only
    /// where that comes near the limit are they all measured).
    pub(super) fn fit_tree(
        &mut self,
        model: &ClothModel,
        thickness: f32,
        refreshed: bool,
    ) -> Result<(), ContactError> {
        let changed = &self.searched[..];
        if self.boxes.swept {
            let (motion, reach) = (self.boxes.motion(), self.reach(thickness));
            let widest = if refreshed {
                self.tree.refit_motion(changed, motion, reach)
            } else {
                self.tree.fit_motion(motion, reach)
            };
            let widest = widest + 2.0 * self.grow(thickness);
            if widest >= 0.999 * WIDEST * self.owners.cell(thickness) {
                for (n, &t) in model.triangles.iter().enumerate() {
                    self.triangle_box(n, t, thickness)?;
                }
            }
        } else if refreshed {
            self.tree
                .refit_boxes(changed, &self.boxes.lo, &self.boxes.hi);
        } else {
            self.tree.fit_boxes(&self.boxes.lo, &self.boxes.hi);
        }
        Ok(())
    }

    /// The pairs of every two triangles whose boxes overlap, each particle's box its
    /// motion grown by half the thickness, or (where the whole cloth moves slowly in the
    /// moving frame) three quarters of it, so that the pairs hold for the substeps after
    /// while each particle's motion stays in its box less half the thickness.
    pub(super) fn find_pairs(
        &mut self,
        model: &ClothModel,
        thickness: f32,
    ) -> Result<(), ContactError> {
        self.found_for = None;
        // Room to reuse the pairs only where the cloth moves slowly in the moving frame; a
        // fast substep would leave its boxes at once, and the room would only add pairs.
        let (from, to) = (&self.from, &self.to);
        // The fastest particle, and how many move at least the share of the thickness.
        let reuse = (REUSE_BELOW * thickness).powi(2);
        let part = |range: std::ops::Range<usize>| {
            let (from, to) = (within(from, range.clone()), within(to, range));
            (from.iter().zip(to))
                .map(|(s, p)| s.distance_squared(*p))
                .fold((0.0f32, 0), |(most, fast), d| {
                    (most.max(d), fast + usize::from(d >= reuse))
                })
        };
        let len = from.len().min(to.len());
        let join = |(a, m): (f32, usize), (b, n): (f32, usize)| (a.max(b), m + n);
        let (fastest, fast) = fold_parts(len, part, join).unwrap_or((0.0, 0));
        // Slow, or so few fast that refreshing their triangles costs less than the whole
        // searches by the motion would.
        let few = few_refreshed_cheaper(fast, model.triangles.len(), len);
        let slow = fastest.sqrt() < REUSE_BELOW * thickness || few;
        // Fast, the pairs are judged by the motion too (see `Boxes::swept`), carried on
        // for a window: twice as long as the last where it ran out, half where it did
        // not.
        self.window = self.window.next(slow, self.boxes.swept);
        self.boxes.swept = !slow;
        if self.boxes.swept {
            (self.boxes).set_motion(&self.from, &self.to, self.window.len);
        }
        let (grow, swept, look) = (self.grow(thickness), self.boxes.swept, self.look_ahead());
        // The boxes taken out while the paths are read.
        let (mut lo, mut hi) = (
            std::mem::take(&mut self.boxes.vertex_lo),
            std::mem::take(&mut self.boxes.vertex_hi),
        );
        let [from, to] = if swept {
            self.boxes.paths()
        } else {
            [&self.from[..], &self.to[..]]
        };
        lo.resize(from.len(), Vec3::ZERO);
        hi.resize(from.len(), Vec3::ZERO);
        each_part([&mut lo[..], &mut hi[..]], |range, [lo, hi]| {
            for ((lo, hi), i) in lo.iter_mut().zip(hi).zip(range) {
                let (s, p) = (from[i], to[i]);
                (*lo, *hi) = Self::vertex_box(s, ahead(look, s, p, thickness), grow);
            }
        });
        (self.boxes.vertex_lo, self.boxes.vertex_hi) = (lo, hi);
        self.search_all(model, thickness)
    }

    /// The pairs of every two triangles whose boxes overlap, from the particles' boxes as
    /// they are.
    pub(super) fn search_all(
        &mut self,
        model: &ClothModel,
        thickness: f32,
    ) -> Result<(), ContactError> {
        self.found_for = None;
        self.boxes.lo.clear();
        self.boxes.hi.clear();
        if !self.boxes.swept {
            for (n, &t) in model.triangles.iter().enumerate() {
                let (lo, hi) = self.triangle_box(n, t, thickness)?;
                self.boxes.lo.push(lo);
                self.boxes.hi.push(hi);
            }
        }
        self.fit_tree(model, thickness, false)?;
        self.found.clear();
        if self.boxes.swept {
            let (motion, reach) = (self.boxes.motion(), self.reach(thickness));
            (self.patches).decide(
                &mut self.tree,
                &model.triangles,
                motion,
                reach,
                &mut self.backoff,
            );
        } else {
            self.cover_boxes(&model.triangles, thickness);
        }
        self.decide_corners(&model.triangles, thickness, false);
        let mut found = std::mem::take(&mut self.found);
        let search = self.search(&model.triangles, thickness);
        let tree = &self.tree;
        let work = |piece: usize, out: &mut Vec<StoredPair>| {
            if piece >= tree.pieces() {
                return search.neighbours(piece - tree.pieces(), None, out);
            }
            let mut tested = 0;
            tree.piece_pairs(piece, |a, b| {
                tested += 1;
                search.pairs_of(a as usize, b as usize, out);
            });
            tested
        };
        let parallel = model.triangles.len() >= PARALLEL_TRIANGLES;
        let pieces = tree.pieces() + search.neighbour_pieces();
        let tested = found.extend(pieces, parallel, &work);
        self.found = found;
        (self.costs).searched(model.triangles.len(), tested);
        self.work.searches += 1;
        self.found_for = Some(thickness);
        Ok(())
    }
}

/// Where a particle's box reaches to beyond its motion from `s` to `p`: that motion carried
/// on as `look` says ([`SelfContacts::look_ahead`]); `p` with none.
fn ahead(look: Option<(f32, f32)>, s: Vec3, p: Vec3, thickness: f32) -> Vec3 {
    let Some((substeps, most)) = look else {
        return p;
    };
    p + ((p - s) * substeps).clamp_length_max(most * thickness)
}
