//! The Effects panel: controls for exactly the effects the scene has, a way to remove each,
//! and a menu that adds the missing ones.

use egui::{DragValue, RichText, Slider};
use glam::Vec3;

use crate::mesh::{SpringKind, bounds};
use crate::scene::Simulation;
use crate::sim::{BendingModel, Collider, Effect, SelfCollision, SimParams, Wind, shortest_edge};

use super::super::panel::{Action, Panel, PanelContext};
use super::sliders::spring_sliders;

/// Dihedral stiffness offered when switching from bend springs, N·m.
const DEFAULT_DIHEDRAL_STIFFNESS: f32 = 2e-3;

/// What a user can add, with the label of its menu entry.
const ADDABLE: [(&str, Addable); 7] = [
    ("Gravity", Addable::Gravity),
    ("Air damping", Addable::AirDamping),
    ("Bending (springs)", Addable::Bending),
    ("Wind", Addable::Wind),
    ("Self-collision", Addable::SelfCollision),
    ("Sphere", Addable::Sphere),
    ("Ground plane", Addable::Plane),
];

#[derive(Clone, Copy, PartialEq)]
enum Addable {
    Gravity,
    AirDamping,
    Bending,
    Wind,
    SelfCollision,
    Sphere,
    Plane,
}

impl Addable {
    /// Whether the scene already has one (one of each, except spheres).
    fn present(self, effects: &[Effect]) -> bool {
        effects.iter().any(|e| {
            matches!(
                (self, e),
                (Addable::Gravity, Effect::Gravity)
                    | (Addable::AirDamping, Effect::AirDamping)
                    | (Addable::Bending, Effect::Bending(_))
                    | (Addable::Wind, Effect::Wind(_))
                    | (Addable::SelfCollision, Effect::SelfCollision(_))
                    | (Addable::Plane, Effect::Collider(Collider::Plane { .. }))
            )
        })
    }

    /// The effect with sensible settings for the cloth as it is now.
    fn create(self, sim: &Simulation) -> Effect {
        let (lo, hi) = bounds(&sim.state().pos);
        let size = (hi - lo).max_element().max(0.1);
        match self {
            Addable::Gravity => Effect::Gravity,
            Addable::AirDamping => Effect::AirDamping,
            Addable::Bending => Effect::Bending(BendingModel::Springs),
            Addable::Wind => Effect::Wind(Wind::default()),
            // Well under the shortest edge, so neighbours are not pushed apart.
            Addable::SelfCollision => Effect::SelfCollision(SelfCollision {
                thickness: (0.25 * shortest_edge(sim.model())).min(0.05),
                ..SelfCollision::default()
            }),
            // Just under the cloth's middle, so it falls onto it.
            Addable::Sphere => {
                let radius = 0.25 * size;
                let mid = 0.5 * (lo + hi);
                Effect::Collider(Collider::Sphere {
                    center: Vec3::new(mid.x, lo.y - 0.05 * size - radius, mid.z),
                    radius,
                    spin: Vec3::ZERO,
                    friction: 0.5,
                })
            }
            Addable::Plane => Effect::Collider(Collider::Plane {
                point: Vec3::new(0.0, lo.y - 0.5 * size, 0.0),
                normal: Vec3::Y,
                friction: 0.5,
            }),
        }
    }
}

/// The Effects section.
#[derive(Default)]
pub struct EffectsPanel;

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
                    ui.label(RichText::new(title(effect)).strong());
                    // The springs are the cloth itself.
                    if !matches!(effect, Effect::Springs)
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
                for (label, kind) in ADDABLE {
                    if !kind.present(&effects) && ui.selectable_label(false, label).clicked() {
                        added = Some(kind);
                    }
                }
            });
        if let Some(kind) = added {
            effects.push(kind.create(ctx.sim));
            effects_changed = true;
        }
        if params_changed {
            ctx.ask(Action::ApplyParams(params));
        }
        if effects_changed {
            ctx.ask(Action::ApplyEffects(effects));
        }
        ui.separator();
    }
}

fn title(effect: &Effect) -> &'static str {
    match effect {
        Effect::Gravity => "Gravity",
        Effect::Springs => "Springs (structural, shear)",
        Effect::AirDamping => "Air damping",
        Effect::Bending(_) => "Bending",
        Effect::Wind(_) => "Wind",
        Effect::SelfCollision(_) => "Self-collision",
        Effect::Collider(Collider::Sphere { .. }) => "Sphere",
        Effect::Collider(Collider::Plane { .. }) => "Ground plane",
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
        Effect::Gravity => {
            p |= ui
                .add(
                    Slider::new(&mut params.gravity.y, -30.0..=0.0)
                        .suffix(" m/s²")
                        .text("g"),
                )
                .changed();
        }
        Effect::Springs => {
            ui.label(RichText::new("stiffness and damping: Material").weak());
        }
        Effect::AirDamping => {
            p |= ui
                .add(
                    Slider::new(&mut params.air_damping, 0.0..=5.0)
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
        Effect::Collider(collider) => e |= collider_controls(ui, collider),
    }
    (p, e)
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

fn collider_controls(ui: &mut egui::Ui, collider: &mut Collider) -> bool {
    let mut changed = false;
    match collider {
        Collider::Sphere {
            center,
            radius,
            spin,
            friction,
        } => {
            ui.horizontal(|ui| {
                ui.label("centre");
                for c in [&mut center.x, &mut center.y, &mut center.z] {
                    changed |= ui.add(DragValue::new(c).speed(0.01).suffix(" m")).changed();
                }
            });
            // A signed rate about an axis that points up (or along +x, +z when level).
            let mut axis = spin.try_normalize().unwrap_or(Vec3::Y);
            if axis.dot(Vec3::new(1e-3, 1.0, 1e-6)) < 0.0 {
                axis = -axis;
            }
            let mut rate = spin.dot(axis);
            changed |= ui
                .add(Slider::new(radius, 0.01..=2.0).suffix(" m").text("radius"))
                .changed();
            if ui
                .add(
                    Slider::new(&mut rate, -10.0..=10.0)
                        .suffix(" rad/s")
                        .text("spin"),
                )
                .changed()
            {
                *spin = axis * rate;
                changed = true;
            }
            changed |= ui
                .add(Slider::new(friction, 0.0..=2.0).text("friction μ"))
                .changed();
        }
        Collider::Plane {
            point, friction, ..
        } => {
            changed |= ui
                .add(
                    Slider::new(&mut point.y, -5.0..=5.0)
                        .suffix(" m")
                        .text("height"),
                )
                .changed();
            changed |= ui
                .add(Slider::new(friction, 0.0..=2.0).text("friction μ"))
                .changed();
        }
    }
    changed
}
