//! The native window: eframe's options and the app inside it.

use std::path::PathBuf;
use std::sync::Arc;

use crate::device::window_device_descriptor;

/// `setup` with [`window_device_descriptor`] (when it creates its own device).
pub fn with_compute_limits(mut setup: egui_wgpu::WgpuSetup) -> egui_wgpu::WgpuSetup {
    if let egui_wgpu::WgpuSetup::CreateNew(new) = &mut setup {
        new.device_descriptor = Arc::new(window_device_descriptor);
    }
    setup
}

/// Opens the window and runs until it is closed.
///
/// # Errors
/// When no window or graphics context can be created.
pub fn run(obj: Option<PathBuf>) -> eframe::Result {
    let mut wgpu_options = egui_wgpu::WgpuConfiguration::default();
    wgpu_options.wgpu_setup = with_compute_limits(wgpu_options.wgpu_setup);
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("clothsim")
            .with_inner_size([1280.0, 800.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        // egui's pass keeps one sample and no depth buffer: the 3D view's image is put into
        // it by a pipeline made for exactly that (`viewport::ViewPaint`).
        multisampling: 0,
        depth_buffer: 0,
        wgpu_options,
        ..Default::default()
    };
    eframe::run_native(
        "clothsim",
        options,
        Box::new(move |cc| {
            let mut app = super::ClothApp::new(cc.wgpu_render_state.clone(), obj.as_deref());
            app.view.log_frame_times = std::env::var_os("CLOTHSIM_FRAME_TIMES").is_some();
            Ok(Box::new(app))
        }),
    )
}
