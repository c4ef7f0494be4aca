//! The pointer in the 3D view: drag the cloth to pull a particle, Ctrl-click to pin or
//! unpin one, drag elsewhere to orbit.

use glam::Vec3;

use crate::mesh::pick;

use super::cloth_app::{ClothApp, Level};
use super::viewport::camera_input;

/// A particle held by the pointer, moving in the plane through where it was grabbed that
/// faces the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grab {
    pub particle: u32,
    pub plane_point: Vec3,
    pub plane_normal: Vec3,
}

impl ClothApp {
    /// The ray through the pointer at `at` (points) in the view `rect`.
    fn pointer_ray(&self, rect: egui::Rect, at: egui::Pos2) -> (Vec3, Vec3) {
        let rel = at - rect.min;
        self.camera
            .ray(rel.x, rel.y, rect.width().max(1.0), rect.height().max(1.0))
    }

    /// The particle under the pointer: the nearest corner of the first triangle it hits.
    pub fn particle_at(&self, rect: egui::Rect, at: egui::Pos2) -> Option<(u32, Vec3)> {
        let (origin, direction) = self.pointer_ray(rect, at);
        let model = self.sim.model();
        let pos = &self.sim.state().pos;
        let hit = pick(origin, direction, pos, &model.triangles)?;
        let p = hit.nearest_corner(&model.triangles);
        Some((p, pos[p as usize]))
    }

    /// Before picking or exporting: on the GPU backend the replica's state is read back only
    /// now and then (the view draws from the GPU's buffer); bring it to the latest frame so
    /// the pointer picks, and an export writes, the cloth as it is drawn. One read-back.
    pub(super) fn catch_up(&mut self) {
        if self.in_effect().on_gpu() {
            let sent = self.stepping.catch_up();
            self.report_sent(sent);
            self.poll_stepping();
        }
    }

    pub(super) fn pointer_input(&mut self, ui: &egui::Ui, response: &egui::Response) {
        let rect = response.rect;
        let ctrl = ui.input(|i| i.modifiers.command);
        let shift = ui.input(|i| i.modifiers.shift);
        let pressed = (response.drag_started_by(egui::PointerButton::Primary) && !shift)
            || (response.clicked() && ctrl);
        if pressed {
            self.catch_up();
        }
        if response.clicked() && ctrl {
            if let Some(at) = response.interact_pointer_pos()
                && let Some((p, _)) = self.particle_at(rect, at)
            {
                self.edit(move |s| s.toggle_pin(p));
                let state = if self.sim.model().pins.contains(&p) {
                    "pinned"
                } else {
                    "freed"
                };
                self.message(Level::Info, format!("{state} particle {p}"));
            }
            return;
        }
        if response.drag_started_by(egui::PointerButton::Primary)
            && !ui.input(|i| i.modifiers.shift)
            && let Some(at) = response.interact_pointer_pos()
            && let Some((particle, point)) = self.particle_at(rect, at)
        {
            self.grab = Some(Grab {
                particle,
                plane_point: point,
                plane_normal: self.camera.forward(),
            });
        }
        match self.grab {
            Some(grab) if response.dragged_by(egui::PointerButton::Primary) => {
                if let Some(at) = response.interact_pointer_pos() {
                    let (origin, direction) = self.pointer_ray(rect, at);
                    let across = direction.dot(grab.plane_normal);
                    if across.abs() > 1e-6 {
                        let t = (grab.plane_point - origin).dot(grab.plane_normal) / across;
                        let (p, target) = (grab.particle, origin + t * direction);
                        self.edit(move |s| s.grab(p, target));
                    }
                }
            }
            Some(_) => {
                self.grab = None;
                self.edit(|s| s.release());
            }
            None => {
                if camera_input(ui, response, &mut self.camera) {
                    self.reset_camera();
                }
            }
        }
    }
}
