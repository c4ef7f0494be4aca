//! The forces a scene uses, evaluated together; accelerations are formed here and only here.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::Vec3;

use crate::cloth::{ClothModel, Real, Vector};

use super::super::constraints::DistanceConstraints;
use super::super::effects::Effect;
use super::super::params::{Changes, Material};
use super::force::Force;
use super::force_term::Fused;
use super::jacobian::{JacobianMode, SystemMatrix};
use super::springs::SpringForce;
use crate::parallel::{Disjoint, PARALLEL_ELEMENTS, Team, share};
use crate::sim::kernels::{BlockPass, Components, Scratch, TwoPasses, split, zeroed};

/// Spring terms the fused path takes (a scene has two at most: springs and bend springs).
const FUSED_PAIR_TERMS: usize = 2;
/// Pieces of particles per team member in the fused path's second section: a member late
/// for its share loses only the pieces the others took meanwhile ([`Team::run_pieces`]).
const PIECES_PER_MEMBER: usize = 4;
/// Terms whose time the fused path records (a scene has six at most, one per effect).
const MAX_TERMS: usize = 8;

/// The scene's force terms, built from its effect list: an absent effect has no term.
#[derive(Debug)]
pub struct ForceSet<R: Real = f32> {
    terms: Vec<Force<R>>,
    /// Simulated time the forces are evaluated at (the wind's gusts move with it), seconds.
    time: f64,
    /// Positions, velocities and forces one array per component, for
    /// [`ForceSet::accelerations_components`].
    scratch: Scratch<[Components; 3]>,
}

/// Wall time and evaluations per term, in term order, filled by [`ForceSet::forces_timed`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TermTimes {
    pub entries: Vec<(&'static str, std::time::Duration, u32)>,
}

impl TermTimes {
    pub fn clear(&mut self) {
        self.entries.clear();
    }

    fn add(&mut self, slot: usize, name: &'static str, took: std::time::Duration) {
        if self.entries.len() <= slot {
            self.entries
                .resize(slot + 1, (name, std::time::Duration::ZERO, 0));
        }
        let entry = &mut self.entries[slot];
        entry.0 = name;
        entry.1 += took;
        entry.2 += 1;
    }
}

impl<R: Real> Default for ForceSet<R> {
    fn default() -> Self {
        Self {
            terms: Vec::new(),
            time: 0.0,
            scratch: Scratch::default(),
        }
    }
}

impl ForceSet {
    /// The terms `effects` call for, with the cloth's `material`.
    pub fn new(model: &ClothModel, material: &Material, effects: &[Effect]) -> Self {
        let mut set = Self::default();
        set.configure(model, material, effects);
        set
    }

    /// A set of exactly these terms (tests, tools).
    pub fn from_terms(terms: Vec<Force>) -> Self {
        Self {
            terms,
            ..Self::default()
        }
    }
}

impl<R: Real> ForceSet<R> {
    /// Sets the simulated time forces are evaluated at, seconds.
    pub fn set_time(&mut self, time: f64) {
        self.time = time;
    }

    /// Rebuilds the term list for `effects` and `material`: each effect's term
    /// ([`Effect::force`]), keeping what the terms before derived (the springs' expansion
    /// and runs, the hinges' rest angles) where it still holds.
    pub fn configure(&mut self, model: &ClothModel, material: &Material, effects: &[Effect]) {
        let old = std::mem::take(&mut self.terms);
        self.terms = (effects.iter())
            .filter_map(|e| e.force(model, material, &old))
            .collect();
    }

    /// Takes what `changes` says changed: a new effect list rebuilds the terms
    /// ([`ForceSet::configure`]), new spring strengths alone retune the terms in place, and
    /// anything else leaves them be. Returns whether the terms changed.
    pub fn apply(
        &mut self,
        model: &ClothModel,
        material: &Material,
        effects: &[Effect],
        changes: Changes,
    ) -> bool {
        if changes.contains(Changes::EFFECTS) {
            self.configure(model, material, effects);
        } else if changes.contains(Changes::STRENGTHS) {
            for term in &mut self.terms {
                term.retune(model, material);
            }
        } else {
            return false;
        }
        true
    }

    pub fn terms(&self) -> &[Force<R>] {
        &self.terms
    }

    /// The spring terms (structural and shear, and bend springs when present).
    pub fn springs(&self) -> impl Iterator<Item = &SpringForce> {
        self.terms.iter().filter_map(Force::springs)
    }

    /// The springs as distance constraints (empty without springs).
    pub fn constraints(&self, model: &ClothModel) -> DistanceConstraints {
        let mut out = DistanceConstraints::default();
        for s in self.springs() {
            s.add_constraints(&model.springs, &mut out);
        }
        out
    }

    /// Writes the total force at `(pos, vel)` into `f` (resized), newtons. Terms selected
    /// by `keep` only.
    pub fn forces_where(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        keep: impl Fn(&Force<R>) -> bool,
        f: &mut Vec<R::V3>,
    ) {
        self.sum_forces(model, pos, vel, keep, f, None);
    }

    /// As [`ForceSet::forces_where`], charging each term's wall time to `times`.
    pub fn forces_timed(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        keep: impl Fn(&Force<R>) -> bool,
        f: &mut Vec<R::V3>,
        times: &mut TermTimes,
    ) {
        self.sum_forces(model, pos, vel, keep, f, Some(times));
    }

    fn sum_forces(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        keep: impl Fn(&Force<R>) -> bool,
        f: &mut Vec<R::V3>,
        times: Option<&mut TermTimes>,
    ) {
        f.clear();
        f.resize(pos.len(), R::V3::ZERO);
        self.each_term(keep, times, |term| {
            term.add_forces(model, pos, vel, self.time, f);
        });
    }

    /// Calls `eval` on each term `keep` selects, in order, charging its wall time to `times`.
    fn each_term(
        &self,
        keep: impl Fn(&Force<R>) -> bool,
        mut times: Option<&mut TermTimes>,
        mut eval: impl FnMut(&Force<R>),
    ) {
        for (slot, term) in self.terms.iter().enumerate().filter(|(_, t)| keep(t)) {
            match times.as_deref_mut() {
                Some(times) => {
                    let start = std::time::Instant::now();
                    eval(term);
                    times.add(slot, term.phase(), start.elapsed());
                }
                None => eval(term),
            }
        }
    }

    /// Whether every term [takes components](super::ForceTerm::takes_components), so that
    /// [`ForceSet::forces_components_timed`] gives the whole force.
    pub fn takes_components(&self) -> bool {
        self.terms.iter().all(|t| t.takes_components())
    }

    /// As [`ForceSet::forces_timed`] (all terms) with positions, velocities and forces
    /// stored one array per component: `f` is set to `pos`'s length and the terms add in
    /// the same order, so the forces are the same bits. Returns false, with `f` only
    /// partly summed, when a term does not [take components](ForceSet::takes_components).
    pub fn forces_components_timed(
        &self,
        model: &ClothModel,
        pos: &Components,
        vel: &Components,
        f: &mut Components,
        times: &mut TermTimes,
    ) -> bool {
        zeroed(f, pos[0].len());
        let mut whole = true;
        self.each_term(
            |_| true,
            Some(times),
            |term| {
                if term.takes_components() {
                    term.add_forces_components(model, pos, vel, f);
                } else {
                    whole = false;
                }
            },
        );
        whole
    }

    /// The forces on component arrays as [`ForceSet::forces_components_timed`] (the same
    /// bits), fused with the caller's per-particle work `then(range, f)` (a step's update),
    /// which gets each range's forces as soon as they are summed, while they are still in
    /// the cache. Two team sections in all, where the term-by-term path takes one or two
    /// per term: the blocks of every spring term, then per range of particles each term in
    /// order (a spring term that comes first overwrites the forces; before any other term
    /// they are zeroed), and `then`. Both sections are cut into pieces that the team's
    /// members take as they come ([`Team::run_pieces`]). A term's time is the calling
    /// thread's time on the pieces it ran; their sum is returned. `None`, with nothing done,
    /// when a term does not [take components](super::ForceTerm::takes_components) or the arrays are
    /// shorter than the springs reach.
    pub fn fused_components(
        &self,
        model: &ClothModel,
        pos: &Components,
        vel: &Components,
        f: &mut Components,
        times: &mut TermTimes,
        then: impl Fn(std::ops::Range<usize>, [&[f32]; 3]) + Sync,
    ) -> Option<Duration> {
        let n = (pos.iter().chain(vel).map(Vec::len)).fold(model.mass.len(), usize::min);
        // The spring terms' passes, with their places in the term list.
        let mut passes: [Option<(usize, TwoPasses<'_>)>; FUSED_PAIR_TERMS] =
            std::array::from_fn(|_| None);
        let mut pairs = 0;
        for (slot, term) in self.terms.iter().enumerate() {
            match term.fused(model) {
                Fused::Pointwise => {}
                Fused::TwoPasses(p) if pairs < FUSED_PAIR_TERMS && p.fits(n) => {
                    passes[pairs] = Some((slot, p));
                    pairs += 1;
                }
                Fused::TwoPasses(_) | Fused::No => return None,
            }
        }
        for comp in f.iter_mut() {
            comp.resize(n, 0.0);
        }
        let springs_first = matches!(passes[0], Some((0, _)));
        let team = Team::current();
        let members = if n >= PARALLEL_ELEMENTS {
            team.members()
        } else {
            1
        };
        let run = |pieces: usize, work: &(dyn Fn(usize, usize) + Sync)| {
            team.run_pieces_if(members > 1, pieces, work)
        };
        // The caller's time per term, nanoseconds.
        let took: [AtomicU64; MAX_TERMS] = std::array::from_fn(|_| AtomicU64::new(0));
        let timed = |i: usize, slot: usize, work: &mut dyn FnMut()| {
            if i != 0 || slot >= MAX_TERMS {
                return work();
            }
            let start = Instant::now();
            work();
            took[slot].fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        };
        {
            let fills: [Option<(usize, BlockPass<'_>)>; FUSED_PAIR_TERMS] =
                (passes.each_mut()).map(|p| p.as_mut().map(|(slot, p)| (*slot, p.blocks())));
            // A piece is one block of each spring term (its blocks cover the same particles).
            let blocks = fills.iter().flatten().map(|(_, f)| f.len()).max();
            run(blocks.unwrap_or(0), &|i, b| {
                for (slot, fill) in fills.iter().flatten() {
                    timed(i, *slot, &mut || fill.fill(b, pos, vel));
                }
            });
        }
        let [fx, fy, fz] = f;
        let out = [&mut fx[..n], &mut fy[..n], &mut fz[..n]].map(Disjoint::new);
        const LINE: usize = 16;
        let lines = n.div_ceil(LINE);
        let pieces = (members * PIECES_PER_MEMBER).min(lines);
        run(pieces, &|i, piece| {
            let lines = share(lines, pieces, piece);
            let range = (lines.start * LINE).min(n)..(lines.end * LINE).min(n);
            // SAFETY: the pieces are disjoint (shares of whole lines), each run once.
            let [fx, fy, fz] = std::array::from_fn(|c| unsafe { out[c].part(range.clone()) });
            let mass = &model.mass[range.clone()];
            let v = vel.each_ref().map(|v| &v[range.clone()]);
            if !springs_first {
                [&mut *fx, &mut *fy, &mut *fz]
                    .into_iter()
                    .for_each(|o| o.fill(0.0));
            }
            let mut pairs = passes.iter().flatten().peekable();
            for (slot, term) in self.terms.iter().enumerate() {
                let pair = pairs.next_if(|(at, _)| *at == slot);
                timed(i, slot, &mut || {
                    let f = [&mut *fx, &mut *fy, &mut *fz];
                    match pair {
                        Some((_, p)) if slot == 0 => p.write_to(range.clone(), f),
                        Some((_, p)) => p.add_to(range.clone(), f),
                        None => term.add_pointwise(mass, v, f),
                    }
                });
            }
            then(range, [&*fx, &*fy, &*fz]);
        });
        let mut total = Duration::ZERO;
        for (slot, term) in self.terms.iter().enumerate().take(MAX_TERMS) {
            let took = Duration::from_nanos(took[slot].load(Ordering::Relaxed));
            times.add(slot, term.phase(), took);
            total += took;
        }
        Some(total)
    }

    /// Accelerations at `(pos, vel)` into `acc` (resized) summed on component arrays, the
    /// same bits as [`ForceSet::accelerations`]; false, with nothing done, when a term needs
    /// the vectors whole.
    pub fn accelerations_components(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        acc: &mut Vec<R::V3>,
        times: &mut TermTimes,
    ) -> bool {
        let (Some(pos), Some(vel), Some(acc)) =
            (R::f32_slice(pos), R::f32_slice(vel), R::f32_vec_mut(acc))
        else {
            return false;
        };
        if !self.takes_components() {
            return false;
        }
        let mut scratch = self.scratch.lock();
        let [p, v, f] = &mut *scratch;
        let n = pos.len().min(vel.len()).min(model.inv_mass.len());
        split(pos, p, n);
        split(vel, v, n);
        if !self.forces_components_timed(model, p, v, f, times) {
            return false;
        }
        let [fx, fy, fz] = &*f;
        acc.clear();
        acc.extend((0..n).map(|i| Vec3::new(fx[i], fy[i], fz[i]) * model.inv_mass[i]));
        true
    }

    /// Writes the total force at `(pos, vel)` into `f`, newtons.
    pub fn forces(&self, model: &ClothModel, pos: &[R::V3], vel: &[R::V3], f: &mut Vec<R::V3>) {
        self.forces_where(model, pos, vel, |_| true, f);
    }

    /// Writes the accelerations at `(pos, vel)` into `acc`: the total force times the inverse
    /// mass, so pinned particles (inverse mass 0) get exactly zero.
    pub fn accelerations(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        acc: &mut Vec<R::V3>,
    ) {
        self.forces(model, pos, vel, acc);
        to_accelerations::<R>(&model.inv_mass, acc);
    }

    /// Potential energy of the conservative terms at `pos`, joules (relative to the rest
    /// length of the springs and `x = 0` for gravity). Dissipative terms have none.
    pub fn potential_energy(&self, model: &ClothModel, pos: &[R::V3]) -> f64 {
        self.terms
            .iter()
            .map(|t| t.potential_energy(model, pos))
            .sum()
    }

    /// `(∂f/∂x)·u` of all terms into `out` (resized).
    pub fn df_dx(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        u: &[R::V3],
        mode: JacobianMode,
        out: &mut Vec<R::V3>,
    ) {
        out.clear();
        out.resize(pos.len(), R::V3::ZERO);
        for term in &self.terms {
            term.add_df_dx(model, pos, vel, u, mode, out);
        }
    }

    /// `(∂f/∂v)·u` of all terms into `out` (resized).
    pub fn df_dv(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        u: &[R::V3],
        out: &mut Vec<R::V3>,
    ) {
        out.clear();
        out.resize(pos.len(), R::V3::ZERO);
        for term in &self.terms {
            term.add_df_dv(model, pos, vel, u, out);
        }
    }

    /// Assembles `A = M − h·∂f/∂v − h²·∂f/∂x` (definite form) and `(∂f/∂x)·v` at `(pos, vel)`.
    pub fn assemble(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        h: R,
        sys: &mut SystemMatrix<R>,
    ) {
        sys.begin(model, h);
        for term in &self.terms {
            term.add_to_system(model, pos, vel, sys);
        }
        sys.finish(&model.springs, pos, vel);
    }
}

/// Turns forces into accelerations in place: `a = f / m`, zero for pinned particles.
pub fn to_accelerations<R: Real>(inv_mass: &[f32], f: &mut [R::V3]) {
    for (a, &w) in f.iter_mut().zip(inv_mass) {
        *a *= R::of_f32(w);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    /// Where each term lives: the same address after a change means it was kept, not built.
    fn addresses(set: &ForceSet) -> Vec<*const ()> {
        (set.terms.iter())
            .map(|t| std::ptr::from_ref::<dyn super::super::ForceTerm>(&**t).cast::<()>())
            .collect()
    }

    fn forces(set: &ForceSet, model: &ClothModel, pos: &[Vec3], vel: &[Vec3]) -> Vec<Vec3> {
        let mut f = Vec::new();
        set.forces_where(model, pos, vel, |_| true, &mut f);
        f
    }

    /// New strengths retune the terms where they are and give the forces a set built for
    /// them gives; a change that is not the forces' leaves the terms be; a new effect list
    /// builds them again.
    #[test]
    fn a_change_redoes_only_what_depends_on_it() {
        let scene = Scene::builtin("sphere-drop").expect("scene");
        let (model, effects) = (&scene.model, &scene.effects);
        let mut material = scene.params.material;
        let mut set = ForceSet::new(model, &material, effects);
        let built = addresses(&set);
        // A state that stretches the springs: the initial one, sheared and moving.
        let pos: Vec<Vec3> = (scene.initial.pos.iter())
            .map(|p| *p + Vec3::new(0.1 * p.y, 0.0, 0.05 * p.x))
            .collect();
        let vel: Vec<Vec3> = pos.iter().map(|p| Vec3::new(p.z, -p.x, 0.5)).collect();

        material.stiffness[1] *= 3.0;
        material.damping[0] *= 2.0;
        assert!(set.apply(model, &material, effects, Changes::STRENGTHS));
        assert_eq!(addresses(&set), built, "retuned in place");
        let fresh = ForceSet::new(model, &material, effects);
        assert_eq!(
            forces(&set, model, &pos, &vel),
            forces(&fresh, model, &pos, &vel)
        );

        let others = Changes::all() - Changes::STRENGTHS - Changes::EFFECTS;
        assert!(!set.apply(model, &material, effects, others));
        assert_eq!(addresses(&set), built);

        let fewer: Vec<Effect> = (effects.iter())
            .filter(|e| !matches!(e, Effect::Bending(_)))
            .cloned()
            .collect();
        assert!(set.apply(model, &material, &fewer, Changes::EFFECTS));
        assert_eq!(set.terms.len(), built.len() - 1);
        let fresh = ForceSet::new(model, &material, &fewer);
        assert_eq!(
            forces(&set, model, &pos, &vel),
            forces(&fresh, model, &pos, &vel)
        );
    }
}
