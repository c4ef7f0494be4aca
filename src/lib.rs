//! clothsim: a cloth simulator and viewer.
//!
//! Data flows one way: [`mesh`] import → [`cloth`] model → [`sim`] step → [`render`].
//! [`scene`] ties a cloth, its parameters and its effects together; the desktop
//! GUI comes later.

pub mod cloth;
pub mod mesh;
pub mod render;
pub mod scene;
pub mod sim;
