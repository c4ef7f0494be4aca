//! The window's panels, one type each, drawn through [`super::panel::Panel`].

mod effects;
mod material;
mod scene;
mod side_panel;
mod sliders;
mod solver;
mod status_bar;
mod transport_bar;
mod view;

pub use effects::EffectsPanel;
pub use material::MaterialPanel;
pub use scene::ScenePanel;
pub use side_panel::SidePanel;
pub use solver::SolverPanel;
pub use status_bar::{StatusBar, drop_hint};
pub use transport_bar::TransportBar;
pub use view::ViewPanel;
