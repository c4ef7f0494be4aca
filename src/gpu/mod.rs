//! The GPU step backend: semi-implicit Euler, implicit Euler, XPBD and VBD for the
//! mass-spring cloth in wgpu compute shaders, under the stability guard. It sits beside the CPU solver (which knows nothing of
//! graphics) and plugs into [`crate::scene::Simulation`] through the same
//! [`crate::sim::StepBackend`] seam. What it runs (`support`), how it lays the cloth out
//! (`packing`), its kernels (`kernel`, `elements`, `health`, `xpbd`, `vbd`,
//! `implicit`, with its substeps in `implicit_steps`; the contacts after each substep,
//! `contacts`, `obstacles`, `self_contact`, what they share in `substep_ends`), the stepper that
//! drives them (`stepper`)
//! and the guard's frame with its rollback points on the device (`guarded`, `snapshot`) are
//! files of their own; it reaches the device through [`crate::device`] only.

mod backend;
mod contacts;
mod elements;
mod error;
mod guarded;
mod handles;
mod health;
mod held;
mod implicit;
mod implicit_steps;
mod kernel;
mod obstacles;
mod packing;
mod rebuild;
mod self_contact;
mod snapshot;
mod stepper;
mod substep_ends;
mod support;
mod vbd;
mod xpbd;

pub use backend::{Backend, gpu_simulation, gpu_simulation_on};
pub use error::GpuError;
pub use stepper::GpuStepper;
pub use support::{GPU_INTEGRATOR, GPU_INTEGRATORS, gpu_support};
