//! Controls shared by several panels.

use egui::Slider;

use crate::mesh::SpringKind;
use crate::sim::SimParams;

/// Stiffness and damping sliders of one spring kind, labelled `{prefix}stiffness` and
/// `{prefix}damping`; whether either changed.
pub fn spring_sliders(
    ui: &mut egui::Ui,
    params: &mut SimParams,
    kind: SpringKind,
    prefix: &str,
) -> bool {
    let k = kind.index();
    let stiffness = Slider::new(&mut params.material.stiffness[k], 0.0..=5000.0)
        .logarithmic(true)
        .suffix(" N/m")
        .text(format!("{prefix}stiffness"));
    let changed = ui.add(stiffness).changed();
    let damping = Slider::new(&mut params.material.damping[k], 0.0..=2.0)
        .logarithmic(true)
        .suffix(" N·s/m")
        .text(format!("{prefix}damping"));
    changed | ui.add(damping).changed()
}
