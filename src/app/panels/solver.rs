//! The Solver section: backend, integrator, time step, substeps.

use egui::RichText;

use crate::gpu::{Backend, gpu_support};
use crate::sim::{IntegratorKind, Precision};

use super::super::panel::{Action, Panel, PanelContext};

/// The Solver section.
#[derive(Default)]
pub struct SolverPanel;

impl Panel for SolverPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>) {
        ui.heading("Solver");
        let in_effect = ctx.status.in_effect;
        let mut params = ctx.sim.params().clone();
        let mut changed = false;
        ui.horizontal(|ui| {
            ui.label("Backend");
            let on_gpu = in_effect.on_gpu();
            if ui.selectable_label(!on_gpu, "CPU").clicked() && on_gpu {
                ctx.ask(Action::SetBackend(Backend::Cpu));
            }
            if ui
                .selectable_label(on_gpu, "GPU")
                .on_hover_text(
                    "wgpu compute: semi-implicit and implicit Euler, XPBD and VBD; springs, gravity, air \
                     damping, wind, dihedral bending, pins, handles, spheres and planes; rigid mesh \
                     obstacles",
                )
                .clicked()
                && !on_gpu
            {
                ctx.ask(Action::SetBackend(Backend::Gpu));
            }
            ui.separator();
            for precision in Precision::ALL {
                let chosen = params.solver.precision == precision;
                // The GPU computes in f32 only: f64 is offered on the CPU.
                let offered = precision == Precision::F32 || !on_gpu;
                let button = ui
                    .add_enabled(offered, egui::Button::selectable(chosen, precision.name()))
                    .on_hover_text(
                        "precision: what the CPU computes in. f32 is fast; f64 keeps rounding \
                         far below what the accuracy report measures (1.6–8× slower, by \
                         integrator)",
                    )
                    .on_disabled_hover_ui(|ui| {
                        // The GPU backend's own reason.
                        if let Err(why) = gpu_support(&params.step, precision, &[]) {
                            ui.label(why.to_string());
                        }
                    });
                if button.clicked() && !chosen {
                    params.solver.precision = precision;
                    changed = true;
                }
            }
        });
        for kind in IntegratorKind::ALL {
            changed |= ui
                .radio_value(&mut params.step.integrator, kind, kind.label())
                .changed();
        }
        egui::Grid::new("solver").num_columns(2).show(ui, |ui| {
            let label = ui.label("Time step");
            changed |= ui
                .add(
                    egui::DragValue::new(&mut params.step.dt)
                        .range(1e-4..=0.1)
                        .speed(1e-4)
                        .suffix(" s")
                        .max_decimals(5),
                )
                .labelled_by(label.id)
                .changed();
            ui.end_row();
            let label = ui.label("Substeps");
            ui.horizontal(|ui| {
                changed |= ui
                    .add(egui::DragValue::new(&mut params.step.substeps).range(1..=2000))
                    .labelled_by(label.id)
                    .changed();
                if in_effect.substeps != params.step.substeps {
                    ui.label(
                        RichText::new(format!("in effect: {}", in_effect.substeps))
                            .color(egui::Color32::from_rgb(230, 160, 40)),
                    )
                    .on_hover_text(
                        "the stability guard raised the substeps after a diverging frame",
                    );
                }
            });
            ui.end_row();
            let sweeps = match params.step.integrator {
                IntegratorKind::Xpbd => Some(&mut params.solver.xpbd_iterations),
                IntegratorKind::Vbd => Some(&mut params.solver.vbd_iterations),
                _ => None,
            };
            if let Some(sweeps) = sweeps {
                let label = ui.label("Sweeps");
                changed |= ui
                    .add(egui::DragValue::new(sweeps).range(1..=100))
                    .on_hover_text(
                        "iterations per substep: more move the step towards the implicit one \
                         (stiffer, less damped); more substeps of one sweep each usually buy \
                         more accuracy for the same time",
                    )
                    .labelled_by(label.id)
                    .changed();
                ui.end_row();
            }
            ui.label("Substep");
            ui.label(format!("{:.3} ms", 1e3 * in_effect.substep_length));
            ui.end_row();
        });
        if changed {
            ctx.ask(Action::ApplyParams(params));
        }
        ui.separator();
    }
}
