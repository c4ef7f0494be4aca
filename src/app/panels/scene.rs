//! The Scene section: built-in scenes, opening a cloth or a scene file, saving the setup,
//! exporting the cloth, the scene's pins.

use egui::RichText;

use crate::scene::scenarios;

use super::super::panel::{Action, Panel, PanelContext};

/// The Scene section, with its two path fields.
pub struct ScenePanel {
    /// Text of the "open" path field (an OBJ cloth or a `.toml` scene).
    pub open_path: String,
    /// Text of the "save scene" path field.
    pub save_path: String,
}

impl Default for ScenePanel {
    fn default() -> Self {
        Self {
            open_path: String::new(),
            save_path: "scene.toml".into(),
        }
    }
}

impl Panel for ScenePanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>) {
        ui.heading("Scene");
        let current = ctx.sim.scenario().to_string();
        for s in scenarios() {
            if ui
                .selectable_label(current == s.name, &s.name)
                .on_hover_text(&s.summary)
                .clicked()
                && current != s.name
            {
                ctx.ask(Action::SetScenario(s.name.clone()));
            }
        }
        ui.add_space(4.0);
        ui.label(format!("Cloth: {}", ctx.sim.cloth_name()));
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.open_path)
                    .hint_text("cloth.obj or scene.toml")
                    .desired_width(170.0),
            );
            if ui.button("Open").clicked() && !self.open_path.trim().is_empty() {
                ctx.ask(Action::Open(self.open_path.trim().into()));
            }
        });
        ui.horizontal(|ui| {
            ui.label(RichText::new("or drop one on the window").weak());
            if ctx.status.custom_cloth && ui.small_button("Scene's cloth").clicked() {
                ctx.ask(Action::UseDefaultCloth);
            }
        });
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.save_path)
                    .hint_text("scene.toml")
                    .desired_width(170.0),
            );
            if ui
                .button("Save scene")
                .on_hover_text("the cloth, pins, solver, material and effects as they are now")
                .clicked()
                && !self.save_path.trim().is_empty()
            {
                ctx.ask(Action::SaveScene(self.save_path.trim().into()));
            }
        });
        if ui
            .button("Export OBJ")
            .on_hover_text("the cloth's current shape, into the capture folder")
            .clicked()
        {
            ctx.ask(Action::ExportObj);
        }
        let mut pins = ctx.sim.pins_enabled();
        if !ctx.sim.scenario_pins().is_empty() && ui.checkbox(&mut pins, "Pins").changed() {
            ctx.ask(Action::SetPinsEnabled(pins));
        }
        ui.separator();
    }
}
