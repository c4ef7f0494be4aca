//! clothsim: a cloth simulator and viewer.
//!
//! Data flows one way: [`mesh`] import → [`cloth`] model → [`sim`] step → [`render`].
//! [`scene`] ties a cloth, its parameters and its effects together; [`app`] is the desktop
//! GUI and the only module that knows about windows and input.
//!
//! Headless use: build a registered scenario, run it, read the summary.
//!
//! ```
//! use clothsim::scene::{Scene, Simulation};
//!
//! let mut sim = Simulation::new(Scene::builtin("sphere-drop")?);
//! let summary = sim.run(0.25);
//! assert!(summary.finite);
//! assert_eq!(summary.particles, 625);
//! // The cloth is still falling towards the sphere, and nothing is inside it.
//! assert!(summary.min_collider_distance.unwrap() > 0.0);
//! # Ok::<(), clothsim::scene::SceneError>(())
//! ```

pub mod app;
pub mod cloth;
pub mod mesh;
pub mod render;
pub mod scene;
pub mod sim;
