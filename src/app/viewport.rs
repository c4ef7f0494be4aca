//! The 3D view: the renderer's offscreen texture shown in the central panel, plus orbit /
//! zoom / pan input. What it shows is exactly what capture writes.

use egui_wgpu::RenderState;

use crate::render::{
    Frame, OrbitCamera, RenderError, RenderOptions, RenderTarget, Renderer, RgbaImage, read_target,
};

/// Radians of orbit per point dragged.
const ORBIT_PER_POINT: f32 = 0.008;
/// Zoom factor per point scrolled: `exp(−delta · ZOOM_RATE)`.
const ZOOM_RATE: f32 = 0.0025;

pub struct Viewport {
    renderer: Renderer,
    target: RenderTarget,
    texture: egui::TextureId,
}

impl Viewport {
    /// Creates the renderer and a first target with `samples` MSAA samples (one the adapter
    /// supports) on the GUI's device.
    ///
    /// # Errors
    /// [`RenderError::BadSize`] for an impossible size.
    pub fn new(
        rs: &RenderState,
        width: u32,
        height: u32,
        samples: u32,
    ) -> Result<Self, RenderError> {
        let target = RenderTarget::new(&rs.device, width.max(1), height.max(1), samples)?;
        let renderer = Renderer::new(&rs.device, samples);
        // The view is drawn at its own size, one texel per pixel: nearest sampling shows the
        // same image as linear and costs less on a software adapter.
        let texture = rs.renderer.write().register_native_texture(
            &rs.device,
            target.view(),
            wgpu::FilterMode::Nearest,
        );
        Ok(Self {
            renderer,
            target,
            texture,
        })
    }

    /// Resizes the target to `width × height` pixels if needed and draws the frame.
    ///
    /// # Errors
    /// [`RenderError::BadSize`].
    pub fn draw(
        &mut self,
        rs: &RenderState,
        width: u32,
        height: u32,
        frame: &Frame<'_>,
        camera: &OrbitCamera,
        options: &RenderOptions,
    ) -> Result<(), RenderError> {
        if self
            .target
            .resize(&rs.device, width.max(1), height.max(1))?
        {
            rs.renderer.write().update_egui_texture_from_wgpu_texture(
                &rs.device,
                self.target.view(),
                wgpu::FilterMode::Nearest,
                self.texture,
            );
        }
        self.renderer
            .render(&rs.device, &rs.queue, &self.target, camera, frame, options);
        Ok(())
    }

    /// MSAA samples per pixel.
    pub fn samples(&self) -> u32 {
        self.target.sample_count()
    }

    pub fn texture(&self) -> egui::TextureId {
        self.texture
    }

    /// Reads the last drawn image back (what the window shows).
    ///
    /// # Errors
    /// [`RenderError::Readback`].
    pub fn read(&self, rs: &RenderState) -> Result<RgbaImage, RenderError> {
        read_target(&rs.device, &rs.queue, &self.target)
    }

    pub fn free(&self, rs: &RenderState) {
        rs.renderer.write().free_texture(&self.texture);
    }
}

/// Applies drag and scroll on `response` to `camera`; returns whether the user asked for
/// the view to be reset (double-click).
pub fn camera_input(ui: &egui::Ui, response: &egui::Response, camera: &mut OrbitCamera) -> bool {
    let height = response.rect.height().max(1.0);
    let shift = ui.input(|i| i.modifiers.shift);
    if response.dragged_by(egui::PointerButton::Middle)
        || (response.dragged_by(egui::PointerButton::Primary) && shift)
    {
        let d = response.drag_delta();
        camera.pan(-d.x / height, d.y / height);
    } else if response.dragged_by(egui::PointerButton::Primary)
        || response.dragged_by(egui::PointerButton::Secondary)
    {
        let d = response.drag_delta();
        camera.orbit(-d.x * ORBIT_PER_POINT, d.y * ORBIT_PER_POINT);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera.zoom((-scroll * ZOOM_RATE).exp());
        }
    }
    response.double_clicked()
}
