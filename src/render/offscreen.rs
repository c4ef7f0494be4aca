//! Headless rendering in one call: device + renderer + target, for the CLI and tests.

use glam::Vec3;

use crate::scene::Simulation;
use crate::sim::Collider;

use super::camera::OrbitCamera;
use super::capture::{RgbaImage, read_target};
use super::device::{AdapterPreference, Gpu};
use super::error::RenderError;
use super::options::RenderOptions;
use super::renderer::{FrameInput, Renderer};
use super::target::{RenderTarget, supported_sample_count};

pub struct Offscreen {
    pub gpu: Gpu,
    pub renderer: Renderer,
    pub target: RenderTarget,
}

impl Offscreen {
    /// A `width × height` offscreen renderer with the best MSAA the adapter supports (≤ 4).
    ///
    /// # Errors
    /// No adapter, no device, or a bad size.
    pub fn new(
        width: u32,
        height: u32,
        preference: AdapterPreference,
    ) -> Result<Self, RenderError> {
        let gpu = Gpu::headless(preference)?;
        let samples = supported_sample_count(&gpu.adapter);
        let target = RenderTarget::new(&gpu.device, width, height, samples)?;
        let renderer = Renderer::new(&gpu.device, samples);
        Ok(Self {
            gpu,
            renderer,
            target,
        })
    }

    /// Draws the simulation's current state and reads the image back.
    ///
    /// # Errors
    /// [`RenderError::Readback`].
    pub fn render(
        &mut self,
        sim: &Simulation,
        camera: &OrbitCamera,
        options: &RenderOptions,
    ) -> Result<RgbaImage, RenderError> {
        let frame = FrameInput::of(sim);
        self.renderer.render(
            &self.gpu.device,
            &self.gpu.queue,
            &self.target,
            camera,
            &frame,
            options,
        );
        read_target(&self.gpu.device, &self.gpu.queue, &self.target)
    }
}

/// A camera that frames a scene: its cloth's initial shape, extended downwards to where the
/// cloth will go (a pinned cloth hangs up to its own size below its pins; a free one falls
/// onto what is below), and its spheres.
pub fn scene_camera(sim: &Simulation) -> OrbitCamera {
    let (mut lo, mut hi) = crate::mesh::bounds(&sim.scene.initial.pos);
    let size = (hi - lo).max_element();
    lo.y -= if sim.scene.model.pins.is_empty() {
        0.2 * size
    } else {
        size
    };
    for c in sim.stepper().colliders() {
        if let Collider::Sphere { center, radius, .. } = *c {
            lo = lo.min(center - Vec3::splat(radius));
            hi = hi.max(center + Vec3::splat(radius));
        }
    }
    OrbitCamera::framing(lo, hi)
}
