//! The native window: eframe's options and the app inside it.

use std::path::PathBuf;

/// Opens the window and runs until it is closed.
///
/// # Errors
/// When no window or graphics context can be created.
pub fn run(obj: Option<PathBuf>) -> eframe::Result {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("clothsim")
            .with_inner_size([1280.0, 800.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    eframe::run_native(
        "clothsim",
        options,
        Box::new(move |cc| {
            Ok(Box::new(super::ClothApp::new(
                cc.wgpu_render_state.clone(),
                obj.as_deref(),
            )))
        }),
    )
}
