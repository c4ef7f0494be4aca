//! clothsim: a cloth simulator and viewer.
//!
//! Data flows one way: [`mesh`] import → [`cloth`] model → [`sim`] step → [`render`].
//! [`scene`] ties a cloth, its parameters and its effects together; [`view`] turns a running
//! simulation into the renderer's plain frame description; [`app`] is the desktop GUI and the
//! only module that knows about windows and input.
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
//! // Still falling freely after a quarter second, slowed only by air damping c = 0.5/s:
//! // g/c·(t − (1 − e^(−ct))/c) = 0.294 m below the start, above the sphere it will meet.
//! let dropped = sim.initial().pos[0].y - sim.state().pos[0].y;
//! assert!((dropped - 0.294).abs() < 0.002, "fell {dropped} m");
//! # Ok::<(), clothsim::scene::SceneError>(())
//! ```

pub mod app;
pub mod bench;
pub mod bench_contact;
pub mod bench_crumple;
pub mod cloth;
pub mod device;
pub mod gpu;
pub mod mesh;
pub mod output;
pub mod parallel;
pub mod render;
pub mod report;
pub mod scene;
pub mod sim;
pub mod view;

#[cfg(test)]
mod test_rng;
