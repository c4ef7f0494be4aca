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
            yaw: 0.45,
            pitch: 0.6,
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

    /// Frames `points` in a view of `aspect` = width / height from the default direction:
    /// looks at the centre of their bounding box from the nearest distance at which every
    /// point falls inside the central 90 % of the picture.
    pub fn framing(points: &[Vec3], aspect: f32) -> Self {
        let d = Self::default();
        Self::framing_from(points, aspect, d.yaw, d.pitch)
    }

    /// As [`OrbitCamera::framing`], looking from `yaw` and `pitch` (radians).
    pub fn framing_from(points: &[Vec3], aspect: f32, yaw: f32, pitch: f32) -> Self {
        let (lo, hi) = points.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
        let mut camera = Self {
            target: if points.is_empty() {
                Vec3::ZERO
            } else {
                0.5 * (lo + hi)
            },
            distance: 1.0,
            yaw,
            pitch,
            ..Self::default()
        };
        let back = (camera.eye() - camera.target).normalize();
        let right = (-back).cross(Vec3::Y).normalize();
        let up = right.cross(-back);
        let tan_y = 0.9 * (0.5 * camera.fov_y).tan();
        let tan_x = tan_y * aspect.max(1e-3);
        let mut distance = MIN_DISTANCE;
        for &p in points {
            let o = p - camera.target;
            // Depth from the eye is `distance − o·back`; the point fits when its offsets
            // across the view are within the half-angles at that depth.
            let toward = o.dot(back);
            distance = distance
                .max(toward + o.dot(right).abs() / tan_x)
                .max(toward + o.dot(up).abs() / tan_y);
        }
        camera.distance = distance.clamp(MIN_DISTANCE, MAX_DISTANCE);
        camera
    }

    /// The ray through pixel `(x, y)` (origin top-left) of a `width × height` image:
    /// `(origin, unit direction)`.
    pub fn ray(&self, x: f32, y: f32, width: f32, height: f32) -> (Vec3, Vec3) {
        let inverse = self.view_projection(width / height.max(1.0)).inverse();
        let ndc_x = 2.0 * x / width.max(1.0) - 1.0;
        let ndc_y = 1.0 - 2.0 * y / height.max(1.0);
        let near = inverse.project_point3(Vec3::new(ndc_x, ndc_y, 0.0));
        let far = inverse.project_point3(Vec3::new(ndc_x, ndc_y, 1.0));
        (near, (far - near).normalize_or(-Vec3::Z))
    }

    /// Unit vector from the eye towards the target.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.eye()).normalize_or(-Vec3::Z)
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
