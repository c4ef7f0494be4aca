//! The transport bar: play, step, reset, speed, capture, accuracy, recording.

use egui::{RichText, Slider};

use super::super::panel::{Action, Panel, PanelContext};

/// The bar along the top of the window.
#[derive(Default)]
pub struct TransportBar;

impl Panel for TransportBar {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>) {
        let status = ctx.status;
        ui.horizontal(|ui| {
            let label = if status.playing { "Pause" } else { "Play" };
            if ui.button(label).on_hover_text("Space").clicked() {
                ctx.ask(Action::SetPlaying(!status.playing));
            }
            if ui
                .button("Step")
                .on_hover_text("Pause and advance one frame")
                .clicked()
            {
                ctx.ask(Action::StepOnce);
            }
            if ui.button("Reset").clicked() {
                ctx.ask(Action::Reset);
            }
            ui.separator();
            let mut speed = status.speed;
            let slider = Slider::new(&mut speed, 0.05..=4.0)
                .logarithmic(true)
                .suffix("×")
                .text("speed");
            if ui.add(slider).changed() {
                ctx.ask(Action::SetSpeed(speed));
            }
            ui.separator();
            if ui.button("Capture PNG").clicked() {
                ctx.ask(Action::Capture);
            }
            let stop_or = |on: bool, stop: &'static str, start: &'static str| {
                if on { stop } else { start }
            };
            let buttons = [
                (
                    "Accuracy",
                    "What accuracy costs: every integrator and step size on this scene",
                    Action::OpenAccuracy,
                ),
                (
                    stop_or(status.recording, "Stop recording", "Record"),
                    "every drawn frame as a numbered PNG",
                    Action::ToggleRecording,
                ),
                (
                    stop_or(status.recording_gif, "Stop GIF", "Record GIF"),
                    "what the view shows, as an animated GIF",
                    Action::ToggleGif,
                ),
            ];
            for (label, hover, action) in buttons {
                if ui.button(label).on_hover_text(hover).clicked() {
                    ctx.ask(action);
                }
            }
            if status.behind {
                ui.separator();
                ui.label(
                    RichText::new("running slower than real time")
                        .color(egui::Color32::from_rgb(230, 160, 40)),
                );
            }
        });
        if ui.input(|i| i.key_pressed(egui::Key::Space)) && !ui.ctx().egui_wants_keyboard_input() {
            ctx.ask(Action::SetPlaying(!status.playing));
        }
    }
}
