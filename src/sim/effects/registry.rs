//! The one list of effects. Each line makes an effect type a variant of [`Effect`], the
//! type scene files, the simulation and the app share; every dispatch below is generated
//! from it. A new effect is a file implementing [`EffectKind`] and one line here (and its
//! controls in the app).

use glam::Vec3;

use crate::cloth::{ClothModel, ClothState, Real};
use crate::sim::forces::Force;
use crate::sim::param_error::ParamError;
use crate::sim::params::Material;
use crate::sim::self_contacts::ContactError;

use super::air_damping::AirDamping;
use super::bending::BendingModel;
use super::cloth_springs::ClothSprings;
use super::effect_kind::{ClothBox, ContactPass, EffectKind, GuardShare};
use super::gravity::Gravity;
use super::handle::Handle;
use super::obstacle::Obstacle;
use super::plane::Plane;
use super::self_collision::SelfCollision;
use super::sphere::Sphere;
use super::wind::Wind;

/// An effect the app offers to add: its title, whether a scene may have several, and the
/// effect with settings that suit a cloth.
pub struct Addable {
    pub title: &'static str,
    pub many: bool,
    pub make: fn(&ClothBox) -> Effect,
}

macro_rules! effects {
    ($($(#[$attr:meta])* $variant:ident($ty:ty),)*) => {
        /// One physical effect a scene can switch on, with its parameters. Scene files list
        /// them as `[[effects]]` tables with `type = "…"`; only the effects a scene lists
        /// run.
        #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(tag = "type", rename_all = "kebab-case")]
        pub enum Effect {
            $($(#[$attr])* $variant($ty),)*
        }

        $(impl From<$ty> for Effect {
            fn from(e: $ty) -> Self {
                Effect::$variant(e)
            }
        })*

        impl Effect {
            /// Its `type` in scene files, and the name of its phase in timings.
            pub fn phase(&self) -> &'static str {
                match self { $(Effect::$variant(_) => <$ty as EffectKind>::NAME,)* }
            }

            /// What the app calls it.
            pub fn title(&self) -> &'static str {
                match self { $(Effect::$variant(_) => <$ty as EffectKind>::TITLE,)* }
            }

            /// Whether a scene may have several of its kind.
            pub fn many(&self) -> bool {
                match self { $(Effect::$variant(_) => <$ty as EffectKind>::MANY,)* }
            }

            /// Whether `other` is of the same kind.
            pub fn same_kind(&self, other: &Effect) -> bool {
                std::mem::discriminant(self) == std::mem::discriminant(other)
            }

            /// Checks what the types cannot rule out ([`EffectKind::check`]).
            ///
            /// # Errors
            /// [`ParamError`] naming the key as a scene file spells it.
            pub fn check(&self) -> Result<(), ParamError> {
                match self { $(Effect::$variant(e) => e.check(),)* }
            }

            /// Its force term, if it adds one ([`EffectKind::force`]).
            pub fn force<R: Real>(&self, model: &ClothModel, material: &Material, kept: &[Force<R>]) -> Option<Force<R>> {
                match self { $(Effect::$variant(e) => e.force(model, material, kept),)* }
            }

            /// Whether it is a solid the cloth may not enter (it has a [surface](EffectKind::surface)).
            pub fn is_solid(&self) -> bool {
                match self { $(Effect::$variant(e) => e.is_solid(),)* }
            }

            /// Whether it acts after each substep ([`EffectKind::is_contact`]).
            pub fn is_contact(&self) -> bool {
                match self { $(Effect::$variant(e) => e.is_contact(),)* }
            }

            /// Resolves its contacts after a substep ([`EffectKind::resolve`]).
            ///
            /// # Errors
            /// [`ContactError`] for a state that has blown up.
            pub fn resolve(&self, pass: &mut ContactPass<'_>) -> Result<usize, ContactError> {
                match self { $(Effect::$variant(e) => e.resolve(pass),)* }
            }

            /// A solid's signed distance, normal and surface velocity at `p`, where it is at
            /// time `t` ([`EffectKind::surface`]).
            pub fn surface(&self, p: Vec3, t: f64) -> Option<(f32, Vec3, Vec3)> {
                match self { $(Effect::$variant(e) => e.surface(p, t),)* }
            }

            /// How far a solid keeps the cloth from its surface where the scene's offset is
            /// `offset` ([`EffectKind::clearance`]).
            pub fn clearance(&self, offset: f32) -> f32 {
                match self { $(Effect::$variant(e) => e.clearance(offset),)* }
            }

            /// A solid's box of the points within `offset` of it or inside it, at time `t`
            /// ([`EffectKind::shell`]).
            pub fn shell(&self, t: f64, offset: f32) -> Option<(Vec3, Vec3)> {
                match self { $(Effect::$variant(e) => e.shell(t, offset),)* }
            }

            /// What it adds to the guard's limits ([`EffectKind::guard`]).
            pub fn guard(&self, up: Vec3, cloth: &ClothState) -> GuardShare {
                match self { $(Effect::$variant(e) => e.guard(up, cloth),)* }
            }

            /// Whether the GPU backend runs it ([`EffectKind::on_gpu`]).
            ///
            /// # Errors
            /// What the GPU backend lacks.
            pub fn on_gpu(&self) -> Result<(), &'static str> {
                match self { $(Effect::$variant(e) => e.on_gpu(),)* }
            }

            /// The effects a user can add, in the list's order.
            pub fn addable() -> Vec<Addable> {
                let mut out = Vec::new();
                $(if <$ty as EffectKind>::ADDABLE {
                    out.push(Addable {
                        title: <$ty as EffectKind>::TITLE,
                        many: <$ty as EffectKind>::MANY,
                        make: |cloth| Effect::$variant(<$ty as EffectKind>::suggested(cloth)),
                    });
                })*
                out
            }
        }
    };
}

effects! {
    /// The cloth's structural and shear springs: in every scene, never listed in files.
    #[serde(skip)]
    Springs(ClothSprings),
    Gravity(Gravity),
    AirDamping(AirDamping),
    Bending(BendingModel),
    Wind(Wind),
    SelfCollision(SelfCollision),
    Sphere(Sphere),
    Plane(Plane),
    Obstacle(Obstacle),
    /// Particles moved along keyframes: from a scene file's `[[handles]]`, not its effects.
    #[serde(skip)]
    Handle(Handle),
}
