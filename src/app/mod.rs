//! The desktop app (eframe + egui): panels, 3D viewport, drag-and-drop, capture. Thin: it
//! drives the library and never re-implements it.

mod background;
mod cloth_app;
mod controls;
mod transport;
mod viewport;

pub use cloth_app::{ClothApp, Level, Message, Stats};
pub use transport::Transport;

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
            Ok(Box::new(ClothApp::new(
                cc.wgpu_render_state.clone(),
                obj.as_deref(),
            )))
        }),
    )
}
