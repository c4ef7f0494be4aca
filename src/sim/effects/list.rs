//! What a scene's effects add up to, for those who need one number from them.

use glam::Vec3;

use crate::cloth::ClothModel;

use super::registry::Effect;
use super::self_collision::{TooThick, shortest_edge};

/// The gravitational acceleration among `effects` (zero without gravity), m/s².
pub fn gravity_of(effects: &[Effect]) -> Vec3 {
    effects
        .iter()
        .find_map(|e| match e {
            Effect::Gravity(g) => Some(g.acceleration),
            _ => None,
        })
        .unwrap_or(Vec3::ZERO)
}

/// An effect listed again whose kind a scene may have once ([`Effect::many`]): two
/// gravities would be summed by the CPU's forces and taken once by what reads one number
/// (the GPU, the guard).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ListedTwice {
    /// The effects' indices: the first of its kind, and the one listed again.
    pub first: usize,
    pub again: usize,
    /// Its `type` in scene files.
    pub kind: &'static str,
}

impl ListedTwice {
    /// What is wrong with the second, after its `type`.
    pub fn rule(&self) -> String {
        format!(
            "is already effect {}; a scene has at most one",
            self.first + 1
        )
    }
}

/// The first effect of `effects` whose kind a scene may have once and an earlier one has.
pub fn listed_twice(effects: &[Effect]) -> Option<ListedTwice> {
    effects.iter().enumerate().find_map(|(i, e)| {
        let first = effects[..i].iter().position(|o| o.same_kind(e));
        first.filter(|_| !e.many()).map(|first| ListedTwice {
            first,
            again: i,
            kind: e.phase(),
        })
    })
}

/// The air damping rate among `effects` (0 without air damping), 1/s.
pub fn air_damping_of(effects: &[Effect]) -> f32 {
    effects
        .iter()
        .find_map(|e| match e {
            Effect::AirDamping(a) => Some(a.rate),
            _ => None,
        })
        .unwrap_or(0.0)
}

/// Checks every self-collision among `effects` against `model`'s shortest rest edge.
///
/// # Errors
/// [`TooThick`] for a thickness at or above it.
pub fn thickness_fits(effects: &[Effect], model: &ClothModel) -> Result<(), TooThick> {
    let edge = shortest_edge(model);
    effects.iter().try_for_each(|e| match e {
        Effect::SelfCollision(s) => s.fits(edge),
        _ => Ok(()),
    })
}

/// Smallest signed distance from any particle to any solid's surface among `effects`,
/// each where it is at time `t` (s), metres; `None` without solids.
pub fn min_surface_distance(effects: &[Effect], pos: &[Vec3], t: f64) -> Option<f32> {
    effects
        .iter()
        .flat_map(|e| {
            pos.iter()
                .filter_map(move |&p| e.surface(p, t).map(|s| s.0))
        })
        .reduce(f32::min)
}

/// A warning for each mesh obstacle the cloth at `pos` already meets: particles within its
/// thickness (`offset` unless it has its own) or cloth edges through it. The first substep
/// then pushes those particles out, as far as the thickness, wherever they are.
pub fn obstacle_overlap_warnings(
    effects: &[Effect],
    model: &ClothModel,
    pos: &[Vec3],
    offset: f32,
) -> Vec<String> {
    let obstacles = effects.iter().filter_map(|e| match e {
        Effect::Obstacle(o) => o.placed().map(|p| (o, p)),
        _ => None,
    });
    let mut out = Vec::new();
    for (obstacle, placed) in obstacles {
        let thickness = obstacle.thickness.unwrap_or(offset);
        let surface = &placed.surface;
        let near = (pos.iter())
            .filter(|&&p| surface.nearest(p, thickness).is_some())
            .count();
        let (a, b) = (&model.springs.a, &model.springs.b);
        let through = (a.iter().zip(b))
            .filter(|(i, j)| {
                let (p, q) = (pos[**i as usize], pos[**j as usize]);
                surface.first_crossing(p, q).is_some()
            })
            .count();
        if near + through > 0 {
            out.push(format!(
                "the obstacle {} already meets the cloth: {near} particles within its \
                 thickness ({thickness} m) and {through} springs through it; the first step \
                 pushes them out",
                obstacle.source()
            ));
        }
    }
    out
}
