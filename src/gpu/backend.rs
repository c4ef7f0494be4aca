//! Which backend steps a simulation, and a simulation on a headless device of its own.

use crate::device::{AdapterPreference, HeadlessDevice, describe_adapter};
use crate::scene::{Scene, Simulation};

use super::error::GpuError;
use super::stepper::GpuStepper;
use super::support::gpu_support;

/// Which backend steps a simulation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Backend {
    /// The CPU solver: every integrator and effect, with the stability guard.
    #[default]
    Cpu,
    /// wgpu compute: semi-implicit and implicit Euler, XPBD and VBD; springs, gravity, air
    /// damping, wind, dihedral bending, pins, handles, spheres and planes, mesh obstacles
    /// (rigid or OBJ sequences), self-collision; with the stability guard.
    Gpu,
}

/// A simulation of `scene` on its own headless GPU device (the first adapter the system
/// offers, a software one if that is all there is). With `read_every_frame`, the
/// simulation's state is current after every frame; without, after
/// [`Simulation::sync_state`]. Returns the simulation and the adapter's description.
///
/// # Errors
/// No adapter or device, or a scene the GPU backend cannot run (said in the message).
pub fn gpu_simulation(
    scene: Scene,
    read_every_frame: bool,
) -> Result<(Simulation, String), GpuError> {
    gpu_simulation_on(scene, read_every_frame, AdapterPreference::Any)
}

/// [`gpu_simulation`] on the adapter `preference` picks: the tests ask for the software
/// one, as their golden images do, so that the same rasteriser's compiler runs them
/// whatever else the machine has (through Vulkan's lavapipe a contact decision at its
/// threshold went the other way in one comparison with the CPU).
///
/// # Errors
/// As [`gpu_simulation`].
pub fn gpu_simulation_on(
    scene: Scene,
    read_every_frame: bool,
    preference: AdapterPreference,
) -> Result<(Simulation, String), GpuError> {
    let params = &scene.params;
    gpu_support(&params.step, params.solver.precision, &scene.effects)?;
    let gpu = HeadlessDevice::open(preference)?;
    let stepper = GpuStepper::new(
        &gpu.device,
        &gpu.queue,
        &scene.model,
        &scene.params,
        &scene.effects,
        read_every_frame,
    )?;
    let adapter = describe_adapter(&gpu.adapter);
    Ok((Simulation::with_backend(scene, Box::new(stepper)), adapter))
}
