//! A deforming obstacle: its mesh placed once per frame of an OBJ sequence (the same
//! triangles in every frame), each vertex moving in a straight line from one frame to the
//! next, and the surface refitted (not rebuilt) to wherever a substep ends.

use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use glam::Vec3;

use super::geometry::barycentric;
use super::surface::Surface;
use super::tree::Nearest;

/// The frames of a deforming obstacle and its surface at the last substep asked for.
#[derive(Debug)]
pub struct Sequence {
    /// Each frame's vertices, placed (shared by the same sequence over another surface).
    frames: Arc<[Vec<Vec3>]>,
    /// Frames per second (> 0).
    fps: f64,
    /// After the last frame: back to the first (over one frame's time) and on, or hold.
    looped: bool,
    moment: Mutex<Moment>,
}

/// The surface where one substep ends, with how far and how fast each vertex moved over it.
#[derive(Debug)]
pub struct Moment {
    start: f64,
    end: f64,
    pub surface: Surface,
    /// Each vertex's move over the substep.
    pub shift: Vec<Vec3>,
    /// The largest of them.
    pub largest_shift: f32,
    /// Each vertex's velocity, m/s.
    pub velocity: Vec<Vec3>,
}

impl Moment {
    /// `field` (one value per vertex) at `point` of triangle `triangle`.
    pub fn at(&self, triangle: u32, point: Vec3, field: &[Vec3]) -> Vec3 {
        let tri = self.surface.triangles()[triangle as usize];
        let corners = tri.map(|i| self.surface.vertices()[i as usize]);
        let w = barycentric(point, corners);
        (0..3).map(|k| field[tri[k] as usize] * w[k]).sum()
    }

    /// `field` at the point `near` found on the surface.
    pub fn at_nearest(&self, near: &Nearest, field: &[Vec3]) -> Vec3 {
        self.at(near.triangle, near.point, field)
    }

    /// The surface's velocity at the point of it nearest to `p` (zero when none is
    /// within `reach`).
    pub fn velocity_near(&self, p: Vec3, reach: f32) -> Vec3 {
        (self.surface.nearest(p, reach)).map_or(Vec3::ZERO, |n| self.at_nearest(&n, &self.velocity))
    }
}

/// When the surface something was measured against stood: what a memory of a deforming
/// surface keeps to tell how far the surface may have moved since.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceClock {
    /// The end of the substep whose surface was last measured against.
    at: Option<f64>,
}

impl SurfaceClock {
    /// How far any point of the surface may have moved since it was last measured
    /// against, now that it is `moment`'s (which it then is): nothing where it is the
    /// same surface (a second pass in one substep), the moment's largest vertex move where
    /// its substep follows (a point of a triangle or an edge moves no farther than its
    /// farthest corner), and anything after a jump (the first pass, a frame rolled back and
    /// redone, a copy of the simulation at another time).
    pub fn moved_to(&mut self, moment: &Moment) -> f32 {
        let by = match self.at {
            Some(at) if at == moment.end => 0.0,
            Some(at) if at == moment.start => moment.largest_shift,
            _ => f32::INFINITY,
        };
        self.at = Some(moment.end);
        by
    }
}

impl Sequence {
    /// `frames` (at least one, all as long as the first; `surface` is the first) shown
    /// `fps` a second.
    ///
    /// # Panics
    /// When `frames` is empty or differ in length from `surface`.
    pub fn new(surface: Surface, frames: Vec<Vec<Vec3>>, fps: f64, looped: bool) -> Self {
        Self::sharing(surface, frames.into(), fps, looped)
    }

    /// [`Sequence::new`] over frames it may share.
    fn sharing(surface: Surface, frames: Arc<[Vec<Vec3>]>, fps: f64, looped: bool) -> Self {
        assert!(
            frames.iter().all(|f| f.len() == surface.vertices().len()),
            "frames of other lengths"
        );
        let count = surface.vertices().len();
        Self {
            frames,
            fps,
            looped,
            moment: Mutex::new(Moment {
                start: 0.0,
                end: 0.0,
                surface,
                shift: vec![Vec3::ZERO; count],
                largest_shift: 0.0,
                velocity: vec![Vec3::ZERO; count],
            }),
        }
    }

    /// The same frames (shared, not copied) over `surface` (frame 0's, as
    /// [`Sequence::new`] takes it: the same vertices, its edges and tips told apart
    /// another way).
    pub fn over(&self, surface: Surface) -> Self {
        Self::sharing(surface, Arc::clone(&self.frames), self.fps, self.looped)
    }

    /// Each frame's vertices, placed.
    pub fn frames(&self) -> impl Iterator<Item = &[Vec3]> {
        self.frames.iter().map(Vec::as_slice)
    }

    pub fn len(&self) -> usize {
        self.frames.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    pub fn fps(&self) -> f64 {
        self.fps
    }

    pub fn is_looped(&self) -> bool {
        self.looped
    }

    /// The two frames time `t` lies between and how far from the first (before 0 and,
    /// unless looped, after the last frame: that frame, still).
    fn span(&self, t: f64) -> (usize, usize, f32) {
        let n = self.frames.len();
        let f = (t.max(0.0)) * self.fps;
        let f = if self.looped {
            f.rem_euclid(n as f64)
        } else {
            f.min((n - 1) as f64)
        };
        let i = (f.floor() as usize).min(n - 1);
        let j = if self.looped {
            (i + 1) % n
        } else {
            (i + 1).min(n - 1)
        };
        (i, j, (f - i as f64) as f32)
    }

    /// Every vertex where the sequence has it at time `t`, seconds.
    pub fn vertices_at(&self, t: f64) -> Vec<Vec3> {
        let mut out = vec![Vec3::ZERO; self.frames[0].len()];
        self.fill_vertices(t, &mut out);
        out
    }

    /// Every vertex's velocity at time `t` (m/s): constant between two frames.
    pub fn velocities_at(&self, t: f64) -> Vec<Vec3> {
        let mut out = vec![Vec3::ZERO; self.frames[0].len()];
        self.fill_velocities(t, &mut out);
        out
    }

    /// [`Sequence::vertices_at`] into `out`.
    fn fill_vertices(&self, t: f64, out: &mut [Vec3]) {
        let (i, j, s) = self.span(t);
        let (a, b) = (&self.frames[i], &self.frames[j]);
        for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
            *o = a.lerp(*b, s);
        }
    }

    /// [`Sequence::velocities_at`] into `out`.
    fn fill_velocities(&self, t: f64, out: &mut [Vec3]) {
        let (i, j, _) = self.span(t);
        let still = i == j || (t < 0.0);
        let (a, b) = (&self.frames[i], &self.frames[j]);
        let fps = self.fps as f32;
        for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
            *o = if still { Vec3::ZERO } else { (*b - *a) * fps };
        }
    }

    /// The lowest any vertex reaches along `up` in any frame.
    pub fn lowest(&self, up: Vec3) -> Option<f32> {
        self.frames
            .iter()
            .flatten()
            .map(|v| v.dot(up))
            .reduce(f32::min)
    }

    /// The fastest any vertex moves, m/s.
    pub fn fastest(&self) -> f32 {
        let n = self.frames.len();
        let pairs = if self.looped { n } else { n.saturating_sub(1) };
        (0..pairs)
            .flat_map(|i| {
                let (a, b) = (&self.frames[i], &self.frames[(i + 1) % n]);
                a.iter().zip(b).map(|(a, b)| a.distance(*b))
            })
            .fold(0.0f32, f32::max)
            * self.fps as f32
    }

    /// The surface where the substep from `start` to `end` ends (refitted when it is not
    /// already there), with each vertex's move over the substep and velocity.
    pub fn moment(&self, start: f64, end: f64) -> MutexGuard<'_, Moment> {
        let mut moment = self.moment.lock().unwrap_or_else(PoisonError::into_inner);
        if (moment.start, moment.end) != (start, end) {
            // In place: a substep allocates nothing (the shift holds the start meanwhile,
            // the velocity the end).
            let m = &mut *moment;
            self.fill_vertices(start, &mut m.shift);
            self.fill_vertices(end, &mut m.velocity);
            m.surface.refit(&m.velocity);
            for (shift, to) in m.shift.iter_mut().zip(&m.velocity) {
                *shift = *to - *shift;
            }
            m.largest_shift = (m.shift.iter().map(|s| s.length())).fold(0.0, f32::max);
            self.fill_velocities(end, &mut m.velocity);
            (m.start, m.end) = (start, end);
        }
        moment
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One triangle whose third corner rises 1 m a frame, at 2 frames a second.
    fn rising(looped: bool) -> Sequence {
        let frames: Vec<Vec<Vec3>> = (0..3)
            .map(|k| vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, k as f32, 1.0)])
            .collect();
        let surface = Surface::new(frames[0].clone(), vec![[0, 1, 2]]);
        Sequence::new(surface, frames, 2.0, looped)
    }

    /// Positions are interpolated linearly between frames, velocities are constant between
    /// them, and after the last frame it holds still, or loops back to the first.
    #[test]
    fn positions_and_velocities_follow_the_frames() {
        let held = rising(false);
        let at = |s: &Sequence, t| s.vertices_at(t)[2].y;
        let speed = |s: &Sequence, t| s.velocities_at(t)[2].y;
        assert_eq!(at(&held, 0.0), 0.0);
        assert!((at(&held, 0.25) - 0.5).abs() < 1e-6);
        assert!((at(&held, 0.8) - 1.6).abs() < 1e-6);
        assert_eq!(speed(&held, 0.25), 2.0);
        assert_eq!(speed(&held, 0.75), 2.0);
        assert_eq!((at(&held, 3.0), speed(&held, 3.0)), (2.0, 0.0));
        assert_eq!((at(&held, -1.0), speed(&held, -1.0)), (0.0, 0.0));
        // Looped: from the last frame back to the first over half a second, then again.
        let looped = rising(true);
        assert!((at(&looped, 1.25) - 1.0).abs() < 1e-6);
        assert_eq!(speed(&looped, 1.25), -4.0);
        assert!((at(&looped, 1.75) - 0.5).abs() < 1e-5);
        assert_eq!(looped.fastest(), 4.0);
        assert_eq!(held.fastest(), 2.0);
    }

    /// The surface of a substep is where the frames put it at the substep's end: a point
    /// above the rising corner is found nearer as it rises, with the corner's velocity.
    #[test]
    fn a_substeps_surface_is_where_its_end_is() {
        let s = rising(false);
        let p = Vec3::new(0.0, 2.0, 1.0);
        let d0 = s
            .moment(0.0, 0.0)
            .surface
            .nearest(p, 10.0)
            .unwrap()
            .distance;
        let m = s.moment(0.5, 0.75);
        let d = m.surface.nearest(p, 10.0).unwrap().distance;
        assert!(d < d0 - 0.5, "{d0} → {d}");
        assert_eq!(m.shift[2], Vec3::new(0.0, 0.5, 0.0));
        assert_eq!(m.largest_shift, 0.5);
        assert!((m.velocity_near(Vec3::new(0.0, 1.5, 1.0), 0.1) - Vec3::Y * 2.0).length() < 1e-5);
    }

    /// A memory's clock counts the surface as moved by nothing while it is the surface
    /// measured against (a second pass in the same substep), by the substep's largest
    /// vertex move where the substep follows it, and by anything after a jump: the first
    /// pass, a frame rolled back and redone, a copy of the simulation at another time.
    #[test]
    fn a_surfaces_move_is_counted_from_the_surface_measured_against() {
        let s = rising(false);
        let mut clock = SurfaceClock::default();
        let h = 0.125;
        let mut moved = |k: f64| clock.moved_to(&s.moment(k * h, (k + 1.0) * h));
        assert_eq!(moved(0.0), f32::INFINITY);
        assert_eq!(moved(0.0), 0.0);
        // The corner rises 2 m/s.
        assert_eq!(moved(1.0), 0.25);
        assert_eq!(moved(2.0), 0.25);
        // Rolled back to the frame's start, or skipped ahead.
        assert_eq!(moved(0.0), f32::INFINITY);
        assert_eq!(moved(5.0), f32::INFINITY);
    }
}
