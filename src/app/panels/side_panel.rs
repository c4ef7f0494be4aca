//! The side panel: the Scene, Solver, Material, Effects and View sections, scrolled.

use super::super::panel::{Panel, PanelContext};
use super::effects::EffectsPanel;
use super::material::MaterialPanel;
use super::scene::ScenePanel;
use super::solver::SolverPanel;
use super::view::ViewPanel;

/// The sections down the left of the window, in order.
#[derive(Default)]
pub struct SidePanel {
    pub scene: ScenePanel,
    pub solver: SolverPanel,
    pub material: MaterialPanel,
    pub effects: EffectsPanel,
    pub view: ViewPanel,
}

impl Panel for SidePanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>) {
        egui::ScrollArea::vertical().show(ui, |ui| {
            let sections: [&mut dyn Panel; 5] = [
                &mut self.scene,
                &mut self.solver,
                &mut self.material,
                &mut self.effects,
                &mut self.view,
            ];
            for section in sections {
                section.ui(ui, ctx);
            }
        });
    }
}
