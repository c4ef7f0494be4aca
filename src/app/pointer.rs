//! The pointer in the 3D view: drag the cloth to pull a particle, Ctrl-click to pin or
//! unpin one, drag elsewhere to orbit.

use glam::Vec3;

use crate::mesh::pick;
use crate::render::OrbitCamera;
use crate::scene::Simulation;

use super::messages::Level;
use super::panel::Action;
use super::viewport::camera_input;

/// A particle held by the pointer, moving in the plane through where it was grabbed that
/// faces the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grab {
    pub particle: u32,
    pub plane_point: Vec3,
    pub plane_normal: Vec3,
}

/// The pointer over the 3D view, and the particle it holds.
#[derive(Debug, Default)]
pub struct Pointer {
    grab: Option<Grab>,
}

/// The ray through the pointer at `at` (points) in the view `rect` of `camera`.
fn pointer_ray(camera: &OrbitCamera, rect: egui::Rect, at: egui::Pos2) -> (Vec3, Vec3) {
    let rel = at - rect.min;
    camera.ray(rel.x, rel.y, rect.width().max(1.0), rect.height().max(1.0))
}

/// The particle of `sim` under the pointer at `at` in the view `rect`: the nearest corner of
/// the first triangle it hits, and where that particle is.
pub fn particle_at(
    camera: &OrbitCamera,
    sim: &Simulation,
    rect: egui::Rect,
    at: egui::Pos2,
) -> Option<(u32, Vec3)> {
    let (origin, direction) = pointer_ray(camera, rect, at);
    let (model, pos) = (sim.model(), &sim.state().pos);
    let hit = pick(origin, direction, pos, &model.triangles)?;
    let p = hit.nearest_corner(&model.triangles);
    Some((p, pos[p as usize]))
}

impl Pointer {
    /// Whether the pointer presses on the cloth's view this frame (a grab or a pin may
    /// follow): the app brings its copy of the state up to date first, so the pointer picks
    /// the cloth as it is drawn.
    pub fn presses(ui: &egui::Ui, response: &egui::Response) -> bool {
        let (ctrl, shift) = ui.input(|i| (i.modifiers.command, i.modifiers.shift));
        (response.drag_started_by(egui::PointerButton::Primary) && !shift)
            || (response.clicked() && ctrl)
    }

    /// Turns this frame's pointer input over the view into actions: a Ctrl-click pins or
    /// frees a particle, a drag from the cloth holds the particle under the pointer where
    /// the pointer moves it, a drag elsewhere orbits `camera`.
    pub fn input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        camera: &mut OrbitCamera,
        sim: &Simulation,
        actions: &mut Vec<Action>,
    ) {
        let rect = response.rect;
        let (ctrl, shift) = ui.input(|i| (i.modifiers.command, i.modifiers.shift));
        if response.clicked() && ctrl {
            if let Some(at) = response.interact_pointer_pos()
                && let Some((p, _)) = particle_at(camera, sim, rect, at)
            {
                let now = if sim.model().pins.contains(&p) {
                    "freed"
                } else {
                    "pinned"
                };
                actions.push(Action::TogglePin(p));
                actions.push(Action::Tell(Level::Info, format!("{now} particle {p}")));
            }
            return;
        }
        if response.drag_started_by(egui::PointerButton::Primary)
            && !shift
            && let Some(at) = response.interact_pointer_pos()
            && let Some((particle, point)) = particle_at(camera, sim, rect, at)
        {
            self.grab = Some(Grab {
                particle,
                plane_point: point,
                plane_normal: camera.forward(),
            });
        }
        match self.grab {
            Some(grab) if response.dragged_by(egui::PointerButton::Primary) => {
                if let Some(at) = response.interact_pointer_pos() {
                    let (origin, direction) = pointer_ray(camera, rect, at);
                    let across = direction.dot(grab.plane_normal);
                    if across.abs() > 1e-6 {
                        let t = (grab.plane_point - origin).dot(grab.plane_normal) / across;
                        let target = origin + t * direction;
                        actions.push(Action::Grab {
                            particle: grab.particle,
                            target,
                        });
                    }
                }
            }
            Some(_) => {
                self.grab = None;
                actions.push(Action::Release);
            }
            None => {
                if camera_input(ui, response, camera) {
                    actions.push(Action::ResetCamera);
                }
            }
        }
    }
}
