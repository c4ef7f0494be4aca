//! What a panel of the window reads and what it may ask for. A panel never holds the app: it
//! draws from a [`PanelContext`] and asks for [`Action`]s, which the app carries out once the
//! panel is drawn, through the functions that keep the window's copy of the simulation and
//! the stepping copy in step.

use std::path::PathBuf;

use glam::Vec3;

use crate::gpu::Backend;
use crate::render::RenderOptions;
use crate::scene::Simulation;
use crate::sim::{Effect, SimParams};

use super::messages::{Level, Message};
use super::stepping::{Checked, InEffect};

/// Something a panel (or the pointer) asks the app to do.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Play, or pause (dropping the frames already due).
    SetPlaying(bool),
    /// Pause and advance exactly one frame.
    StepOnce,
    /// Back to the initial state.
    Reset,
    /// Simulated seconds per wall-clock second.
    SetSpeed(f32),
    /// Capture the next drawn frame to a PNG.
    Capture,
    /// Open the Accuracy window.
    OpenAccuracy,
    /// Start or stop writing every drawn frame as a PNG.
    ToggleRecording,
    /// Start or stop recording an animated GIF.
    ToggleGif,
    /// Switch to a built-in scene (keeping a cloth the user opened).
    SetScenario(String),
    /// Open an OBJ cloth or a `.toml` scene file.
    Open(PathBuf),
    /// Back to each scene's own cloth.
    UseDefaultCloth,
    /// Read an OBJ and add it to the scene as an obstacle, where the file has it.
    AddObstacle(PathBuf),
    /// Write the current setup as a scene file.
    SaveScene(PathBuf),
    /// Write the cloth as it is now as OBJ, into the capture folder.
    ExportObj,
    /// Switch the scene's pins on or off.
    SetPinsEnabled(bool),
    /// Step on the CPU or the GPU.
    SetBackend(Backend),
    /// New parameters (refused with a message if bad).
    ApplyParams(SimParams),
    /// A new effect list (refused with a message if bad).
    ApplyEffects(Vec<Effect>),
    /// MSAA samples per pixel of the 3D view.
    SetSamples(u32),
    /// Frame the scene with its default camera.
    ResetCamera,
    /// Clear the status messages.
    DismissMessages,
    /// Check every frame for intersections (the cloth's own and with each solid), or not.
    CheckIntersections(bool),
    /// Pin particle `p`, or free it.
    TogglePin(u32),
    /// Hold a particle at a point (metres) until released.
    Grab { particle: u32, target: Vec3 },
    /// Let go of the held particle.
    Release,
    /// Show a message.
    Tell(Level, String),
}

/// What the window shows besides the simulation.
#[derive(Clone, Copy, Debug)]
pub struct Status<'a> {
    /// Backend, substeps and integrator in effect on the stepping copy.
    pub in_effect: InEffect,
    pub playing: bool,
    /// Simulated seconds per wall-clock second.
    pub speed: f32,
    /// The simulation runs slower than real time.
    pub behind: bool,
    /// UI frames per second.
    pub fps: f64,
    /// Milliseconds of simulation per simulated frame, by phase.
    pub phase_ms: &'a [(&'static str, f64)],
    /// "name (backend, type)" of the adapter drawing the view.
    pub adapter: Option<&'a str>,
    /// The latest status message.
    pub message: Option<&'a Message>,
    /// A file is loading.
    pub loading: bool,
    pub recording: bool,
    pub recording_gif: bool,
    /// The user opened a cloth that replaces each scene's own.
    pub custom_cloth: bool,
    /// MSAA samples in use and those the adapter offers.
    pub samples_in_use: u32,
    pub sample_choices: &'a [u32],
    /// Whether every frame is checked for intersections, and what the check found.
    pub check: (bool, Option<&'a Checked>),
}

/// What a panel draws from, and where it puts what it asks for.
pub struct PanelContext<'a> {
    /// The simulation as the window shows it (read only: changes are [`Action`]s).
    pub sim: &'a Simulation,
    pub status: Status<'a>,
    /// How the 3D view draws the cloth: the View panel's to edit.
    pub options: &'a mut RenderOptions,
    actions: &'a mut Vec<Action>,
}

impl<'a> PanelContext<'a> {
    pub fn new(
        sim: &'a Simulation,
        status: Status<'a>,
        options: &'a mut RenderOptions,
        actions: &'a mut Vec<Action>,
    ) -> Self {
        Self {
            sim,
            status,
            options,
            actions,
        }
    }

    /// Asks the app to do something once the panels are drawn.
    pub fn ask(&mut self, action: Action) {
        self.actions.push(action);
    }
}

/// A part of the window: draws itself and asks for what the user did.
pub trait Panel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>);
}
