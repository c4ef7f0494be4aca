//! The status bar: frame rate, time, counts, energy, phases, and the latest message.

use egui::RichText;

use crate::mesh::SpringKind;

use super::super::intersection_check::intersections_text;
use super::super::messages::Level;
use super::super::panel::{Action, Panel, PanelContext};

/// The colour of an error, and of intersections found.
const ERROR: egui::Color32 = egui::Color32::from_rgb(240, 80, 70);

/// The bar along the bottom of the window.
#[derive(Default)]
pub struct StatusBar;

impl Panel for StatusBar {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>) {
        let (sim, status) = (ctx.sim, ctx.status);
        ui.horizontal_wrapped(|ui| {
            let model = sim.model();
            ui.label(format!("{:.0} fps", status.fps))
                .on_hover_text(status.adapter.unwrap_or("no renderer"));
            ui.separator();
            ui.label(format!("t = {:.2} s", sim.state().time));
            ui.separator();
            ui.label(format!(
                "{} particles · {} springs ({} bend)",
                model.particle_count(),
                model.springs.len(),
                model.springs.count(SpringKind::Bend)
            ));
            ui.separator();
            ui.label(format!("KE {:.3e} J", sim.state().kinetic_energy(model)));
            ui.separator();
            if let (true, found) = status.check {
                let text = RichText::new(intersections_text(found));
                let any = found.is_some_and(|f| f.most.total() > 0);
                let text = if any { text.color(ERROR) } else { text };
                ui.label(text).on_hover_text(
                    "After every frame: the cloth's own pairs of triangles that meet, and its \
                     triangles that meet a solid (after the last frame; the most after any \
                     since the check began or the run started)",
                );
                ui.separator();
            }
            let phases: Vec<String> = (status.phase_ms.iter())
                .map(|(n, ms)| format!("{n} {ms:.2}"))
                .collect();
            ui.label(format!(
                "ms/frame: {}",
                if phases.is_empty() {
                    "—".into()
                } else {
                    phases.join(" · ")
                }
            ));
            if status.loading {
                ui.separator();
                ui.spinner();
                ui.label("loading…");
            }
        });
        // The message row is always there, as tall as its button, so the 3D view does not
        // jump when a message appears; with none, it holds nothing to press.
        ui.horizontal(|ui| {
            ui.set_min_height(ui.spacing().interact_size.y);
            if let Some(m) = status.message {
                let color = match m.level {
                    Level::Info => ui.visuals().text_color(),
                    Level::Warning => egui::Color32::from_rgb(230, 160, 40),
                    Level::Error => ERROR,
                };
                ui.label(RichText::new(&m.text).color(color));
                if ui.small_button("Dismiss").clicked() {
                    ctx.ask(Action::DismissMessages);
                }
            }
        });
    }
}

/// Darkens the window and says what a dropped file does.
pub fn drop_hint(ui: &mut egui::Ui) {
    let rect = ui.ctx().content_rect();
    ui.painter()
        .rect_filled(rect, 0.0, egui::Color32::from_black_alpha(160));
    ui.painter().text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        "Drop an OBJ (the cloth) or a .toml (a whole scene)",
        egui::FontId::proportional(24.0),
        egui::Color32::WHITE,
    );
}
