//! The Material section: structural and shear springs, density, collision thickness.

use egui::Slider;

use crate::mesh::SpringKind;

use super::super::panel::{Action, Panel, PanelContext};
use super::sliders::spring_sliders;

/// The Material section.
#[derive(Default)]
pub struct MaterialPanel;

impl Panel for MaterialPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>) {
        ui.heading("Material");
        let mut params = ctx.sim.params().clone();
        let mut changed = false;
        // Bend springs are set under Effects → Bending, where they exist.
        for kind in [SpringKind::Structural, SpringKind::Shear] {
            changed |= spring_sliders(ui, &mut params, kind, &format!("{} ", kind.name()));
        }
        let density = Slider::new(&mut params.material.density, 0.01..=5.0)
            .logarithmic(true)
            .suffix(" kg/m²")
            .text("density");
        changed |= ui.add(density).changed();
        let offset = Slider::new(&mut params.contact.offset, 0.0..=0.05)
            .suffix(" m")
            .text("collision thickness");
        changed |= ui
            .add(offset)
            .on_hover_text("how far particles stay from collider surfaces")
            .changed();
        if changed {
            ctx.ask(Action::ApplyParams(params));
        }
        ui.separator();
    }
}
