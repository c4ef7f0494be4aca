//! The View section: what the 3D view draws, antialiasing, the camera.

use egui::RichText;

use crate::mesh::SpringKind;
use crate::render::SpringColoring;

use super::super::panel::{Action, Panel, PanelContext};

/// The View section.
#[derive(Default)]
pub struct ViewPanel;

impl Panel for ViewPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>) {
        ui.heading("View");
        let o = &mut *ctx.options;
        ui.checkbox(&mut o.mesh, "Mesh");
        ui.checkbox(&mut o.checker, "Checker");
        ui.checkbox(&mut o.wireframe, "Wireframe");
        ui.checkbox(&mut o.springs, "Springs");
        ui.add_enabled_ui(o.springs, |ui| {
            ui.horizontal(|ui| {
                ui.radio_value(&mut o.spring_coloring, SpringColoring::ByKind, "by kind");
                ui.radio_value(
                    &mut o.spring_coloring,
                    SpringColoring::ByStrain,
                    "by strain",
                );
            });
            ui.horizontal(|ui| {
                for kind in SpringKind::ALL {
                    ui.checkbox(&mut o.spring_kinds[kind.index()], kind.name());
                }
            });
        });
        ui.checkbox(&mut o.particles, "Particles");
        ui.checkbox(&mut o.colliders, "Colliders");
        let status = ctx.status;
        let mut check = status.check.0;
        let hover = "After every frame, the exact test of every pair of the cloth's triangles, \
                     and of the cloth's against each solid; the counts show in the status bar. \
                     A few milliseconds a frame, on the simulation's thread.";
        if ui
            .checkbox(&mut check, "Check intersections")
            .on_hover_text(hover)
            .changed()
        {
            ctx.ask(Action::CheckIntersections(check));
        }
        ui.horizontal(|ui| {
            ui.label("Antialiasing")
                .on_hover_text("MSAA samples per pixel: fewer draw faster on a software adapter");
            for &n in status.sample_choices {
                let label = if n == 1 {
                    "off".to_string()
                } else {
                    format!("{n}×")
                };
                if ui
                    .selectable_label(status.samples_in_use == n, label)
                    .clicked()
                {
                    ctx.ask(Action::SetSamples(n));
                }
            }
        });
        if ui
            .button("Reset view")
            .on_hover_text("or double-click the view")
            .clicked()
        {
            ctx.ask(Action::ResetCamera);
        }
        ui.label(RichText::new("drag: orbit · shift/middle-drag: pan · wheel: zoom").weak());
    }
}
