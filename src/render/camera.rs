//! Orbit camera with a perspective projection.

use glam::{Mat4, Vec3};

/// Looks at `target` from `distance` metres, at `yaw` (about +y, radians; 0 looks along −z)
/// and `pitch` (radians above the horizon).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: Vec3::new(0.0, 0.7, 0.0),
            yaw: 0.5,
            pitch: 0.35,
            distance: 2.8,
            fov_y: 45f32.to_radians(),
        }
    }
}

/// Limits that keep the view well-defined (no flip over the poles, no zero distance).
const PITCH_LIMIT: f32 = 1.5;
const MIN_DISTANCE: f32 = 0.05;
const MAX_DISTANCE: f32 = 500.0;

impl OrbitCamera {
    /// Eye position, metres.
    pub fn eye(&self) -> Vec3 {
        let dir = Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        );
        self.target + self.distance * dir
    }

    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye(), self.target, Vec3::Y)
    }

    /// Perspective projection for `aspect` = width / height (wgpu depth range 0..1).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        let near = (self.distance * 0.01).clamp(0.001, 0.1);
        Mat4::perspective_rh(self.fov_y, aspect.max(1e-3), near, near * 1.0e5)
    }

    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view()
    }

    /// Rotates by `d_yaw`, `d_pitch` radians.
    pub fn orbit(&mut self, d_yaw: f32, d_pitch: f32) {
        self.yaw = (self.yaw + d_yaw) % std::f32::consts::TAU;
        self.pitch = (self.pitch + d_pitch).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Multiplies the distance by `factor` (< 1 zooms in).
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(MIN_DISTANCE, MAX_DISTANCE);
        }
    }

    /// Moves the target in the view plane by fractions of the visible height (`dx` right,
    /// `dy` up).
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let forward = (self.target - self.eye()).normalize_or_zero();
        let right = forward.cross(Vec3::Y).normalize_or_zero();
        let up = right.cross(forward);
        let visible = 2.0 * self.distance * (0.5 * self.fov_y).tan();
        self.target += (right * dx + up * dy) * visible;
    }

    /// Frames a bounding box: looks at its centre from a distance that fits it.
    pub fn framing(lo: Vec3, hi: Vec3) -> Self {
        let fov_y = Self::default().fov_y;
        let radius = (0.5 * (hi - lo).length()).max(0.1);
        Self {
            target: 0.5 * (lo + hi),
            distance: radius / (0.5 * fov_y).sin() * 1.1,
            ..Self::default()
        }
    }

    /// Projects a world point to pixel coordinates (origin top-left) in a `width × height`
    /// image; `None` behind the camera.
    pub fn project(&self, p: Vec3, width: u32, height: u32) -> Option<(f32, f32)> {
        let clip = self.view_projection(width as f32 / height as f32) * p.extend(1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some((
            (ndc.x * 0.5 + 0.5) * width as f32,
            (0.5 - ndc.y * 0.5) * height as f32,
        ))
    }
}
