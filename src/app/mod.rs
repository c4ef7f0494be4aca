//! The desktop app (eframe + egui): panels, 3D viewport, drag-and-drop, capture. Thin: it
//! drives the library and never re-implements it.

mod accuracy;
mod background;
mod cloth_app;
mod controls;
mod effects;
mod files;
mod pointer;
mod record;
mod stepping;
mod transport;
mod viewport;
mod window;

pub use accuracy::AccuracyWindow;
pub use cloth_app::{ClothApp, Level, Message, Stats};
pub use stepping::InEffect;
pub use transport::Transport;
pub use window::{device_descriptor, run, with_compute_limits};
