//! The Effects panel: controls for exactly the effects the scene has, a way to remove each,
//! and a menu that adds the missing ones.

use egui::{DragValue, RichText, Slider};
use glam::Vec3;

use crate::mesh::{SpringKind, bounds};
use crate::sim::{
    BendingModel, ClothBox, DEFAULT_DIHEDRAL_STIFFNESS, Effect, Obstacle, Plane, SimParams, Sphere,
    Wind, shortest_edge,
};

use super::super::panel::{Action, Panel, PanelContext};
use super::sliders::spring_sliders;

/// The Effects section.
#[derive(Default)]
pub struct EffectsPanel {
    /// The OBJ path typed for *Add obstacle*.
    pub obstacle_path: String,
}

impl Panel for EffectsPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &mut PanelContext<'_>) {
        ui.heading("Effects");
        let mut params = ctx.sim.params().clone();
        let mut effects = ctx.sim.effects().to_vec();
        let (mut params_changed, mut effects_changed) = (false, false);
        let edge = shortest_edge(ctx.sim.model());
        let mut remove = None;
        for (i, effect) in effects.iter_mut().enumerate() {
            ui.push_id(i, |ui| {
                ui.horizontal(|ui| {
                    ui.label(RichText::new(effect.title()).strong());
                    // The springs are the cloth itself.
                    if !matches!(effect, Effect::Springs(_))
                        && ui
                            .small_button("Remove")
                            .on_hover_text("stop simulating this effect")
                            .clicked()
                    {
                        remove = Some(i);
                    }
                });
                let (p, e) = effect_controls(ui, effect, &mut params, edge);
                params_changed |= p;
                effects_changed |= e;
            });
        }
        if let Some(i) = remove {
            effects.remove(i);
            effects_changed = true;
        }
        let mut added = None;
        egui::ComboBox::from_label("Add effect")
            .selected_text("choose…")
            .show_ui(ui, |ui| {
                for kind in Effect::addable() {
                    let cloth = cloth_box(ctx);
                    let effect = (kind.make)(&cloth);
                    let present = effects.iter().any(|e| e.same_kind(&effect));
                    if (kind.many || !present) && ui.selectable_label(false, kind.title).clicked() {
                        added = Some(effect);
                    }
                }
            });
        if let Some(effect) = added {
            effects.push(effect);
            effects_changed = true;
        }
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.obstacle_path)
                    .hint_text("mesh.obj")
                    .desired_width(150.0),
            );
            let path = self.obstacle_path.trim();
            if ui
                .add_enabled(!path.is_empty(), egui::Button::new("Add obstacle"))
                .on_hover_text("read this OBJ as a mesh obstacle, placed as the file has it")
                .clicked()
            {
                ctx.ask(Action::AddObstacle(path.into()));
            }
        });
        if params_changed {
            ctx.ask(Action::ApplyParams(params));
        }
        if effects_changed {
            ctx.ask(Action::ApplyEffects(effects));
        }
        ui.separator();
    }
}

/// The cloth as the suggested settings of a new effect see it.
fn cloth_box(ctx: &PanelContext<'_>) -> ClothBox {
    let (lo, hi) = bounds(&ctx.sim.state().pos);
    ClothBox {
        lo,
        hi,
        shortest_edge: shortest_edge(ctx.sim.model()),
    }
}

/// Controls of one effect on a cloth whose shortest rest edge is `edge` metres; returns
/// whether the parameters and whether the effect changed.
fn effect_controls(
    ui: &mut egui::Ui,
    effect: &mut Effect,
    params: &mut SimParams,
    edge: f32,
) -> (bool, bool) {
    let (mut p, mut e) = (false, false);
    match effect {
        Effect::Gravity(g) => {
            e |= ui
                .add(
                    Slider::new(&mut g.acceleration.y, -30.0..=0.0)
                        .suffix(" m/s²")
                        .text("g"),
                )
                .changed();
        }
        Effect::Springs(_) => {
            ui.label(RichText::new("stiffness and damping: Material").weak());
        }
        Effect::AirDamping(a) => {
            e |= ui
                .add(
                    Slider::new(&mut a.rate, 0.0..=5.0)
                        .suffix(" 1/s")
                        .text("rate"),
                )
                .changed();
        }
        Effect::Bending(model) => {
            let mut dihedral = matches!(model, BendingModel::Dihedral { .. });
            ui.horizontal(|ui| {
                e |= ui.radio_value(&mut dihedral, false, "springs").changed();
                e |= ui.radio_value(&mut dihedral, true, "dihedral").changed();
            });
            if e {
                *model = if dihedral {
                    BendingModel::Dihedral {
                        stiffness: DEFAULT_DIHEDRAL_STIFFNESS,
                    }
                } else {
                    BendingModel::Springs
                };
            }
            match model {
                BendingModel::Springs => {
                    p |= spring_sliders(ui, params, SpringKind::Bend, "");
                }
                BendingModel::Dihedral { stiffness } => {
                    e |= ui
                        .add(
                            Slider::new(stiffness, 1e-5..=1.0)
                                .logarithmic(true)
                                .suffix(" N·m")
                                .text("stiffness"),
                        )
                        .changed();
                }
            }
        }
        Effect::Wind(wind) => e |= wind_controls(ui, wind),
        Effect::SelfCollision(s) => {
            e |= ui
                .add(
                    // Below the shortest edge: a thicker cloth is refused.
                    Slider::new(&mut s.thickness, 1e-4..=(0.95 * edge).clamp(2e-4, 0.1))
                        .logarithmic(true)
                        .suffix(" m")
                        .text("thickness"),
                )
                .changed();
            e |= ui
                .add(Slider::new(&mut s.friction, 0.0..=2.0).text("friction μ"))
                .changed();
        }
        Effect::Sphere(sphere) => e |= sphere_controls(ui, sphere),
        Effect::Plane(plane) => e |= plane_controls(ui, plane),
        Effect::Obstacle(obstacle) => e |= obstacle_controls(ui, obstacle),
        Effect::Handle(handle) => {
            let until = handle.motion.end();
            ui.label(
                RichText::new(format!(
                    "{} particles, moving until {until} s (Pins frees them)",
                    handle.particles.len()
                ))
                .weak(),
            );
        }
    }
    (p, e)
}

fn obstacle_controls(ui: &mut egui::Ui, obstacle: &mut Obstacle) -> bool {
    let triangles = obstacle.placed().map_or(0, |p| p.surface.triangles().len());
    ui.label(RichText::new(format!("{} ({triangles} triangles)", obstacle.source())).weak());
    let mut changed = ui
        .add(Slider::new(&mut obstacle.friction, 0.0..=2.0).text("friction μ"))
        .changed();
    let mut own = obstacle.thickness.is_some();
    if ui
        .checkbox(&mut own, "own thickness")
        .on_hover_text("off: the solver's collision offset")
        .changed()
    {
        obstacle.thickness = own.then_some(0.01);
        changed = true;
    }
    if let Some(thickness) = &mut obstacle.thickness {
        changed |= ui
            .add(
                Slider::new(thickness, 1e-4..=0.1)
                    .logarithmic(true)
                    .suffix(" m")
                    .text("thickness"),
            )
            .changed();
    }
    changed
}

fn wind_controls(ui: &mut egui::Ui, wind: &mut Wind) -> bool {
    let mut changed = false;
    // Speed and heading in the horizontal plane (0° blows along +x).
    let horizontal = Vec3::new(wind.velocity.x, 0.0, wind.velocity.z);
    let mut speed = horizontal.length();
    let mut heading = wind.velocity.z.atan2(wind.velocity.x).to_degrees();
    let mut steer = false;
    steer |= ui
        .add(
            Slider::new(&mut speed, 0.0..=30.0)
                .suffix(" m/s")
                .text("speed"),
        )
        .changed();
    steer |= ui
        .add(
            Slider::new(&mut heading, -180.0..=180.0)
                .suffix("°")
                .text("heading"),
        )
        .changed();
    if steer {
        let (sin, cos) = heading.to_radians().sin_cos();
        wind.velocity = Vec3::new(speed * cos, wind.velocity.y, speed * sin);
        changed = true;
    }
    changed |= ui
        .add(Slider::new(&mut wind.gust, 0.0..=1.0).text("gusts"))
        .changed();
    changed |= ui
        .add(
            Slider::new(&mut wind.gust_period, 0.1..=10.0)
                .logarithmic(true)
                .suffix(" s")
                .text("gust period"),
        )
        .changed();
    ui.horizontal(|ui| {
        ui.label("drag");
        changed |= ui
            .add(DragValue::new(&mut wind.drag).range(0.0..=5.0).speed(0.01))
            .changed();
        ui.label("lift");
        changed |= ui
            .add(DragValue::new(&mut wind.lift).range(0.0..=5.0).speed(0.01))
            .changed();
    });
    changed
}

fn sphere_controls(ui: &mut egui::Ui, sphere: &mut Sphere) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label("centre");
        let c = &mut sphere.center;
        for c in [&mut c.x, &mut c.y, &mut c.z] {
            changed |= ui.add(DragValue::new(c).speed(0.01).suffix(" m")).changed();
        }
    });
    // A signed rate about an axis that points up (or along +x, +z when level).
    let mut axis = sphere.spin.try_normalize().unwrap_or(Vec3::Y);
    if axis.dot(Vec3::new(1e-3, 1.0, 1e-6)) < 0.0 {
        axis = -axis;
    }
    let mut rate = sphere.spin.dot(axis);
    changed |= ui
        .add(
            Slider::new(&mut sphere.radius, 0.01..=2.0)
                .suffix(" m")
                .text("radius"),
        )
        .changed();
    if ui
        .add(
            Slider::new(&mut rate, -10.0..=10.0)
                .suffix(" rad/s")
                .text("spin"),
        )
        .changed()
    {
        sphere.spin = axis * rate;
        changed = true;
    }
    changed
        | ui.add(Slider::new(&mut sphere.friction, 0.0..=2.0).text("friction μ"))
            .changed()
}

fn plane_controls(ui: &mut egui::Ui, plane: &mut Plane) -> bool {
    let height = ui
        .add(
            Slider::new(&mut plane.point.y, -5.0..=5.0)
                .suffix(" m")
                .text("height"),
        )
        .changed();
    height
        | ui.add(Slider::new(&mut plane.friction, 0.0..=2.0).text("friction μ"))
            .changed()
}
