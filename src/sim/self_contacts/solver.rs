//! The self-contact solver: finds the pairs, pushes them apart, and cuts motion that
//! could make a pair meet (see the module's notes).

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

use glam::{Vec3, Vec3A};

use crate::cloth::{ClothModel, ClothState};
use crate::parallel::{Disjoint, each_part, within};
use crate::sim::kernels::{leaves, less_into, outside};

use super::ccd::safe_fraction;
use super::certify::Certificates;
use super::costs::SearchCosts;
use super::error::ContactError;
use super::found::Found;
use super::patches::Patches;
use super::primitives::StoredPair;
use super::search::{Boxes, Owners, Search};
use super::sweeps::Sweeps;
use super::tree::TriangleTree;
use super::window::Window;
use super::work::SelfWork;

/// The separation the continuous check keeps, as a share of the thickness (pairs that
/// start closer keep half of what they start at).
const KEEP: f64 = 0.1;

/// Only the triangles whose particles left their boxes are searched again while those
/// particles are fewer than one in this many (and, judged by the boxes, the refreshes
/// since the last whole search have cost less than it did: [`SearchCosts`]); more, and
/// the whole tree is.
const REFRESH_BELOW: usize = 4;

/// The most triangles self-contact takes: a stored edge–edge pair numbers each edge as
/// three times its triangle's number and its side, below the bit that marks its kind.
const MOST_TRIANGLES: usize = (1 << 31) / 3;

/// The distance, as a share of the thickness, within which the continuous check needs
/// its pairs: twice what it keeps, for margin (pairs farther apart along the whole motion
/// cannot come within [`KEEP`]). The pushes need the whole thickness.
const CHECKED: f32 = 2.0 * KEEP as f32;

/// Gauss–Seidel sweeps of the pushes over the pairs.
const PUSH_SWEEPS: usize = 4;

/// The pushes' sweeps after the first go through only the pairs whose sides were closer
/// than this many thicknesses when the first came to them (see [`Sweeps`]).
const NEAR: f32 = 2.0;

/// Pairs from which the continuous check's rounds are shared with the team.
const PARALLEL_PAIRS: usize = 16_384;

/// Pairs a particle found by a substep's first search above which the state's springs are
/// measured against the guard's strain limit ([`SelfContacts::strain_limit`]). Cloth in
/// contact finds far fewer: at most 2.5 a particle in `crumple` at 64² and 34 in five
/// stacked cloths (`layers`) at 16² and 32², under implicit Euler, VBD and XPBD; a state
/// blown up within a frame, a spring of it stretched 20–650 times its rest length, 73–1 050.
/// A measure costs about as much as a spring-force pass, a fraction of the work such pairs
/// bring.
const SUSPECT_PAIRS: usize = 8;

/// Rounds of cuts by the safe fraction; after them, a pair that can still meet has its
/// free particles sent back to the substep's start.
const SCALED_ROUNDS: usize = 4;

/// The continuous check's cuts in a round, as atomics the team's members lower together.
/// Scratch: a clone starts empty.
#[derive(Debug, Default)]
struct Cuts(Vec<AtomicU64>);

impl Clone for Cuts {
    fn clone(&self) -> Self {
        Cuts::default()
    }
}

/// A substep's motion from `start` to `end`, to be put in the frame that moves with the
/// cloth: less `shift`, how far the frame had moved by the substep's start, and the end less
/// the substep's `mean` motion too.
#[derive(Clone, Copy)]
struct Moved<'a> {
    start: &'a [Vec3],
    end: &'a [Vec3],
    shift: Vec3,
    mean: Vec3,
}

impl Moved<'_> {
    /// Fills particles `range`'s start and end in the moving frame into `from` and `to`
    /// (that range of each).
    fn fill(&self, range: std::ops::Range<usize>, [from, to]: [&mut [Vec3]; 2]) {
        less_into(
            from,
            within(self.start, range.clone()),
            self.shift,
            Vec3::ZERO,
        );
        less_into(to, within(self.end, range), self.shift, self.mean);
    }
}

/// Reusable buffers of self-contact: nothing is allocated per substep once warm.
#[derive(Clone, Debug, Default)]
pub struct SelfContacts {
    tree: TriangleTree,
    /// The tree's patches certified apart by the rest shape.
    patches: Patches,
    /// Each particle's box's middle, where the patches are certified for the boxes, and
    /// how far from it the particle may go (the room its box leaves), m.
    middles: Vec<Vec3A>,
    rooms: Vec<f32>,
    /// How many searches each node's certificate is left out of (see [`Patches::decide`]).
    backoff: Vec<u8>,
    owners: Owners,
    /// The particles' and triangles' boxes the pairs were found with.
    boxes: Boxes,
    /// The substep's start and end in the frame that moves with the cloth, and how far
    /// that frame has moved.
    from: Vec<Vec3>,
    to: Vec<Vec3>,
    shift: Vec3,
    /// The cloth's mean motion in the last substep resolved.
    mean: Vec3,
    /// The pairs found: for every two triangles whose boxes overlap, their pairs whose
    /// particles' boxes could come within the thickness.
    found: Found,
    /// Which corners' pairs the cloth's relative motion keeps apart, where the pairs are
    /// judged by the motion.
    certificates: Certificates,
    /// Particles whose motion left their boxes, and the triangles they are corners of
    /// (as flags), for a refresh; and the corners whose pairs lie on those triangles (the
    /// particles that left and their rings).
    left: Vec<bool>,
    dirty: Vec<bool>,
    touched: Vec<bool>,
    /// The triangles a refresh searches again, in order.
    searched: Vec<u32>,
    /// The window the pairs judged by the motion were found for, and how far into it the
    /// substep resolved is.
    window: Window,
    /// Particles resting on a solid this substep (set by the stepper before
    /// [`SelfContacts::resolve`]): pushes move them only where nothing else can.
    pub held: Vec<bool>,
    /// The stability guard's strain limit (relative extension), where it judges the
    /// substep (set by the stepper before [`SelfContacts::resolve`]). A state whose first
    /// search finds more than 8 pairs a particle (`SUSPECT_PAIRS`) is measured against it,
    /// and one past it is refused ([`ContactError::Stretched`]) before the pushes and the
    /// continuous check, whose work grows with the pairs (a state blown up within a frame
    /// otherwise cost them seconds a substep, the guard judging strain at the frame's end
    /// only). `None`: not measured.
    pub strain_limit: Option<f32>,
    /// Particles the cuts leave alone besides the pinned (those the solids moved, in
    /// [`SelfContacts::settle`]); empty: none.
    fixed: Vec<bool>,
    /// The thickness the pairs were found for (`None`: none found, or a failed search).
    found_for: Option<f32>,
    /// How much of its motion each particle keeps, and whether that changed last round.
    scale: Vec<f64>,
    /// What the pushes' sweeps keep.
    sweeps: Sweeps,
    /// Particles whose motion changed since [`SelfContacts::update_pairs`] last checked it
    /// against its box and path in this substep; every particle where `all_unchecked`
    /// (at a substep's start, whose window has moved on, or where a check asks more than
    /// the last). Each other particle's motion passed the last check, or got a box and a
    /// path since, so it passes a check that asks as much or less.
    unchecked: Vec<u32>,
    all_unchecked: bool,
    /// What the last check asked for: its `within`.
    checked_within: f32,
    /// This round's cuts: each particle's smallest scale yet, as the bits of an `f64`.
    cut: Cuts,
    changed: Vec<bool>,
    /// Whether `scale`, `cut` and `changed` are as a first round needs them (every share
    /// whole, every particle changed): left so by the calls in which no round cut, so that
    /// most calls need not fill them again.
    cuts_whole: bool,
    pub work: SelfWork,
    /// What the searches since the last whole one cost.
    costs: SearchCosts,
}

/// Triangles searched again in one piece of a refresh (the pieces' pairs come in the
/// searched triangles' order however long the pieces are).
const REFRESHED_PER_PIECE: usize = 16;

/// Triangles searched again from which a refresh is shared out between the team's
/// members (two pieces): where `crumple` settles at 64² a refresh searches 300–400, and
/// sharing those cut its second and third seconds' self-contact by a sixth on two threads
/// (from 512 on, it ran them alone); sharing from 32 rather than 128 took the refreshes
/// run alone from 2.6 % of the contact phases' samples on two threads to 1.1 %.
const PARALLEL_REFRESHED: usize = 2 * REFRESHED_PER_PIECE;

impl SelfContacts {
    /// Keeps the cloth off itself after a substep that moved it from
    /// `start` to `state`: pairs closer than `thickness` (m) are pushed apart on the side
    /// they started on, with Coulomb `friction`; then no pair's sides may meet anywhere along
    /// the substep's straight-line motion. Returns the pushes.
    ///
    /// # Errors
    /// [`ContactError`] for a state that has blown up (a non-finite position, or a triangle
    /// a million times wider than the cloth's scale); nothing is moved then.
    pub fn resolve(
        &mut self,
        [thickness, friction]: [f32; 2],
        model: &ClothModel,
        start: &[Vec3],
        state: &mut ClothState,
    ) -> Result<usize, ContactError> {
        if thickness <= 0.0 || model.triangles.is_empty() {
            return Ok(0);
        }
        // Pairs are found, and kept while they hold, in a frame that moves with the
        // cloth's mean motion (it changes no distance): a cloth falling as a whole moves
        // little in it. A position that is not finite makes the mean so.
        let n = start.len() as f64;
        let mean = (start.iter().zip(&state.pos))
            .fold(glam::DVec3::ZERO, |m, (s, p)| m + (*p - *s).as_dvec3())
            / n;
        if !mean.is_finite()
            && let Some(particle) = state.pos.iter().position(|p| !p.is_finite())
        {
            return Err(ContactError::NonFinite { particle });
        }
        // Nothing to build where it was prepared for this cloth.
        self.prepare(model)?;
        // Only the running total outlives a resolve.
        self.work = SelfWork {
            forced_total: self.work.forced_total,
            ..SelfWork::default()
        };
        let mean = mean.as_vec3();
        // A substep further into the window: every particle's motion is checked again.
        self.window.at = self.window.at.saturating_add(1);
        let moved = Moved {
            start,
            end: &state.pos,
            shift: self.shift,
            mean,
        };
        self.update_pairs(model, thickness, thickness, Some(moved))?;
        self.work.candidates = self.found.len() as u64;
        self.refuse_stretched(model, state)?;
        let contacts = self.sweeps.push(
            PUSH_SWEEPS,
            (&self.found, &self.owners),
            [thickness, friction, NEAR * thickness],
            model,
            start,
            state,
            &self.held,
        );
        self.work.contacts = contacts as u64;
        // The pushes may have taken a particle out of the box its pairs were found in; the
        // check needs only the pairs that can come within what it keeps. Only the pushed
        // particles' ends changed.
        for &i in self.sweeps.pushed() {
            self.to[i as usize] = state.pos[i as usize] - self.shift - mean;
        }
        self.unchecked.extend_from_slice(self.sweeps.pushed());
        self.update_pairs(model, thickness, CHECKED * thickness, None)?;
        self.shift += mean;
        self.mean = mean;
        self.fixed.clear();
        self.keep_apart(model, start, state, thickness)?;
        Ok(contacts)
    }

    /// [`ContactError::Stretched`] where the pairs found number more than [`SUSPECT_PAIRS`]
    /// a particle and a spring of `state` is stretched past [`SelfContacts::strain_limit`];
    /// the next resolve then searches the whole tree again.
    fn refuse_stretched(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
    ) -> Result<(), ContactError> {
        let (pairs, particles) = (self.found.len(), state.pos.len());
        let Some(limit) = self.strain_limit else {
            return Ok(());
        };
        if pairs <= SUSPECT_PAIRS * particles {
            return Ok(());
        }
        let strain = model.springs.largest_strain(&state.pos);
        if strain <= limit {
            return Ok(());
        }
        self.found_for = None;
        Err(ContactError::Stretched {
            strain,
            limit,
            pairs,
            particles,
        })
    }

    /// Builds what self-contact keeps for `model` alone, from its triangles and rest
    /// shape: which triangle owns each vertex and edge and the pairs of the triangles
    /// that share a corner, each corner's rest shape as its first reference, the tree
    /// over the triangles and its patches with the cloth's rest gap. Once per cloth (a
    /// stepper calls it when self-collision is turned on, so that the first substep does
    /// not wait for it); each resolve checks that they are the model's, and builds them
    /// again only for another cloth. Returns whether it built them.
    ///
    /// # Errors
    /// [`ContactError::TooMany`] for more triangles than a stored pair can number.
    pub fn prepare(&mut self, model: &ClothModel) -> Result<bool, ContactError> {
        if model.triangles.len() > MOST_TRIANGLES {
            return Err(ContactError::TooMany {
                triangles: model.triangles.len(),
                most: MOST_TRIANGLES,
            });
        }
        if self.owners.update(model) {
            // Nothing found for the old cloth holds: not its pairs, its tree (nor, built
            // with it, its corners' references and its patches), nor how long its windows
            // ran.
            self.found_for = None;
            self.tree = TriangleTree::default();
            (self.window, self.boxes.swept) = (Window::default(), false);
        }
        if self.tree.triangles() == model.triangles.len() {
            return Ok(false);
        }
        let (triangles, rest) = (&model.triangles, &model.rest_positions);
        self.certificates = Certificates::build(&self.owners, triangles, rest);
        self.tree = TriangleTree::build(triangles, rest);
        let corners = self.certificates.least_at_rest();
        self.patches = Patches::build(&mut self.tree, triangles, rest, (&self.owners, corners));
        self.backoff.clear();
        Ok(true)
    }

    /// Forgets what the run so far steers the next searches by (the pairs, the windows,
    /// the frame that moves with the cloth, the searches' costs, how many searches each
    /// patch sits out), keeping the buffers and what was built from the rest shape: the
    /// next substep searches as a new one's first would, and the run goes on as a new one
    /// would (a reset).
    pub fn forget(&mut self) {
        self.backoff.iter_mut().for_each(|b| *b = 0);
        self.found_for = None;
        (self.window, self.boxes.swept) = (Window::default(), false);
        (self.shift, self.mean) = (Vec3::ZERO, Vec3::ZERO);
        self.costs = SearchCosts::default();
        self.work = SelfWork::default();
    }

    /// Checks the substep's motion again after [`SelfContacts::resolve`] and a move of the
    /// solids (from `start`, the substep's, free of intersections, to `state`; `placed`:
    /// the positions before the solids moved them) along its whole length, cutting it where
    /// a pair could meet, as `resolve` does but without pushes; what the solids moved is cut
    /// only where nothing else can be. Returns the pairs cut.
    ///
    /// # Errors
    /// As [`SelfContacts::resolve`].
    pub fn settle(
        &mut self,
        thickness: f32,
        model: &ClothModel,
        [start, placed]: [&[Vec3]; 2],
        state: &mut ClothState,
    ) -> Result<usize, ContactError> {
        if thickness <= 0.0 || model.triangles.is_empty() {
            return Ok(0);
        }
        self.prepare(model)?;
        // The substep in the frame it was resolved in (whose shift already has its mean).
        let moved = Moved {
            start,
            end: &state.pos,
            shift: self.shift - self.mean,
            mean: self.mean,
        };
        let searches = self.work.searches + self.work.refreshes;
        self.update_pairs(model, thickness, CHECKED * thickness, Some(moved))?;
        let impacts = self.work.impacts;
        // What the solids just moved stays where they put it: the cut falls on the rest.
        self.fixed.resize(placed.len().min(state.pos.len()), false);
        each_part([&mut self.fixed], |range, [fixed]| {
            let (placed, pos) = (within(placed, range.clone()), within(&state.pos, range));
            for ((fixed, a), b) in fixed.iter_mut().zip(placed).zip(pos) {
                *fixed = a != b;
            }
        });
        // Where the last check cut nothing (every pair checked along the motion to
        // `placed`, none to cut) and the pairs are the same, a pair none of whose particles
        // the solids moved has the motion that check passed: only the others are checked
        // (in `layers`, whose sphere presses its stack every substep, most pairs are not).
        let same_pairs = self.work.searches + self.work.refreshes == searches;
        let narrowed = same_pairs && self.cuts_whole && self.changed.len() == self.fixed.len();
        #[cfg(test)]
        let narrowed = narrowed && !tests::RECHECK_EVERY_PAIR.get();
        if narrowed {
            #[cfg(test)]
            tests::NARROWED.set(tests::NARROWED.get() + 1);
            self.changed.copy_from_slice(&self.fixed);
        }
        let kept = self.keep_apart(model, start, state, thickness);
        if self.cuts_whole {
            // Where nothing was cut every particle's motion stays whole, and the next check
            // starts from every pair.
            self.changed.fill(true);
        }
        kept?;
        Ok((self.work.impacts - impacts) as usize)
    }

    /// Fills the substep's start and end in the moving frame ([`Moved::fill`]) on their
    /// own, for a whole search.
    fn relative(&mut self, moved: Moved<'_>) {
        each_part([&mut self.from, &mut self.to], |range, [from, to]| {
            moved.fill(range, [from, to]);
        });
    }

    /// Makes the pairs hold every pair that can come within `within` along the motion from
    /// `from` to `to`: they do while they were found for this thickness and every
    /// particle's motion lies in its box less half of `within` (two boxes that far apart
    /// keep their particles `within` apart), or judged by the boxes alone, less half the
    /// thickness, whatever `within` (the pairs kept are only those that could come within
    /// the thickness from there: [`Search::keep`]). Particles whose motion left theirs get new
    /// boxes, and their triangles are searched again ([`SelfContacts::refresh`]); where
    /// many left, or (judged by the boxes) the refreshes since the last whole search have
    /// cost as much as it did, the whole tree is ([`SelfContacts::find_pairs`]).
    /// Where the pairs are judged by the motion, also while the window they were found for
    /// lasts ([`Window`]). With `moved`, a new motion: every particle's start and end are
    /// put in the moving frame first, as each member checks its part (one section rather
    /// than two: on two threads each of this size waited 2–3 µs for the helper), or on their
    /// own before a whole search.
    fn update_pairs(
        &mut self,
        model: &ClothModel,
        thickness: f32,
        within: f32,
        moved: Option<Moved<'_>>,
    ) -> Result<(), ContactError> {
        if let Some(moved) = moved {
            self.all_unchecked = true;
            self.from.resize(moved.start.len(), Vec3::ZERO);
            self.to.resize(moved.end.len(), Vec3::ZERO);
        }
        let swept = self.boxes.swept;
        // Less room to come within (more to stray) holds wherever more did.
        self.all_unchecked |= within > self.checked_within;
        self.checked_within = within;
        if self.found_for != Some(thickness)
            || self.boxes.vertex_lo.len() != self.to.len()
            || swept && self.window.at >= self.window.len
        {
            // Every particle gets a box and a path for its motion now.
            if let Some(moved) = moved {
                self.relative(moved);
            }
            self.all_unchecked = false;
            self.unchecked.clear();
            return self.find_pairs(model, thickness);
        }
        let g = 0.5 * if swept { within } else { thickness };
        // Pairs judged by the motion hold while each particle starts and ends within the
        // allowance and half of what `within` leaves of the thickness of where its path in
        // the window puts it (see `Window`): a pair kept apart by the thickness and twice
        // the allowance along the paths then stays `within` apart. A window of one
        // substep has no allowance: each particle starts where it did.
        let slack = 0.5 * (thickness - within);
        let (boxes, window) = (&self.boxes, self.window);
        let allowance = self.allowance(thickness);
        let (strays, off) = (allowance > 0.0, f64::from(allowance + slack));
        // In f64: the path's points are not rounded on the way.
        let len = f64::from(window.len);
        let at = [window.at, window.at + 1].map(|step| f64::from(step) / len);
        let strayed = |(s, p): (Vec3, Vec3), (from, to): (Vec3, Vec3)| {
            if !strays {
                return s != from || p.distance(to) > slack;
            }
            let (from, along) = (from.as_dvec3(), (to - from).as_dvec3());
            let gap = |x: Vec3, t: f64| x.as_dvec3().distance_squared(from + along * t);
            gap(s, at[0]) > off * off || gap(p, at[1]) > off * off
        };
        // A particle without a path (none can be: the search sets them all) has left.
        let has_left = |(s, p): (Vec3, Vec3), (lo, hi): (Vec3, Vec3), path: Option<_>| {
            leaves(s, p, [lo, hi], g) || swept && path.is_none_or(|path| strayed((s, p), path))
        };
        // Particle `i`'s path in the window, from the paths' starts and ends (read only
        // where the pairs are judged by the motion: `has_left` asks for it only then).
        let path_at = |[from, to]: [&[Vec3]; 2], i: usize| Some((*from.get(i)?, *to.get(i)?));
        self.left.resize(self.to.len(), false);
        // How many left, counted by each member in its part.
        let count = AtomicUsize::new(0);
        if self.all_unchecked {
            let (all_from, all_to) = (Disjoint::new(&mut self.from), Disjoint::new(&mut self.to));
            each_part([&mut self.left], |range, [left]| {
                // SAFETY: the members' ranges are disjoint.
                let (from, to) =
                    unsafe { (all_from.part(range.clone()), all_to.part(range.clone())) };
                if let Some(moved) = moved {
                    moved.fill(range.clone(), [&mut *from, &mut *to]);
                }
                // Each array cut to the shortest's length once (as a zip of them stops),
                // then read by index: one bound check a part, not a particle.
                let part = |v| crate::parallel::within(v, range.clone());
                let (from, to, lo, hi) =
                    (&*from, &*to, part(&boxes.vertex_lo), part(&boxes.vertex_hi));
                let n = (left.len().min(from.len()).min(to.len())).min(lo.len().min(hi.len()));
                let (from, to, lo, hi) = (&from[..n], &to[..n], &lo[..n], &hi[..n]);
                // The boxes four particles at a time (as `has_left` tells them), then the
                // paths of those still in theirs.
                outside(&mut left[..n], [from, to], [lo, hi], g);
                if swept {
                    // (`within` is the parameter here.)
                    let paths = boxes
                        .paths()
                        .map(|v| crate::parallel::within(v, range.clone()));
                    for (i, l) in left[..n].iter_mut().enumerate().filter(|(_, l)| !**l) {
                        *l = path_at(paths, i).is_none_or(|path| strayed((from[i], to[i]), path));
                    }
                }
                let left = left.iter().filter(|&&l| l).count();
                count.fetch_add(left, Ordering::Relaxed);
            });
        } else {
            self.left.fill(false);
            let (from, to) = (&self.from, &self.to);
            let (room, paths) = (
                |i: usize| (boxes.vertex_lo[i], boxes.vertex_hi[i]),
                boxes.paths(),
            );
            let mut left = 0;
            for &i in &self.unchecked {
                let i = i as usize;
                let l = has_left((from[i], to[i]), room(i), path_at(paths, i));
                // (A particle may be listed twice.)
                left += usize::from(l && !self.left[i]);
                self.left[i] = l;
            }
            count.store(left, Ordering::Relaxed);
        }
        let left = count.into_inner();
        self.all_unchecked = false;
        self.unchecked.clear();
        if left == 0 {
            return Ok(());
        }
        // Judged by the motion, the window brings a whole search every few substeps anyway;
        // judged by the boxes, once the refreshes since the last have cost as much.
        let due = !swept && self.costs.whole_due();
        if left * REFRESH_BELOW < self.left.len() && !due {
            return self.refresh(model, thickness);
        }
        self.find_pairs(model, thickness)
    }

    /// Cuts the free particles' motion short until no pair's sides can meet along the
    /// substep (see the module's notes); a cut particle keeps the share of its velocity
    /// that it keeps of its motion.
    fn keep_apart(
        &mut self,
        model: &ClothModel,
        start: &[Vec3],
        state: &mut ClothState,
        thickness: f32,
    ) -> Result<(), ContactError> {
        // No pair: nothing to cut (most substeps of a cloth falling free).
        if self.found.len() == 0 {
            return Ok(());
        }
        let keep = KEEP * f64::from(thickness);
        // Rounds of cuts until none cuts; the cut positions are rounded to `f32`, which
        // can undo a cut's last fraction where the pair has come close (`crumple`-like
        // stacks pressed by a solid every substep: a VT pair at 5·10⁻⁸ m crossed so), so
        // they are checked again as rounded, and cut again where they fail.
        // A pass whose cuts move nothing (a particle already held at its start against
        // prescribed motion is cut again to where it is) ends them; its forced pairs are
        // the substep's, counted once however many passes saw them.
        let mut round = 0;
        loop {
            let (forced, cut) =
                self.cut_rounds(model, [start, &state.pos], keep, &mut round, thickness)?;
            let mut moved = false;
            // Where no round cut, every particle keeps its whole motion.
            if cut {
                let cuts =
                    (self.scale.iter().zip(start)).zip(state.pos.iter_mut().zip(&mut state.vel));
                for ((&s, from), (pos, vel)) in cuts {
                    if s < 1.0 {
                        let from = from.as_dvec3();
                        let to = from + s * (pos.as_dvec3() - from);
                        moved |= to.as_vec3() != *pos;
                        *pos = to.as_vec3();
                        // The same share of its velocity: its motion may hold the pushes'
                        // moves, which are no velocity (their impulses are in it already),
                        // and a cut that made them one would give a particle pressed in a
                        // stack a push's depth a substep as speed.
                        *vel *= s as f32;
                    }
                }
            }
            if !moved {
                self.work.forced += forced;
                self.work.forced_total += forced;
                return Ok(());
            }
        }
    }

    /// Rounds of cuts of the motion from `start` to `end`, counted on from `round`, until one
    /// cuts nothing; leaves each particle's share of its motion in `scale`, and returns
    /// how many pairs were forced (no particle of theirs could be cut) and whether any
    /// round cut (where none did, every share is whole).
    fn cut_rounds(
        &mut self,
        model: &ClothModel,
        [start, end]: [&[Vec3]; 2],
        keep: f64,
        round: &mut usize,
        thickness: f32,
    ) -> Result<(u64, bool), ContactError> {
        let n = end.len();
        let pinned_free = |i: usize| model.inv_mass[i] > 0.0;
        let sized = [self.scale.len(), self.changed.len(), self.cut.0.len()] == [n; 3];
        if !(self.cuts_whole && sized) {
            self.scale.clear();
            self.scale.resize(n, 1.0);
            self.changed.clear();
            self.changed.resize(n, true);
            self.cut.0.clear();
            (self.cut.0).extend(self.scale.iter().map(|s| AtomicU64::new(s.to_bits())));
            self.cuts_whole = true;
        }
        let (mut forced_here, first) = (0, *round);
        loop {
            let round_now = *round;
            *round += 1;
            let fixed = &self.fixed;
            let free = |i: usize| pinned_free(i) && !fixed.get(i).copied().unwrap_or(false);
            // A round's cuts depend only on the last round's scales, and each particle keeps
            // the smallest: the pairs can be shared out in any order and give the same bits.
            let parallel = self.found.len() >= PARALLEL_PAIRS;
            // Each round starts with the cuts at the scales: as filled, or as the last
            // round left both.
            let (impacts, forced) = (AtomicU64::new(0), AtomicU64::new(0));
            let (scale, changed, cut) = (&self.scale, &self.changed, &self.cut.0);
            let (triangles, edges) = (&model.triangles, &self.owners.edges);
            self.found.share(parallel, &|stored| {
                let (mut impacted, mut stuck) = (0, 0);
                for pair in stored.iter().map(|p| p.expand(triangles, edges)) {
                    let ids = pair.ids();
                    if !ids.iter().any(|&i| changed[i]) {
                        continue;
                    }
                    let from = ids.map(|i| start[i].as_dvec3());
                    let moves = ids.map(|i| scale[i] * (end[i].as_dvec3() - start[i].as_dvec3()));
                    let t = safe_fraction(&pair, from, moves, keep);
                    if t >= 1.0 {
                        continue;
                    }
                    impacted += 1;
                    // Particles a solid placed are cut only where nothing else in the pair
                    // can be: the cloth's own guarantee comes first.
                    let only_placed = !ids.iter().any(|&i| free(i) && scale[i] > 0.0);
                    let movable = |i: usize| {
                        scale[i] > 0.0 && if only_placed { pinned_free(i) } else { free(i) }
                    };
                    let mut cut_any = false;
                    for &i in &ids {
                        if movable(i) {
                            let to = if round_now < SCALED_ROUNDS {
                                scale[i] * t
                            } else {
                                0.0
                            };
                            // Non-negative floats order as their bits do.
                            cut[i].fetch_min(to.to_bits(), Ordering::Relaxed);
                            cut_any = true;
                        }
                    }
                    stuck += u64::from(!cut_any);
                }
                impacts.fetch_add(impacted, Ordering::Relaxed);
                forced.fetch_add(stuck, Ordering::Relaxed);
            });
            let (impacted, stuck) = (impacts.into_inner(), forced.into_inner());
            self.work.impacts += impacted;
            forced_here += stuck;
            // Every impact cut something, or was forced (no cut lowered: where no round
            // before did either, the shares are still whole).
            if impacted == stuck {
                return Ok((forced_here, round_now > first));
            }
            self.cuts_whole = false;
            let rounds = (self.changed.iter_mut()).zip(self.scale.iter_mut().zip(&self.cut.0));
            for (changed, (scale, cut)) in rounds {
                let cut = f64::from_bits(cut.load(Ordering::Relaxed));
                *changed = cut != *scale;
                *scale = cut;
            }
            // The pairs hold for the motion as cut only while each cut particle's
            // motion, in the frame that moves with the cloth, keeps within where they
            // were found for: judged by the motion, ending within the slack of where it
            // did; by the boxes, within its box. A cut particle stops short of where
            // the frame goes on to, so its motion there is not a part of the one the
            // pairs were found for, and can leave its box: one held at its start by a
            // stack pressed under it rose 4 cm in the frame of a falling cloth, into
            // the layer falling onto it, whose pairs with it had not been found
            // (`layers` at 24 quads, one implicit substep a frame: 56 pairs of
            // triangles crossed at frame 16). The others' pairs are searched again, and
            // the next round checks every pair.
            let cuts = (self.to.iter_mut().zip(&self.scale)).zip(start.iter().zip(end));
            for (i, ((to, &s), (&a, &b))) in cuts.enumerate() {
                if s < 1.0 {
                    let end = a.as_dvec3() + s * (b.as_dvec3() - a.as_dvec3());
                    *to = end.as_vec3() - self.shift;
                    self.unchecked.push(i as u32);
                }
            }
            let searches = self.work.searches + self.work.refreshes;
            self.update_pairs(model, thickness, CHECKED * thickness, None)?;
            if self.work.searches + self.work.refreshes != searches {
                self.changed.iter_mut().for_each(|c| *c = true);
            }
        }
    }
}

mod finding;

#[cfg(test)]
mod tests;
