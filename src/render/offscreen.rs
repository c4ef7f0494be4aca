//! Headless rendering in one call: device + renderer + target, for the CLI and tests.

use super::camera::OrbitCamera;
use super::capture::{RgbaImage, read_target};
use super::error::RenderError;
use super::frame::Frame;
use super::options::RenderOptions;
use super::renderer::Renderer;
use super::target::{RenderTarget, supported_sample_count};
use crate::device::{AdapterPreference, HeadlessDevice};

pub struct Offscreen {
    pub gpu: HeadlessDevice,
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
        let gpu = HeadlessDevice::open(preference)?;
        let samples = supported_sample_count(&gpu.adapter);
        let target = RenderTarget::new(&gpu.device, width, height, samples)?;
        let renderer = Renderer::new(&gpu.device, samples);
        Ok(Self {
            gpu,
            renderer,
            target,
        })
    }

    /// Width over height of the target.
    pub fn aspect(&self) -> f32 {
        let (w, h) = self.target.size();
        w as f32 / h as f32
    }

    /// Draws `frame` and reads the image back.
    ///
    /// # Errors
    /// [`RenderError::Readback`].
    pub fn render(
        &mut self,
        frame: &Frame<'_>,
        camera: &OrbitCamera,
        options: &RenderOptions,
    ) -> Result<RgbaImage, RenderError> {
        self.renderer.render(
            &self.gpu.device,
            &self.gpu.queue,
            &self.target,
            camera,
            frame,
            options,
        );
        read_target(&self.gpu.device, &self.gpu.queue, &self.target)
    }
}
