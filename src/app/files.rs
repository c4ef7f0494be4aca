//! Opening cloths and scene files, saving the current setup as a scene file, exporting the
//! cloth as OBJ. A bad file never replaces what the app has.

use std::path::{Path, PathBuf};

use crate::scene::{Scene, Simulation};
use crate::sim::{Effect, Obstacle};

use super::background::{Load, Loaded};
use super::cloth_app::ClothApp;
use super::messages::Level;
use super::panel::Action;
use super::record::next_free;

impl ClothApp {
    /// Starts loading `path` in the background: a `.toml` scene file replaces the scene, an
    /// OBJ replaces the cloth. What the app has stays until the load succeeds.
    pub fn open_path(&mut self, path: PathBuf) {
        self.message(Level::Info, format!("loading {} …", path.display()));
        self.loading.load = Some(Load::start(path));
    }

    /// Waits for a running load (tests, or when the caller must know the outcome).
    pub fn finish_loading(&mut self) {
        if let Some(load) = self.loading.load.take()
            && let Some(result) = load.wait()
        {
            self.apply_loaded(&load.path, result);
        }
    }

    pub(super) fn poll_loading(&mut self) {
        let Some(load) = &self.loading.load else {
            return;
        };
        let Some(result) = load.poll() else { return };
        let path = load.path.clone();
        self.loading.load = None;
        self.apply_loaded(&path, result);
    }

    fn apply_loaded(&mut self, path: &Path, result: Result<Loaded, String>) {
        match result {
            Err(e) => {
                let kept = if path.extension().is_some_and(|e| e == "toml") {
                    "the current scene is kept"
                } else {
                    "the current cloth is kept"
                };
                self.message(Level::Error, format!("{e} — {kept}"));
            }
            Ok(Loaded::Scene(scene)) => {
                let text = format!(
                    "opened scene `{}` from {}: {} particles",
                    scene.scenario,
                    path.display(),
                    scene.model.particle_count()
                );
                // A scene file brings its own cloth.
                self.loading.custom_cloth = None;
                self.replace_sim(Simulation::new(*scene));
                self.message(Level::Info, text);
                self.reset_camera();
            }
            Ok(Loaded::Cloth(build)) => self.use_cloth(path, *build),
        }
    }

    /// A new cloth keeps the scenario, its effects and the current parameters.
    fn use_cloth(&mut self, path: &Path, build: crate::mesh::MeshBuild) {
        let name = path.display().to_string();
        let scene = match Scene::with_cloth(self.sim().scenario(), &build, &name) {
            Ok(scene) => scene,
            Err(e) => return self.message(Level::Error, e.to_string()),
        };
        let mut sim = Simulation::new(scene);
        // The current parameters were validated when they were set.
        if let Err(e) = sim.set_params(self.sim().params().clone()) {
            return self.message(Level::Error, e.to_string());
        }
        // The current effects, unless they do not fit the new cloth (a self-collision
        // thicker than its edges): then the scene's own, and the user is told.
        let mut notes = sim.warnings().to_vec();
        if let Err(e) = sim.set_effects(self.sim().effects().to_vec()) {
            notes.push(format!("{e}; the scene's own effects are used"));
        }
        sim.set_pins_enabled(self.sim().pins_enabled());
        let mut text = format!(
            "loaded {name}: {} particles, {} triangles",
            sim.model().particle_count(),
            sim.model().triangles.len()
        );
        // Import notes (dropped faces and the like) stay visible with the result.
        let level = if notes.is_empty() {
            Level::Info
        } else {
            text += &format!(" ({})", notes.join("; "));
            Level::Warning
        };
        self.message(level, text);
        self.loading.custom_cloth = Some((build, name));
        self.replace_sim(sim);
        self.reset_camera();
    }

    /// Writes the current setup (cloth, placement, parameters, effects, pins) as a scene
    /// file; a failure is reported and nothing is left half-written.
    pub fn save_scene(&mut self, path: &Path) {
        match self.sim().save_scene(path) {
            Ok(saved) if saved.meshes.is_empty() => {
                self.message(Level::Info, format!("saved scene to {}", path.display()));
            }
            Ok(saved) => {
                let meshes = saved.meshes.len();
                let text = format!(
                    "saved scene to {} with the {meshes} built-in meshes it uses beside it",
                    path.display()
                );
                self.message(Level::Info, text);
            }
            Err(e) => self.message(Level::Error, e.to_string()),
        }
    }

    /// Asks what a dropped OBJ is: the new cloth, or an obstacle added to the scene.
    pub(super) fn dropped_obj_ui(&mut self, ctx: &egui::Context) {
        let Some(path) = self.loading.dropped_obj.clone() else {
            return;
        };
        let mut choice = None;
        egui::Window::new("Dropped an OBJ")
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                ui.label(format!("What is {}?", path.display()));
                ui.horizontal(|ui| {
                    if ui.button("Replace cloth").clicked() {
                        choice = Some(Action::Open(path.clone()));
                    }
                    if ui.button("Add as obstacle").clicked() {
                        choice = Some(Action::AddObstacle(path.clone()));
                    }
                    if ui.button("Cancel").clicked() {
                        choice = Some(Action::DismissMessages);
                    }
                });
            });
        if let Some(action) = choice {
            self.loading.dropped_obj = None;
            if action != Action::DismissMessages {
                self.apply(action);
            }
        }
    }

    /// Reads `path` as an obstacle (placed as the file has it, the default friction, the
    /// solver's thickness) and adds it to the effects; a file that cannot be read is
    /// reported and the effects stay as they are.
    pub fn add_obstacle(&mut self, path: &Path) {
        let mut obstacle = Obstacle::new(path);
        if let Err(e) = obstacle.load(None) {
            return self.message(Level::Error, format!("{e} — the effects are kept"));
        }
        let triangles = obstacle.placed().map_or(0, |p| p.surface.triangles().len());
        let mut effects = self.sim().effects().to_vec();
        effects.push(Effect::Obstacle(obstacle));
        let before = self.sim().effects().len();
        self.apply_effects(effects);
        if self.sim().effects().len() > before {
            let text = format!("added obstacle {}: {triangles} triangles", path.display());
            self.message(Level::Info, text);
        }
    }

    /// Writes the cloth as it is now as `clothsim-export-NNNN.obj` in the capture folder.
    pub fn export_obj(&mut self) {
        self.catch_up();
        let path = next_free(&self.recording.capture_dir, "clothsim-export", ".obj");
        match crate::output::write_bytes(&path, self.sim().export_obj().as_bytes()) {
            Ok(()) => self.message(Level::Info, format!("exported {}", path.display())),
            Err(e) => self.message(Level::Error, e.to_string()),
        }
    }
}
