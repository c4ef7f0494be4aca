//! What every effect says about itself: its name, its checks, the force term or the contact
//! it adds to a step, what it adds to the guard's limits, whether the GPU backend runs it,
//! and a setting to start from for a given cloth.

use glam::Vec3;

use super::faces::FacePatches;
use crate::cloth::{ClothModel, ClothState, Real};
use crate::sim::forces::Force;
use crate::sim::param_error::ParamError;
use crate::sim::params::Material;
use crate::sim::self_contacts::{ContactError, SelfContacts};

/// What one substep's contact pass works on.
pub struct ContactPass<'a> {
    pub model: &'a ClothModel,
    /// Positions at the substep's start: the paths contacts sweep end where `state` is now.
    pub start: &'a [Vec3],
    /// The substep's length, seconds (it started at `state.time − substep`).
    pub substep: f32,
    pub state: &'a mut ClothState,
    /// Collision thickness against colliders, metres.
    pub offset: f32,
    /// Self-collision's buffers, kept between substeps.
    pub self_contacts: &'a mut SelfContacts,
    /// Where solids keep the cloth's triangles out too, not only its particles (the
    /// stepper's always: the guarantee covers the surface, and a coarse cloth's triangle
    /// dips into a sphere or over a tip between its corners): the triangles in patches,
    /// so a solid tests the triangles of the patches near it only. `None` keeps only the
    /// particles and edges out (tests of those passes alone).
    pub faces: Option<&'a mut FacePatches>,
}

/// What an effect adds to the stability guard's limits.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GuardShare {
    /// The lowest point of its surface along `up`, metres (the cloth can fall to it).
    pub floor: Option<f32>,
    /// The fastest its surface moves, m/s (it can throw the cloth that fast).
    pub surface_speed: f32,
    /// The fastest air it blows, m/s.
    pub flow_speed: f32,
}

/// A cloth as an effect's suggested setting sees it: its box now and its shortest rest
/// edge (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClothBox {
    pub lo: Vec3,
    pub hi: Vec3,
    pub shortest_edge: f32,
}

/// One kind of effect, implemented in its own file; the list in `registry.rs` makes each a
/// variant of [`super::Effect`] and dispatches to these methods.
pub trait EffectKind: Sized {
    /// Its `type` in scene files, and its phase in timings.
    const NAME: &'static str;
    /// What the app calls it.
    const TITLE: &'static str;
    /// Whether a scene may have more than one (spheres), and whether a user adds it (the
    /// cloth's springs are always there).
    const MANY: bool;
    const ADDABLE: bool;

    /// Checks what the types cannot rule out.
    ///
    /// # Errors
    /// [`ParamError`] naming the key as a scene file spells it.
    fn check(&self) -> Result<(), ParamError> {
        Ok(())
    }

    /// The force term it adds to a step, built for `model` with the cloth's `material`
    /// (from what `kept`, the terms before, already derived); `None`: no force.
    fn force<R: Real>(
        &self,
        _model: &ClothModel,
        _material: &Material,
        _kept: &[Force<R>],
    ) -> Option<Force<R>> {
        None
    }

    /// Whether it acts after each substep (a contact).
    fn is_contact(&self) -> bool {
        false
    }

    /// Resolves its contacts after a substep; returns how many particles it moved.
    ///
    /// # Errors
    /// [`ContactError`] for a state that has blown up.
    fn resolve(&self, _pass: &mut ContactPass<'_>) -> Result<usize, ContactError> {
        Ok(0)
    }

    /// Whether it is a solid the cloth may not enter: then [`EffectKind::surface`] answers.
    fn is_solid(&self) -> bool {
        false
    }

    /// For a solid: signed distance from `p` to its surface where it is at time `t` (s; m,
    /// negative inside), the outward normal there, and the surface's velocity there (m/s).
    fn surface(&self, _p: Vec3, _t: f64) -> Option<(f32, Vec3, Vec3)> {
        None
    }

    /// For a solid: how far it keeps the cloth from its surface, m, where the scene's
    /// collision offset is `offset` (a mesh obstacle may have its own).
    fn clearance(&self, offset: f32) -> f32 {
        offset
    }

    /// For a solid: a box holding every point within `offset` of its surface or inside it,
    /// where it is at time `t` (s); a side it does not bound is infinite (a plane's box is
    /// unbounded along it, and across it unless it faces along an axis; a solid whose box
    /// is not known cheaply gives an unbounded one). `None` for what is not a solid.
    fn shell(&self, _t: f64, _offset: f32) -> Option<(Vec3, Vec3)> {
        None
    }

    /// What it adds to the guard's limits for `cloth` as it is when they are derived, with
    /// `up` against gravity.
    fn guard(&self, _up: Vec3, _cloth: &ClothState) -> GuardShare {
        GuardShare::default()
    }

    /// Whether the GPU backend runs it (`Err`: what it lacks). Every effect must say.
    ///
    /// # Errors
    /// The name of what the GPU backend does not have.
    fn on_gpu(&self) -> Result<(), &'static str>;

    /// A setting that suits `cloth` (what the app's *Add effect* gives).
    fn suggested(cloth: &ClothBox) -> Self;
}
