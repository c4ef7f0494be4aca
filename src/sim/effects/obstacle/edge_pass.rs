//! The edge pass of a mesh obstacle: every cloth edge kept off the obstacle's sharp edges
//! (a table's rim), where a cloth edge can rest across one with both its particles clear of
//! the faces.

use glam::{Vec3, Vec3A};

use super::super::effect_kind::ContactPass;
use super::super::solid::touching;
use crate::sim::obstacle::{Clearance, LOOK, LOOK_DEFORMING, SharpEdges, SurfaceClock};

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
/// began and where it is now, in the frame (scratch: nothing is allocated once warm).
#[derive(Debug, Default)]
pub(super) struct EdgeMemory {
    clearance: Vec<Clearance>,
    before: Vec<Vec3A>,
    local: Vec<Vec3A>,
    /// Where the edges deform: when the surface the clearances were measured against stood.
    pub(super) clock: SurfaceClock,
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

/// Keeps every cloth edge (its structural and shear springs, in the model's colour order)
/// `pass.offset` from the sharp `edges` where it ends the substep: the two particles are
/// moved apart from the edge in proportion to how near each is to the nearest point, which
/// moves by exactly what was missing; their velocity towards the edge is removed, with
/// Coulomb friction `mu` along it. Each particle is taken into the frame once, and again
/// only when a push moves it. Each cloth edge's last measured clearance, less how far the
/// edges `moved` in the frame since (nothing where they are fixed in it: a rigid
/// obstacle's; a deforming surface's largest vertex move over the substep,
/// [`SurfaceClock::moved_to`]), spares it the walk of the tree while it stays clear
/// ([`SharpEdges::nearest_remembering`]: the same answers). Returns how many cloth edges
/// it moved.
pub(super) fn push_edges<S, L, W, V>(
    edges: &SharpEdges,
    frame: &EdgeFrame<S, L, W, V>,
    mu: f32,
    pass: &mut ContactPass<'_>,
    (memory, moved): (&mut EdgeMemory, EdgesMoved),
) -> usize
where
    S: Fn(Vec3) -> Vec3,
    L: Fn(Vec3) -> Vec3,
    W: Fn(Vec3) -> Vec3,
    V: Fn(Vec3) -> Vec3,
{
    if edges.is_empty() {
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
    memory.local.clear();
    (memory.local).extend(state.pos.iter().map(|&p| Vec3A::from((frame.to_local)(p))));
    (memory.clearance).resize(springs.a.len(), Clearance::NONE);
    let look = match moved {
        EdgesMoved::Fixed => LOOK,
        EdgesMoved::By(by) => {
            if by > 0.0 {
                (memory.clearance.iter_mut()).for_each(|c| c.surface_moved(by));
            }
            LOOK_DEFORMING
        }
    };
    let clearance = &mut memory.clearance;
    let (before, local) = (&memory.before, &mut memory.local);
    let mut moved = 0;
    // A cloth edge put back from a crossing can pull a neighbour across another: the pass
    // repeats (a few times at most) while it finds crossings.
    for _ in 0..EDGE_SWEEPS {
        let mut crossings = 0;
        // In colours (the GPU's order too, a colour's edges side by side there).
        for &e in &pass.model.edge_colours.order {
            let e = e as usize;
            let (i, j) = (springs.a[e] as usize, springs.b[e] as usize);
            let free = [inv_mass[i] > 0.0, inv_mass[j] > 0.0].map(f32::from);
            if free == [0.0, 0.0] {
                continue;
            }
            let (now, then) = ([local[i], local[j]], [before[i], before[j]]);
            // An edge the cloth edge passed through in the substep puts it back on the side
            // it came from; else one it ends within the thickness of pushes it out. Every
            // point of the cloth edge moved at most `travel`: one that passed through a
            // sharp edge ends within that of it, so an edge with none that near is not
            // asked.
            let travel = (now[0] - then[0]).length().max((now[1] - then[1]).length());
            let reach = thickness.max(travel);
            let near = edges.nearest_remembering(now, [reach, look], &mut clearance[e]);
            let Some(near) = near else {
                continue;
            };
            let (now, then) = (now.map(Vec3::from), then.map(Vec3::from));
            let crossed = (near.distance <= travel)
                .then(|| edges.crossed(then, now))
                .flatten();
            let (hit, side) = match crossed {
                Some((edge, side)) => {
                    crossings += 1;
                    (SharpEdges::between(now[0], now[1], edge), side)
                }
                None => {
                    if near.distance <= thickness * 1e-3 || near.distance >= thickness {
                        continue;
                    }
                    (near, (near.on_segment - near.on_edge) / near.distance)
                }
            };
            // What the nearest point of the cloth edge must move by, in the frame.
            let gap = side * thickness - (hit.on_segment - hit.on_edge);
            let n = (frame.to_world)(side);
            let gap = (frame.to_world)(gap);
            let share = [1.0 - hit.along, hit.along];
            let weight = share[0] * share[0] * free[0] + share[1] * share[1] * free[1];
            if weight <= 0.0 {
                continue;
            }
            let v_surface = (frame.velocity)(hit.on_edge);
            for (k, p) in [i, j].into_iter().enumerate() {
                let part = share[k] * free[k];
                if part <= 0.0 {
                    continue;
                }
                state.pos[p] += gap * (part / weight);
                state.vel[p] = touching(state.vel[p], v_surface, n, mu, part);
                local[p] = (frame.to_local)(state.pos[p]).into();
            }
            moved += 1;
        }
        if crossings == 0 {
            break;
        }
    }
    moved
}
