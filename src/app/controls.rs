//! The panels: transport bar, parameter side panel, status bar.

use egui::{RichText, Slider};

use crate::mesh::SpringKind;
use crate::render::SpringColoring;
use crate::scene::scenarios;
use crate::sim::{IntegratorKind, SimParams};

use super::cloth_app::{ClothApp, Level};

pub fn transport_bar(ui: &mut egui::Ui, app: &mut ClothApp) {
    ui.horizontal(|ui| {
        let label = if app.transport.playing {
            "Pause"
        } else {
            "Play"
        };
        if ui.button(label).on_hover_text("Space").clicked() {
            app.set_playing(!app.transport.playing);
        }
        if ui
            .button("Step")
            .on_hover_text("Pause and advance one frame")
            .clicked()
        {
            app.step_once();
        }
        if ui.button("Reset").clicked() {
            app.reset();
        }
        ui.separator();
        ui.add(
            Slider::new(&mut app.transport.speed, 0.05..=4.0)
                .logarithmic(true)
                .suffix("×")
                .text("speed"),
        );
        ui.separator();
        if ui.button("Capture PNG").clicked() {
            app.request_capture();
        }
        if ui
            .button("Accuracy")
            .on_hover_text("What accuracy costs: every integrator and step size on this scene")
            .clicked()
        {
            app.accuracy.open = true;
        }
        let record = if app.is_recording() {
            "Stop recording"
        } else {
            "Record"
        };
        if ui
            .button(record)
            .on_hover_text("every drawn frame as a numbered PNG")
            .clicked()
        {
            app.toggle_recording();
        }
        let gif = if app.is_recording_gif() {
            "Stop GIF"
        } else {
            "Record GIF"
        };
        if ui
            .button(gif)
            .on_hover_text("what the view shows, as an animated GIF")
            .clicked()
        {
            app.toggle_gif();
        }
        if app.transport.behind {
            ui.separator();
            ui.label(
                RichText::new("running slower than real time")
                    .color(egui::Color32::from_rgb(230, 160, 40)),
            );
        }
    });
    if ui.input(|i| i.key_pressed(egui::Key::Space)) && !ui.ctx().egui_wants_keyboard_input() {
        app.set_playing(!app.transport.playing);
    }
}

pub fn status_bar(ui: &mut egui::Ui, app: &mut ClothApp) {
    ui.horizontal_wrapped(|ui| {
        let (sim, model) = (&app.sim, app.sim.model());
        ui.label(format!("{:.0} fps", app.stats.fps))
            .on_hover_text(app.adapter().unwrap_or("no renderer"));
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
        let phases: Vec<String> = app
            .stats
            .phase_ms
            .iter()
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
        if app.is_loading() {
            ui.separator();
            ui.spinner();
            ui.label("loading…");
        }
    });
    // The message row is always there, so the 3D view does not jump when one appears.
    ui.horizontal(|ui| match app.messages.last().cloned() {
        Some(m) => {
            let color = match m.level {
                Level::Info => ui.visuals().text_color(),
                Level::Warning => egui::Color32::from_rgb(230, 160, 40),
                Level::Error => egui::Color32::from_rgb(240, 80, 70),
            };
            ui.label(RichText::new(&m.text).color(color));
            if ui.small_button("Dismiss").clicked() {
                app.messages.clear();
            }
        }
        None => {
            ui.add_enabled(false, egui::Button::new("Dismiss").small());
        }
    });
}

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

pub fn side_panel(ui: &mut egui::Ui, app: &mut ClothApp) {
    egui::ScrollArea::vertical().show(ui, |ui| {
        scenario_section(ui, app);
        solver_section(ui, app);
        material_section(ui, app);
        super::effects::effects_section(ui, app);
        render_section(ui, app);
    });
}

fn scenario_section(ui: &mut egui::Ui, app: &mut ClothApp) {
    ui.heading("Scene");
    let current = app.sim.scenario().to_string();
    for s in scenarios() {
        if ui
            .selectable_label(current == s.name, &s.name)
            .on_hover_text(&s.summary)
            .clicked()
            && current != s.name
        {
            app.set_scenario(&s.name);
        }
    }
    ui.add_space(4.0);
    ui.label(format!("Cloth: {}", app.cloth_name()));
    ui.horizontal(|ui| {
        ui.add(
            egui::TextEdit::singleline(&mut app.open_path)
                .hint_text("cloth.obj or scene.toml")
                .desired_width(170.0),
        );
        if ui.button("Open").clicked() && !app.open_path.trim().is_empty() {
            let path = std::path::PathBuf::from(app.open_path.trim());
            app.open_path(path);
        }
    });
    ui.horizontal(|ui| {
        ui.label(RichText::new("or drop one on the window").weak());
        if app.has_custom_cloth() && ui.small_button("Scene's cloth").clicked() {
            app.use_default_cloth();
        }
    });
    ui.horizontal(|ui| {
        ui.add(
            egui::TextEdit::singleline(&mut app.save_path)
                .hint_text("scene.toml")
                .desired_width(170.0),
        );
        if ui
            .button("Save scene")
            .on_hover_text("the cloth, pins, solver, material and effects as they are now")
            .clicked()
            && !app.save_path.trim().is_empty()
        {
            let path = std::path::PathBuf::from(app.save_path.trim());
            app.save_scene(&path);
        }
    });
    if ui
        .button("Export OBJ")
        .on_hover_text("the cloth's current shape, into the capture folder")
        .clicked()
    {
        app.export_obj();
    }
    let mut pins = app.sim.pins_enabled();
    if !app.sim.scenario_pins().is_empty() && ui.checkbox(&mut pins, "Pins").changed() {
        app.set_pins_enabled(pins);
    }
    ui.separator();
}

fn solver_section(ui: &mut egui::Ui, app: &mut ClothApp) {
    ui.heading("Solver");
    ui.horizontal(|ui| {
        ui.label("Backend");
        let on_gpu = app.in_effect().on_gpu();
        if ui.selectable_label(!on_gpu, "CPU").clicked() && on_gpu {
            app.set_backend(crate::gpu::Backend::Cpu);
        }
        if ui
            .selectable_label(on_gpu, "GPU")
            .on_hover_text(
                "wgpu compute: semi-implicit Euler, springs, gravity, air damping, pins, spheres \
                 and planes",
            )
            .clicked()
            && !on_gpu
        {
            app.set_backend(crate::gpu::Backend::Gpu);
        }
    });
    let mut params = app.sim.params().clone();
    let mut changed = false;
    for kind in IntegratorKind::ALL {
        changed |= ui
            .radio_value(&mut params.integrator, kind, kind.label())
            .changed();
    }
    egui::Grid::new("solver").num_columns(2).show(ui, |ui| {
        let label = ui.label("Time step");
        changed |= ui
            .add(
                egui::DragValue::new(&mut params.dt)
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
                .add(egui::DragValue::new(&mut params.substeps).range(1..=2000))
                .labelled_by(label.id)
                .changed();
            let effective = app.in_effect().substeps;
            if effective != params.substeps {
                ui.label(
                    RichText::new(format!("in effect: {effective}"))
                        .color(egui::Color32::from_rgb(230, 160, 40)),
                )
                .on_hover_text("the stability guard raised the substeps after a diverging frame");
            }
        });
        ui.end_row();
        ui.label("Substep");
        ui.label(format!("{:.3} ms", 1e3 * app.in_effect().substep_length));
        ui.end_row();
    });
    if changed {
        app.apply_params(params);
    }
    ui.separator();
}

/// Stiffness and damping sliders of one spring kind, labelled `{prefix}stiffness` and
/// `{prefix}damping`; whether either changed.
pub(super) fn spring_sliders(
    ui: &mut egui::Ui,
    params: &mut SimParams,
    kind: SpringKind,
    prefix: &str,
) -> bool {
    let k = kind.index();
    let stiffness = Slider::new(&mut params.stiffness[k], 0.0..=5000.0)
        .logarithmic(true)
        .suffix(" N/m")
        .text(format!("{prefix}stiffness"));
    let changed = ui.add(stiffness).changed();
    let damping = Slider::new(&mut params.damping[k], 0.0..=2.0)
        .logarithmic(true)
        .suffix(" N·s/m")
        .text(format!("{prefix}damping"));
    changed | ui.add(damping).changed()
}

fn material_section(ui: &mut egui::Ui, app: &mut ClothApp) {
    ui.heading("Material");
    let mut params = app.sim.params().clone();
    let mut changed = false;
    // Bend springs are set under Effects → Bending, where they exist.
    for kind in [SpringKind::Structural, SpringKind::Shear] {
        changed |= spring_sliders(ui, &mut params, kind, &format!("{} ", kind.name()));
    }
    let density = Slider::new(&mut params.density, 0.01..=5.0)
        .logarithmic(true)
        .suffix(" kg/m²")
        .text("density");
    changed |= ui.add(density).changed();
    let offset = Slider::new(&mut params.collision_offset, 0.0..=0.05)
        .suffix(" m")
        .text("collision thickness");
    changed |= ui
        .add(offset)
        .on_hover_text("how far particles stay from collider surfaces")
        .changed();
    if changed {
        app.apply_params(params);
    }
    ui.separator();
}

fn render_section(ui: &mut egui::Ui, app: &mut ClothApp) {
    ui.heading("View");
    let o = &mut app.options;
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
    ui.horizontal(|ui| {
        ui.label("Antialiasing")
            .on_hover_text("MSAA samples per pixel: fewer draw faster on a software adapter");
        let in_use = app.samples_in_use();
        for &n in &app.sample_choices.clone() {
            let label = if n == 1 {
                "off".to_string()
            } else {
                format!("{n}×")
            };
            if ui.selectable_label(in_use == n, label).clicked() {
                app.samples = n;
            }
        }
    });
    if ui
        .button("Reset view")
        .on_hover_text("or double-click the view")
        .clicked()
    {
        app.reset_camera();
    }
    ui.label(RichText::new("drag: orbit · shift/middle-drag: pan · wheel: zoom").weak());
}
