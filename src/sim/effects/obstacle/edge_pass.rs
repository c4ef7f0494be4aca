//! The edge pass of a mesh obstacle: every cloth edge kept off the obstacle's sharp edges
//! (a table's rim), where a cloth edge can rest across one with both its particles clear of
//! the faces. Colour by colour, a large colour's edges shared out between the team.

use glam::{Vec3, Vec3A};

use super::super::effect_kind::ContactPass;
use super::super::solid::touching;
use crate::cloth::EdgeColours;
use crate::parallel::{Disjoint, Team};
use crate::sim::obstacle::{Clearance, LOOK, LOOK_DEFORMING, SharpEdges, SurfaceClock, Tips};

/// How the frame of the sharp edges lies in the world: `to_local` takes a world point into
/// it, `to_world` turns a direction of it into the world's, `velocity` is the surface's
/// velocity (world) at one of its points.
pub(super) struct EdgeFrame<S, L, W, V> {
    /// A world point where the substep began, into the frame as it was then.
    pub from_start: S,
    pub to_local: L,
    pub to_world: W,
    pub velocity: V,
}

/// What the edge pass of one obstacle keeps from one substep to the next: how clear of the
/// sharp edges each cloth edge (spring) was last measured, in the obstacle's frame (where
/// the edges are fixed in it: a rigid obstacle's), and each particle where the substep
/// began and where the last pass left it, in the frame (nothing is allocated once warm).
#[derive(Debug, Default)]
pub(super) struct EdgeMemory {
    clearance: Vec<Clearance>,
    before: Vec<Vec3A>,
    local: Vec<Vec3A>,
    /// Where the edges are fixed in the frame (a rigid obstacle's): how far each particle
    /// can have moved in it since the odometers were set to zero, m (its moves between
    /// one pass and the next and its pushes, each with room for its rounding).
    odometers: Vec<f64>,
    /// For each cloth edge, in the colour order the pass takes them in, what it was when
    /// last asked.
    asked_at: Vec<Asked>,
    /// Each particle's pushes in this pass added up (in the frame), m.
    pushed: Vec<f32>,
    /// The tips near one patch of the cloth, and the vertices near one of its triangles
    /// (scratch of the tip pass).
    tips_near: Vec<Vec3A>,
    tips_close: Vec<Vec3A>,
    /// The last pass's room for a distance's rounding in the frame, and how far the edges
    /// moved in it over the substep, m (the tip pass reads them).
    rounding: f32,
    moved_by: f32,
    /// Where the edges deform: when the surface the clearances were measured against stood.
    pub(super) clock: SurfaceClock,
    /// Cloth edges asked about (not passed by on the odometers) since the memory was made.
    #[cfg(test)]
    asked: usize,
}

/// A cloth edge when it was last asked: its two particles, their odometers added up then,
/// and how much of its clearance was left then (less its rounding). Until those odometers
/// have run on by that much less the reach, its answer would be the same (none), and it is
/// passed by unasked: only for the same two particles (another cloth of as many particles
/// and edges may have taken the memory on) and where something was left (`-∞`: ask).
#[derive(Clone, Copy, Debug)]
struct Asked {
    ends: [u32; 2],
    reading: f64,
    left: f32,
}

impl Asked {
    const NOT: Asked = Asked {
        ends: [u32::MAX; 2],
        reading: 0.0,
        left: f32::NEG_INFINITY,
    };
}

/// How far the particles moved since the substep began (the most any did: `travel`),
/// and the room for the rounding of a distance between two of them (`rounding`), m.
struct Reading {
    travel: f32,
    rounding: f32,
}

impl EdgeMemory {
    /// Takes every particle of `pos` into the frame (`to_local`). Where the sharp edges are
    /// `fixed` in it, runs each particle's odometer on by its move since the last pass (all
    /// set to zero, and each of the `edges` cloth edges to be asked, where the particles
    /// are not the last pass's), and reads how far the particles moved since the substep
    /// began (`before` must be filled). Where the edges move, every cloth edge is asked:
    /// their own move wears each clearance down by about as much as is left of it over a
    /// substep (`arm`: every one was asked every substep), and no odometer is kept.
    fn take_in(
        &mut self,
        pos: &[Vec3],
        to_local: impl Fn(Vec3) -> Vec3 + Sync,
        edges: usize,
        fixed: bool,
    ) -> Option<Reading> {
        self.pushed.clear();
        self.pushed.resize(pos.len(), 0.0);
        if !fixed {
            // No odometers: every cloth edge is asked.
            self.odometers.clear();
            self.asked_at.clear();
            self.local.clear();
            (self.local).extend(pos.iter().map(|&p| Vec3A::from(to_local(p))));
            return None;
        }
        let counted = (self.local.len(), self.odometers.len(), self.asked_at.len())
            == (pos.len(), pos.len(), edges);
        if !counted {
            self.local.clear();
            (self.local).extend(pos.iter().map(|&p| Vec3A::from(to_local(p))));
            self.odometers.clear();
            self.odometers.resize(pos.len(), 0.0);
            self.asked_at.clear();
            self.asked_at.resize(edges, Asked::NOT);
        }
        // Each particle's own, so a large cloth's are shared out between the team in
        // pieces (the farthest move and the largest coordinate are the same however cut).
        let team = Team::current();
        let pieces = pos.len().div_ceil(PIECE);
        let parallel = pos.len() > SHARED_FROM && team.members() <= TALLIES;
        let mut most = [(0.0f32, 0.0f32); TALLIES];
        let slots = Disjoint::new(&mut most);
        let (locals, odometers) = (
            Disjoint::new(&mut self.local),
            Disjoint::new(&mut self.odometers),
        );
        let before = &self.before;
        team.run_pieces_if(parallel, pieces, &|member, piece| {
            let (mut travel, mut scale) = (0.0f32, 0.0f32);
            for i in piece * PIECE..pos.len().min((piece + 1) * PIECE) {
                let now = Vec3A::from(to_local(pos[i]));
                // SAFETY: particle `i` is this piece's alone.
                let (local, odometer) = unsafe { (locals.at(i), odometers.at(i)) };
                // The sum of the move's components: never less than its length, and no root.
                *odometer += f64::from((now - *local).abs().element_sum());
                travel = travel.max(now.distance_squared(before[i]));
                scale = scale.max(now.abs().max_element());
                *local = now;
            }
            // SAFETY: each member keeps its own.
            let slot = unsafe { slots.at(member) };
            *slot = (slot.0.max(travel), slot.1.max(scale));
        });
        let (travel, scale) =
            (most.iter()).fold((0.0f32, 0.0f32), |(t, s), &(mt, ms)| (t.max(mt), s.max(ms)));
        // A distance between two points of this size is rounded by far less.
        let rounding = 4.0 * f32::EPSILON * (1.0 + scale);
        for odometer in &mut self.odometers {
            *odometer += f64::from(rounding);
        }
        Some(Reading {
            travel: travel.sqrt() + rounding,
            rounding,
        })
    }
}

/// What the tip pass after an edge pass reads and moves, in the same frame
/// ([`EdgeMemory::for_tips`]).
pub(super) struct ForTips<'a> {
    /// Each particle where the substep began, and where it is now, in the frame.
    pub(super) before: &'a [Vec3A],
    pub(super) local: &'a mut [Vec3A],
    /// Each particle's odometer, where the edges are fixed in the frame (else none).
    pub(super) odometers: &'a mut [f64],
    /// Scratch: the tips near one patch, and the vertices near one triangle.
    pub(super) found: &'a mut Vec<Vec3A>,
    pub(super) close: &'a mut Vec<Vec3A>,
    /// How far the tips moved in the frame over the substep, and the room for a
    /// distance's rounding there, m.
    pub(super) moved_by: f32,
    pub(super) rounding: f32,
}

impl<S, L, W, V> Shared<'_, S, L, W, V>
where
    S: Fn(Vec3) -> Vec3,
    L: Fn(Vec3) -> Vec3,
    W: Fn(Vec3) -> Vec3,
    V: Fn(Vec3) -> Vec3,
{
    /// The turn of the cloth edge at `k` in the colour order, where no particle's pushes
    /// of this pass add up to more than `most_pushed` before it: its two particles kept
    /// off the sharp edges ([`push_edges`]), what it did added to `tally`.
    ///
    /// # Safety
    /// No other turn at the same time may move either of its particles, its spring or its
    /// place in the order (a colour's edges share none).
    unsafe fn edge_turn(&self, slices: &Slices<'_>, k: usize, most_pushed: f32, tally: &mut Tally) {
        let (colours, thickness) = (self.colours, self.thickness);
        let (e, ends) = (colours.order[k] as usize, colours.ends[k]);
        let [i, j] = ends.map(|p| p as usize);
        // SAFETY (every access below): the particles `i` and `j`, the spring `e` and the
        // place `k` are this turn's alone, by the caller's contract.
        let (odometers, local) = (&slices.odometers, &slices.local);
        let clearance = unsafe { slices.clearance.at(e) };
        let rounding = self.reading.map_or(0.0, |r| r.rounding);
        // Neither particle has moved farther than its odometer ran on since this cloth edge
        // was last asked, nor (any particle) farther than `reach_most` since the substep
        // began: while the two odometers leave it more than the reach clear, it is not
        // asked.
        let reading_now =
            (self.reading).map(|r| (r, unsafe { *odometers.at(i) + *odometers.at(j) }));
        if let Some((r, at)) = reading_now {
            // (Where there is a reading, every cloth edge has its last asking.)
            let last = unsafe { *slices.asked_at.at(k) };
            let reach_most = thickness.max(r.travel + most_pushed);
            let wanted = reach_most * (1.0 + 2e-4) + 2.0 * rounding;
            if last.ends == ends && (at - last.reading) + f64::from(wanted) < f64::from(last.left) {
                return;
            }
        }
        let free = [self.inv_mass[i] > 0.0, self.inv_mass[j] > 0.0].map(f32::from);
        if free == [0.0, 0.0] {
            return;
        }
        let now = unsafe { [*local.at(i), *local.at(j)] };
        let then = [self.before[i], self.before[j]];
        // An edge the cloth edge passed through in the substep puts it back on the side it
        // came from; else one it ends within the thickness of pushes it out. Every point of
        // the cloth edge moved at most `travel`: one that passed through a sharp edge ends
        // within that of it, so an edge with none that near is not asked.
        let travel = (now[0] - then[0]).length().max((now[1] - then[1]).length());
        let reach = thickness.max(travel);
        let edges = self.edges;
        let near = edges.nearest_remembering(now, [reach, self.look], clearance);
        #[cfg(test)]
        {
            tally.asked += 1;
        }
        // What is left of its clearance, from the odometers' reading now.
        if let Some((_, at)) = reading_now {
            let left = clearance.left(now) - rounding;
            *unsafe { slices.asked_at.at(k) } = Asked {
                ends,
                reading: at,
                left,
            };
        }
        let Some(near) = near else {
            return;
        };
        let (now, then) = (now.map(Vec3::from), then.map(Vec3::from));
        let crossed = (near.distance <= travel)
            .then(|| edges.crossed(then, now))
            .flatten();
        let (hit, side) = match crossed {
            Some((edge, side)) => {
                tally.crossings += 1;
                (SharpEdges::between(now[0], now[1], edge), side)
            }
            None => {
                if near.distance <= thickness * 1e-3 || near.distance >= thickness {
                    return;
                }
                (near, (near.on_segment - near.on_edge) / near.distance)
            }
        };
        // What the nearest point of the cloth edge must move by, in the frame.
        let frame = self.frame;
        let gap = side * thickness - (hit.on_segment - hit.on_edge);
        let n = (frame.to_world)(side);
        let gap = (frame.to_world)(gap);
        let share = [1.0 - hit.along, hit.along];
        let weight = share[0] * share[0] * free[0] + share[1] * share[1] * free[1];
        if weight <= 0.0 {
            return;
        }
        let v_surface = (frame.velocity)(hit.on_edge);
        for (end, p) in [i, j].into_iter().enumerate() {
            let part = share[end] * free[end];
            if part <= 0.0 {
                continue;
            }
            let (pos, vel) = unsafe { (slices.pos.at(p), slices.vel.at(p)) };
            *pos += gap * (part / weight);
            *vel = touching(*vel, v_surface, n, self.mu, part);
            let local = unsafe { local.at(p) };
            let was = std::mem::replace(local, (frame.to_local)(*pos).into());
            if self.reading.is_some() {
                let (pushed, odometer) = unsafe { (slices.pushed.at(p), odometers.at(p)) };
                let push = local.distance(was) + rounding;
                *pushed += push;
                *odometer += f64::from(push);
                tally.most_pushed = tally.most_pushed.max(*pushed);
            }
        }
        tally.moved += 1;
    }
}

impl EdgeMemory {
    /// What the tip pass reads and moves after [`push_edges`] (which takes every particle
    /// into the frame where the obstacle has tips, for it): a push it makes runs the
    /// particle's odometer on too.
    pub(super) fn for_tips(&mut self) -> ForTips<'_> {
        ForTips {
            before: &self.before,
            local: &mut self.local,
            odometers: &mut self.odometers,
            found: &mut self.tips_near,
            close: &mut self.tips_close,
            moved_by: self.moved_by,
            rounding: self.rounding,
        }
    }
}

/// How far the sharp edges moved in the edge pass's frame since its last pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum EdgesMoved {
    /// Not at all: they are fixed in it (a rigid obstacle's, in its own frame).
    Fixed,
    /// At most this far, metres (a deforming surface's: [`SurfaceClock::moved_to`]).
    By(f32),
}

/// How many times at most the edge pass runs in one substep.
const EDGE_SWEEPS: usize = 4;

/// Cloth edges (or particles) a member of the team takes at once; a colour of fewer is
/// taken by one.
const PIECE: usize = 256;

/// Particles from which the pass takes them into its frame shared out between the team.
const SHARED_FROM: usize = 1024;

/// Members of the team whose tallies a colour keeps (a larger team takes each colour alone).
const TALLIES: usize = 16;

/// What the edge pass's turns of some cloth edges did: crossings put back, cloth edges
/// moved, the most any particle's pushes of the pass added up to after them, and (for
/// tests) the cloth edges asked.
#[derive(Clone, Copy, Debug, Default)]
struct Tally {
    crossings: usize,
    moved: usize,
    most_pushed: f32,
    #[cfg(test)]
    asked: usize,
}

impl Tally {
    fn join(self, other: Tally) -> Tally {
        Tally {
            crossings: self.crossings + other.crossings,
            moved: self.moved + other.moved,
            most_pushed: self.most_pushed.max(other.most_pushed),
            #[cfg(test)]
            asked: self.asked + other.asked,
        }
    }
}

/// What every turn of the edge pass reads.
struct Shared<'a, S, L, W, V> {
    edges: &'a SharpEdges,
    frame: &'a EdgeFrame<S, L, W, V>,
    mu: f32,
    thickness: f32,
    look: f32,
    inv_mass: &'a [f32],
    before: &'a [Vec3A],
    reading: Option<&'a Reading>,
    colours: &'a EdgeColours,
}

/// What the turns of the edge pass move: each particle's position, velocity, place in the
/// frame, odometer and pushes, and each cloth edge's clearance (by spring) and last asking
/// (by its place in the order).
struct Slices<'a> {
    pos: Disjoint<'a, Vec3>,
    vel: Disjoint<'a, Vec3>,
    local: Disjoint<'a, Vec3A>,
    odometers: Disjoint<'a, f64>,
    pushed: Disjoint<'a, f32>,
    clearance: Disjoint<'a, Clearance>,
    asked_at: Disjoint<'a, Asked>,
}

/// Keeps every cloth edge (its structural and shear springs, in the model's colour order)
/// `pass.offset` from the sharp `edges` where it ends the substep: the two particles are
/// moved apart from the edge in proportion to how near each is to the nearest point, which
/// moves by exactly what was missing; their velocity towards the edge is removed, with
/// Coulomb friction `mu` along it. Each particle is taken into the frame once, and again
/// only when a push moves it. Each cloth edge's last measured clearance, less how far the
/// edges `moved` in the frame since (nothing where they are fixed in it: a rigid
/// obstacle's; a deforming surface's largest vertex move over the substep,
/// [`SurfaceClock::moved_to`]), spares it the walk of the tree while it stays clear
/// ([`SharpEdges::nearest_remembering`]: the same answers); and where the edges are fixed
/// in the frame, while its two particles' odometers (how far each can have moved since)
/// have not run on by what was left of it when last asked, less the reach, the cloth edge
/// is passed by unasked (its answer would be the same: none). Where the obstacle has
/// `tips` and the solids keep the cloth's triangles out, every particle is taken into the
/// frame for the tip pass after it, edges or none ([`EdgeMemory::for_tips`]). A colour of
/// more than [`PIECE`] cloth edges is shared out between the team's members in pieces
/// (its edges share no particle); the result is the same however it is cut. Returns how
/// many cloth edges it moved.
pub(super) fn push_edges<S, L, W, V>(
    (edges, tips): (&SharpEdges, &Tips),
    frame: &EdgeFrame<S, L, W, V>,
    mu: f32,
    pass: &mut ContactPass<'_>,
    (memory, moved): (&mut EdgeMemory, EdgesMoved),
) -> usize
where
    S: Fn(Vec3) -> Vec3 + Sync,
    L: Fn(Vec3) -> Vec3 + Sync,
    W: Fn(Vec3) -> Vec3 + Sync,
    V: Fn(Vec3) -> Vec3 + Sync,
{
    let tipped = !tips.is_empty() && pass.faces.is_some();
    if edges.is_empty() && !tipped {
        return 0;
    }
    let thickness = pass.offset;
    let (springs, inv_mass) = (&pass.model.springs, &pass.model.inv_mass);
    let state = &mut *pass.state;
    memory.before.clear();
    (memory.before).extend(
        pass.start
            .iter()
            .map(|&p| Vec3A::from((frame.from_start)(p))),
    );
    let colours = &pass.model.edge_colours;
    let order = &colours.order;
    debug_assert_eq!(
        colours.ends.len(),
        order.len(),
        "each edge's ends, in order"
    );
    let fixed = moved == EdgesMoved::Fixed;
    let reading = memory.take_in(&state.pos, &frame.to_local, order.len(), fixed);
    (memory.clearance).resize(springs.a.len(), Clearance::NONE);
    let (look, moved_by) = match moved {
        EdgesMoved::Fixed => (LOOK, 0.0),
        EdgesMoved::By(by) => {
            if by > 0.0 {
                (memory.clearance.iter_mut()).for_each(|c| c.surface_moved(by));
            }
            (LOOK_DEFORMING, by)
        }
    };
    let shared = Shared {
        edges,
        frame,
        mu,
        thickness,
        look,
        inv_mass,
        before: &memory.before,
        reading: reading.as_ref(),
        colours,
    };
    let slices = Slices {
        pos: Disjoint::new(&mut state.pos),
        vel: Disjoint::new(&mut state.vel),
        local: Disjoint::new(&mut memory.local),
        odometers: Disjoint::new(&mut memory.odometers),
        pushed: Disjoint::new(&mut memory.pushed),
        clearance: Disjoint::new(&mut memory.clearance),
        asked_at: Disjoint::new(&mut memory.asked_at),
    };
    let team = Team::current();
    // The most any particle's pushes of this pass have added up to, as each colour began
    // (a colour's edges share no particle: none of its pushes moves another's ends).
    let mut most_pushed = 0.0f32;
    let mut moved = 0;
    // A cloth edge put back from a crossing can pull a neighbour across another: the pass
    // repeats (a few times at most) while it finds crossings.
    let sweeps = if edges.is_empty() { 0 } else { EDGE_SWEEPS };
    for _ in 0..sweeps {
        let mut crossings = 0;
        // In colours (the GPU's order too, a colour's edges side by side there), a large
        // colour's edges shared out between the team's members: each edge's turn reads and
        // moves only its own particles, so the result is the same however they are cut.
        for (range, may_share) in &colours.runs {
            let mut tallies = [Tally::default(); TALLIES];
            let pieces = range.len().div_ceil(PIECE);
            let parallel = !may_share && pieces > 1 && team.members() <= TALLIES;
            let slots = Disjoint::new(&mut tallies);
            team.run_pieces_if(parallel, pieces, &|member, piece| {
                let first = range.start + piece * PIECE;
                let edges = first..(first + PIECE).min(range.end);
                // SAFETY: each member adds to its own tally; the edges of a colour share no
                // particle, and each is its own spring and place in the order (a run whose
                // edges may share one is taken by one member, in order).
                let tally = unsafe { slots.at(member) };
                for k in edges {
                    unsafe { shared.edge_turn(&slices, k, most_pushed, tally) };
                }
            });
            let tally = tallies.into_iter().fold(Tally::default(), Tally::join);
            crossings += tally.crossings;
            moved += tally.moved;
            most_pushed = most_pushed.max(tally.most_pushed);
            #[cfg(test)]
            {
                memory.asked += tally.asked;
            }
        }
        if crossings == 0 {
            break;
        }
    }
    let rounding = reading.as_ref().map_or(0.0, |r| r.rounding);
    (memory.rounding, memory.moved_by) = (rounding, moved_by);
    moved
}

#[cfg(test)]
mod tests;
