//! The desktop app (eframe + egui): panels, 3D viewport, drag-and-drop, capture. Thin: it
//! drives the library and never re-implements it.

mod accuracy;
mod accuracy_extras;
mod background;
mod cloth_app;
mod files;
mod intersection_check;
mod messages;
mod panel;
mod panels;
mod pointer;
mod record;
mod stepping;
mod transport;
mod viewport;
mod window;

pub use accuracy::AccuracyWindow;
pub use cloth_app::{ClothApp, Loading, Panels, Recording, Stats, ViewState};
pub use intersection_check::IntersectionCheck;
pub use messages::{Level, Message};
pub use panel::{Action, Panel, PanelContext, Status};
pub use panels::{
    EffectsPanel, MaterialPanel, ScenePanel, SidePanel, SolverPanel, StatusBar, TransportBar,
    ViewPanel,
};
pub use stepping::{Checked, InEffect};
pub use transport::Transport;
pub use window::{run, with_compute_limits};
