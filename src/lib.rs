//! clothsim: a cloth simulator and viewer.
//!
//! Data flows one way: [`mesh`] import → [`cloth`] model → [`sim`] step → [`render`].
//! [`scene`] ties a cloth, its parameters and its effects together; [`app`] is the desktop
//! GUI and the only module that knows about windows and input.

pub mod app;
pub mod cloth;
pub mod mesh;
pub mod render;
pub mod scene;
pub mod sim;
