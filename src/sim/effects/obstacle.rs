//! An obstacle of any shape: a triangle mesh from an OBJ file, placed (scale, then rotate,
//! then translate, about the OBJ's own origin) and optionally moved through keyframes; or
//! an animated mesh, one OBJ per frame, placed the same way. The cloth may not pass it;
//! the cloth does not push it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Quat, Vec3};

use super::effect_kind::{ClothBox, ContactPass, EffectKind, GuardShare};
use super::solid::{Solid, default_friction, resolve_remembering};
use crate::cloth::ClothState;
use crate::mesh::{ObjError, PolygonSoup, parse_obj, read_obj};
use crate::sim::motion::{AxisAngle, Keyframe, Pose, RigidMotion};
use crate::sim::obstacle::{Fitted, Gathered, Moment, Sequence, Surface, SurfaceClock};
use crate::sim::param_error::ParamError;
use crate::sim::self_contacts::ContactError;

use self::edge_pass::{EdgeFrame, EdgeMemory, EdgesMoved, push_edges};
use self::tip_pass::push_tips;

mod edge_pass;
mod reach;
mod tip_pass;

/// A mesh obstacle as a scene file gives it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// The OBJ file (relative to the scene file); metres. Empty when `frames` gives the
    /// mesh.
    #[serde(default, skip_serializing_if = "is_empty_path")]
    pub obj: PathBuf,
    /// An animated mesh instead of `obj`: one OBJ per frame (relative to the scene file),
    /// `%d` or `%04d` standing for the frame's number from 0; as many frames as are found,
    /// all with frame 0's triangles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames: Option<String>,
    /// Frames a second of `frames` (default 30).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fps: Option<f32>,
    /// After the last of `frames`, on to frame 0 (over one frame's time) and round again;
    /// otherwise the last frame holds.
    #[serde(default, rename = "loop", skip_serializing_if = "std::ops::Not::not")]
    pub looped: bool,
    /// Uniform scale, first (default 1).
    #[serde(default = "unit_scale")]
    pub scale: f32,
    /// Then a rotation about the OBJ's origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate: Option<AxisAngle>,
    /// Then a translation, metres.
    #[serde(default)]
    pub translate: Vec3,
    /// Coulomb friction against the cloth (dimensionless, default 0.5).
    #[serde(default = "default_friction")]
    pub friction: f32,
    /// How far the cloth is kept from its surface, metres (default: the solver's
    /// `collision_offset`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f32>,
    /// Motion on top of the placement: rotations about the placed origin (`translate`),
    /// translations added.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub keyframes: Vec<Keyframe>,
    /// The mesh as read and placed ([`Obstacle::load`]); not part of the file.
    #[serde(skip)]
    pub shape: Shape,
}

fn unit_scale() -> f32 {
    1.0
}

fn is_empty_path(path: &Path) -> bool {
    path.as_os_str().is_empty()
}

/// Frames a second of an OBJ sequence that gives none.
pub const DEFAULT_FPS: f32 = 30.0;

/// The most frames an OBJ sequence may have.
const MAX_FRAMES: usize = 100_000;

/// The file of frame `k` of a sequence named by `pattern` (`%d`, or `%0Nd` for N digits),
/// or `None` when the pattern has no such place.
pub fn frame_path(pattern: &str, k: usize) -> Option<String> {
    let at = pattern.find('%')?;
    let rest = &pattern[at + 1..];
    let digits = rest.find('d')?;
    let width = &rest[..digits];
    if !width.chars().all(|c| c.is_ascii_digit()) || (width.len() > 1 && !width.starts_with('0')) {
        return None;
    }
    let width: usize = if width.is_empty() {
        0
    } else {
        width.parse().ok()?
    };
    Some(format!(
        "{}{k:0width$}{}",
        &pattern[..at],
        &rest[digits + 1..]
    ))
}

/// An obstacle's mesh once read: its surface as placed (in the obstacle's own frame, which
/// its motion then moves) and its motion.
#[derive(Clone, Debug, Default)]
pub struct Shape(Option<Arc<Placed>>);

/// Two shapes are the same when they are the same reading of a file.
impl PartialEq for Shape {
    fn eq(&self, other: &Self) -> bool {
        match (&self.0, &other.0) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        }
    }
}

/// The placed surface and its motion about `pivot`; for an OBJ sequence, the surface is
/// frame 0 and `sequence` the frames (its motion then is none).
#[derive(Debug)]
pub struct Placed {
    pub surface: Surface,
    pub motion: RigidMotion,
    pub pivot: Vec3,
    pub sequence: Option<Sequence>,
    /// What each particle's last contact gathered, in the obstacle's frame, and (for a
    /// sequence, whose surface changes every substep) when the surface it was gathered
    /// from stood.
    memory: std::sync::Mutex<(Vec<Gathered>, SurfaceClock)>,
    /// What its edge pass keeps from one substep to the next.
    edge_memory: std::sync::Mutex<EdgeMemory>,
    /// What fitting it to a cloth measured and gave last ([`Obstacle::reaching`]).
    reached: std::sync::Mutex<Fitted<Placed>>,
}

impl Placed {
    /// `f` with each particle's memory of its last contact (`particles` of them), made less
    /// by how far a sequence's surface moved since where `moment` is its surface now
    /// ([`Gathered::surface_moved`]), or (where another stepping copy of the simulation
    /// holds it now) with none: the memory only saves walks of the tree, the result is the
    /// same.
    fn with_memory<T>(
        &self,
        particles: usize,
        moment: Option<&Moment>,
        f: impl FnOnce(Option<&mut [Gathered]>) -> T,
    ) -> T {
        let mut memory = self.memory.try_lock().ok();
        f(memory.as_deref_mut().map(|(gathered, clock)| {
            gathered.resize(particles, Gathered::NONE);
            if let Some(moment) = moment {
                let by = clock.moved_to(moment);
                if by > 0.0 {
                    gathered.iter_mut().for_each(|g| g.surface_moved(by));
                }
            }
            &mut gathered[..]
        }))
    }

    /// `f` with the edge pass's memory, or (where another stepping copy of the simulation
    /// holds it now) with a fresh one: the memory only saves work, the result is the same.
    fn with_edge_memory<T>(&self, f: impl FnOnce(&mut EdgeMemory) -> T) -> T {
        match self.edge_memory.try_lock() {
            Ok(mut memory) => f(&mut memory),
            Err(_) => f(&mut EdgeMemory::default()),
        }
    }

    /// Its vertices at simulated time `time`, in the obstacle's frame (for a sequence, in
    /// the world), and whether they change from frame to frame.
    pub fn vertices_at(&self, time: f64) -> (std::borrow::Cow<'_, [Vec3]>, bool) {
        match &self.sequence {
            Some(seq) => (seq.vertices_at(time).into(), true),
            None => (self.surface.vertices().into(), false),
        }
    }

    /// Its vertices at simulated time `time` in the world: moved by its motion about the
    /// pivot, or a sequence's frame as it is.
    pub fn world_vertices(&self, time: f64) -> Vec<Vec3> {
        let (vertices, _) = self.vertices_at(time);
        match &self.sequence {
            Some(_) => vertices.into_owned(),
            None => {
                let pose = self.motion.at(time);
                (vertices.iter())
                    .map(|&v| pose.apply(self.pivot, v))
                    .collect()
            }
        }
    }
}

/// An obstacle whose mesh could not be read or placed.
#[derive(Debug, thiserror::Error)]
pub enum ObstacleError {
    #[error(transparent)]
    Obj(#[from] ObjError),
    #[error("{path}: {error}")]
    Setting { path: PathBuf, error: ParamError },
}

impl Obstacle {
    /// An obstacle of `obj` as it stands, with the default friction and no motion.
    pub fn new(obj: impl Into<PathBuf>) -> Self {
        Self {
            obj: obj.into(),
            scale: 1.0,
            rotate: None,
            translate: Vec3::ZERO,
            friction: default_friction(),
            thickness: None,
            keyframes: Vec::new(),
            frames: None,
            fps: None,
            looped: false,
            shape: Shape::default(),
        }
    }

    /// An obstacle of the OBJ sequence `pattern` (see [`Obstacle::frames`]) at `fps`.
    pub fn sequence(pattern: impl Into<String>, fps: f32, looped: bool) -> Self {
        Self {
            frames: Some(pattern.into()),
            fps: Some(fps),
            looped,
            ..Self::new(PathBuf::new())
        }
    }

    /// What it is read from: its OBJ, or its sequence's pattern.
    pub fn source(&self) -> String {
        match &self.frames {
            Some(pattern) => pattern.clone(),
            None => self.obj.display().to_string(),
        }
    }

    /// Whether its mesh has been read.
    pub fn is_loaded(&self) -> bool {
        self.shape.0.is_some()
    }

    /// Its mesh as placed and its motion, once read.
    pub fn placed(&self) -> Option<&Placed> {
        self.shape.0.as_deref()
    }

    /// Reads its OBJ, or every frame of its sequence (`base` is where a relative path
    /// starts), and places it.
    ///
    /// # Errors
    /// The OBJ's [`ObjError`] (naming its file and line), or [`ObstacleError::Setting`] for a
    /// placement or motion that [`EffectKind::check`] refuses, a sequence with no frame 0
    /// or whose frames differ in their triangles.
    pub fn load(&mut self, base: Option<&Path>) -> Result<(), ObstacleError> {
        self.load_with(base, &|_| None)
    }

    /// As [`Obstacle::load`], taking the text of a file from `builtin` where it has it
    /// (the program's own meshes, by the name a built-in scene gives them).
    ///
    /// # Errors
    /// As [`Obstacle::load`].
    pub fn load_with(
        &mut self,
        base: Option<&Path>,
        builtin: &dyn Fn(&Path) -> Option<&'static str>,
    ) -> Result<(), ObstacleError> {
        let at = |name: &Path| base.map_or_else(|| name.to_path_buf(), |b| b.join(name));
        let read = |name: &Path| -> Option<Result<PolygonSoup, ObjError>> {
            if let Some(text) = builtin(name) {
                return Some(parse_obj(text, name));
            }
            let path = at(name);
            path.is_file().then(|| read_obj(&path))
        };
        let first_path = at(Path::new(&self.source()));
        let setting = |path: &Path, error| ObstacleError::Setting {
            path: path.to_path_buf(),
            error,
        };
        self.check().map_err(|e| setting(&first_path, e))?;
        let Some(pattern) = self.frames.clone() else {
            let soup = match read(&self.obj) {
                Some(soup) => soup?,
                None => read_obj(&first_path)?,
            };
            return self.place(&soup, &first_path, Vec::new());
        };
        // Frame 0 as read (its triangles are every frame's), and every frame placed.
        let mut first: Option<(PolygonSoup, PathBuf)> = None;
        let mut frames = Vec::new();
        for k in 0..MAX_FRAMES {
            let Some(name) = frame_path(&pattern, k) else {
                break;
            };
            let Some(soup) = read(Path::new(&name)) else {
                break;
            };
            let soup = soup?.triangulated();
            frames.push(self.placed_positions(&soup));
            match &first {
                None => first = Some((soup, at(Path::new(&name)))),
                Some((first, path))
                    if soup.face_indices != first.face_indices
                        || soup.positions.len() != first.positions.len() =>
                {
                    let error = ParamError::new(
                        "frames",
                        &pattern,
                        format!(
                            "frame {k} ({}) has other triangles than frame 0 ({}): every frame \
                             needs the same",
                            at(Path::new(&name)).display(),
                            path.display()
                        ),
                    );
                    return Err(setting(path, error));
                }
                Some(_) => {}
            }
        }
        let Some((soup, path)) = first else {
            let name = frame_path(&pattern, 0).unwrap_or_default();
            let error = ParamError::new(
                "frames",
                &pattern,
                format!(
                    "has no frame 0 ({} not found)",
                    at(Path::new(&name)).display()
                ),
            );
            return Err(setting(&first_path, error));
        };
        self.place(&soup, &path, frames)
    }

    /// Places `soup` (a mesh made in code, named by [`Obstacle::obj`]) as the obstacle says,
    /// as [`Obstacle::load`] places a file's.
    ///
    /// # Errors
    /// As [`Obstacle::load`].
    pub fn load_mesh(&mut self, soup: &PolygonSoup) -> Result<(), ObstacleError> {
        let path = self.obj.clone();
        self.check().map_err(|error| ObstacleError::Setting {
            path: path.clone(),
            error,
        })?;
        self.place(soup, &path, Vec::new())
    }

    /// Places `soup` (read from `path`) as the obstacle says; `frames`, when not empty, are
    /// every frame of a sequence, placed.
    fn place(
        &mut self,
        soup: &PolygonSoup,
        path: &Path,
        frames: Vec<Vec<Vec3>>,
    ) -> Result<(), ObstacleError> {
        let setting = |error| ObstacleError::Setting {
            path: path.to_path_buf(),
            error,
        };
        let soup = soup.triangulated();
        let vertices = self.placed_positions(&soup);
        let triangles = (soup.face_indices.chunks_exact(3))
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let motion = RigidMotion::new(&self.keyframes)
            .map_err(|e| setting(ParamError::new("keyframes", e.index, e.to_string())))?;
        let surface = match frames.is_empty() {
            true => Surface::new(vertices, triangles),
            false => Surface::of_frames(vertices, triangles, &frames),
        };
        let fps = f64::from(self.fps.unwrap_or(DEFAULT_FPS));
        let sequence =
            (!frames.is_empty()).then(|| Sequence::new(surface.clone(), frames, fps, self.looped));
        self.shape = Shape(Some(Arc::new(Placed {
            surface,
            motion,
            pivot: self.translate,
            sequence,
            memory: std::sync::Mutex::new((Vec::new(), SurfaceClock::default())),
            edge_memory: std::sync::Mutex::new(EdgeMemory::default()),
            reached: Default::default(),
        })));
        Ok(())
    }

    /// The positions of `soup` placed: scaled, rotated, translated.
    fn placed_positions(&self, soup: &PolygonSoup) -> Vec<Vec3> {
        let rotation = self.rotation();
        (soup.positions.iter())
            .map(|&p| rotation * (p * self.scale) + self.translate)
            .collect()
    }

    /// The placement's rotation.
    fn rotation(&self) -> Quat {
        self.rotate.map_or(Quat::IDENTITY, |r| {
            Quat::from_axis_angle(r.axis.normalize_or(Vec3::Y), r.degrees.to_radians())
        })
    }
}

/// The obstacle over one substep: where its motion has it at the substep's start and end.
struct Posed<'a> {
    placed: &'a Placed,
    start: Pose,
    end: Pose,
    friction: f32,
}

impl Posed<'_> {
    /// [`push_edges`] against the obstacle's sharp edges where the substep ends (fixed in
    /// its frame), then [`push_tips`].
    fn push_edges(&self, pass: &mut ContactPass<'_>, memory: &mut EdgeMemory) -> usize {
        let (pivot, start, end) = (self.placed.pivot, self.start, self.end);
        let frame = EdgeFrame {
            from_start: |p| start.unapply(pivot, p),
            to_local: |p| end.unapply(pivot, p),
            to_world: |n| end.rotation * n,
            velocity: |q| end.velocity_at(pivot, end.apply(pivot, q)),
        };
        let (surface, mu) = (&self.placed.surface, self.friction);
        let edges = (surface.sharp_edges(), surface.tips());
        push_edges(edges, &frame, mu, pass, (memory, EdgesMoved::Fixed))
            + push_tips(surface.tips(), &frame, mu, pass, memory)
    }
}

/// A deforming obstacle (an OBJ sequence) over one substep: its surface where the substep
/// ends, with each vertex's move over it.
struct Deforming<'a> {
    moment: &'a Moment,
    friction: f32,
}

impl Deforming<'_> {
    /// [`push_edges`] against its sharp edges where the substep ends (which move), then
    /// [`push_tips`].
    fn push_edges(&self, pass: &mut ContactPass<'_>, memory: &mut EdgeMemory) -> usize {
        let reach = pass.offset;
        // (Its edges are taken where the substep ends for the whole substep.)
        let frame = EdgeFrame {
            from_start: |p| p,
            to_local: |p| p,
            to_world: |n| n,
            velocity: |q| self.moment.velocity_near(q, reach),
        };
        let surface = &self.moment.surface;
        let (edges, tips) = (surface.sharp_edges(), surface.tips());
        let moved = EdgesMoved::By(memory.clock.moved_to(self.moment));
        push_edges((edges, tips), &frame, self.friction, pass, (memory, moved))
            + push_tips(tips, &frame, self.friction, pass, memory)
    }
}

/// Particles from which a mesh obstacle's contacts are shared out between the team's
/// members ([`Solid::SHARED_FROM`]): each particle near it walks the tree, some 300
/// instructions a particle on average where `tablecloth` drapes, against a hand-over of
/// the team's of a few microseconds.
const SHARED_FROM: usize = 512;

impl Solid for Deforming<'_> {
    const SHARED_FROM: usize = SHARED_FROM;

    fn surface_at(&self, p: Vec3) -> (f32, Vec3, Vec3) {
        match self.moment.surface.nearest(p, f32::INFINITY) {
            Some(near) => {
                let away = (p - near.point).normalize_or(Vec3::Y);
                let velocity = self.moment.at_nearest(&near, &self.moment.velocity);
                (near.distance, away, velocity)
            }
            None => (f32::INFINITY, Vec3::Y, Vec3::ZERO),
        }
    }

    fn catch(&self, from: Vec3, to: Vec3, offset: f32) -> Option<Vec3> {
        self.contact(from, to, offset, None).map(|(at, _, _)| at)
    }

    /// The move as [`Deforming::contact`] sees it, where the surface moved too little in
    /// the substep to carry a start (else none is told clear here).
    #[inline]
    fn clear_remembered(&self, from: Vec3, to: Vec3, offset: f32, memory: &Gathered) -> bool {
        self.moment.largest_shift < 0.5 * offset && Surface::clears(from, to, offset, memory)
    }

    /// The move seen from the surface: a start near it is carried by the surface's own
    /// move over the substep (so a particle resting on it stays on its side however the
    /// surface moves), then caught against the surface where the substep ends. A surface
    /// that moves less than half the thickness in the substep carries nothing: what rests
    /// on it is still outside it, and pushed back out to the thickness.
    /// `memory`: what the particle's last contact gathered, made less by the surface's move
    /// since ([`Placed::with_memory`]).
    fn contact(
        &self,
        from: Vec3,
        to: Vec3,
        offset: f32,
        memory: Option<&mut Gathered>,
    ) -> Option<(Vec3, Vec3, Vec3)> {
        let m = self.moment;
        let start = if m.largest_shift >= 0.5 * offset {
            let reach = 2.0 * (offset + m.largest_shift);
            (m.surface.nearest(from, reach))
                .map_or(from, |near| from + m.at_nearest(&near, &m.shift))
        } else {
            from
        };
        let caught = m.surface.catch_remembering(start, to, offset, memory)?;
        let velocity = m.at(caught.triangle, caught.on_surface, &m.velocity);
        Some((caught.at, caught.normal, velocity))
    }

    fn friction(&self) -> f32 {
        self.friction
    }
}

impl Solid for Posed<'_> {
    const SHARED_FROM: usize = SHARED_FROM;

    fn surface_at(&self, p: Vec3) -> (f32, Vec3, Vec3) {
        let pivot = self.placed.pivot;
        let local = self.end.unapply(pivot, p);
        let velocity = self.end.velocity_at(pivot, p);
        match self.placed.surface.nearest(local, f32::INFINITY) {
            Some(near) => {
                let away = (local - near.point).normalize_or(Vec3::Y);
                (near.distance, self.end.rotation * away, velocity)
            }
            None => (f32::INFINITY, Vec3::Y, velocity),
        }
    }

    fn catch(&self, from: Vec3, to: Vec3, offset: f32) -> Option<Vec3> {
        self.contact(from, to, offset, None).map(|(at, _, _)| at)
    }

    /// The move seen from the obstacle, as [`Posed::contact`] sees it.
    #[inline]
    fn clear_remembered(&self, from: Vec3, to: Vec3, offset: f32, memory: &Gathered) -> bool {
        let pivot = self.placed.pivot;
        let (a, b) = (self.start.unapply(pivot, from), self.end.unapply(pivot, to));
        Surface::clears(a, b, offset, memory)
    }

    /// The move seen from the obstacle (start and end each in its frame at that time), so
    /// a moving obstacle sweeps particles along as a still one stops them.
    fn contact(
        &self,
        from: Vec3,
        to: Vec3,
        offset: f32,
        memory: Option<&mut Gathered>,
    ) -> Option<(Vec3, Vec3, Vec3)> {
        let pivot = self.placed.pivot;
        let (a, b) = (self.start.unapply(pivot, from), self.end.unapply(pivot, to));
        let caught = (self.placed.surface).catch_remembering(a, b, offset, memory)?;
        let at = self.end.apply(pivot, caught.at);
        let normal = self.end.rotation * caught.normal;
        Some((at, normal, self.end.velocity_at(pivot, at)))
    }

    fn friction(&self) -> f32 {
        self.friction
    }
}

impl EffectKind for Obstacle {
    const NAME: &'static str = "obstacle";
    const TITLE: &'static str = "Obstacle (mesh)";
    const MANY: bool = true;
    const ADDABLE: bool = false;

    fn check(&self) -> Result<(), ParamError> {
        match &self.frames {
            None => ParamError::require(
                !is_empty_path(&self.obj),
                "obj",
                "\"\"",
                "needs an OBJ file (or frames, an OBJ sequence)",
            )?,
            Some(pattern) => {
                ParamError::require(
                    is_empty_path(&self.obj),
                    "frames",
                    pattern,
                    "give either obj or frames, not both",
                )?;
                ParamError::require(
                    self.keyframes.is_empty(),
                    "frames",
                    pattern,
                    "give either keyframes or frames, not both",
                )?;
                ParamError::require(
                    frame_path(pattern, 0).is_some(),
                    "frames",
                    pattern,
                    "needs %d (or %04d, for four digits) where the frame number goes",
                )?;
            }
        }
        if let Some(fps) = self.fps {
            ParamError::require(fps.is_finite() && fps > 0.0, "fps", fps, "must be > 0")?;
            ParamError::require(self.frames.is_some(), "fps", fps, "is for frames only")?;
        }
        ParamError::require(
            !self.looped || self.frames.is_some(),
            "loop",
            self.looped,
            "is for frames only",
        )?;
        ParamError::require(
            self.scale.is_finite() && self.scale > 0.0,
            "scale",
            self.scale,
            "must be > 0",
        )?;
        if let Some(r) = self.rotate {
            ParamError::require(
                r.axis.is_finite() && r.axis.length_squared() > 0.0 && r.degrees.is_finite(),
                "rotate",
                format!("{} about {}", r.degrees, r.axis),
                "needs a finite angle about a non-zero axis",
            )?;
        }
        ParamError::require(
            self.translate.is_finite(),
            "translate",
            self.translate,
            "must be finite metres",
        )?;
        ParamError::require(
            self.friction.is_finite() && self.friction >= 0.0,
            "friction",
            self.friction,
            "must be ≥ 0",
        )?;
        if let Some(t) = self.thickness {
            ParamError::require(t.is_finite() && t >= 0.0, "thickness", t, "must be ≥ 0 m")?;
        }
        RigidMotion::new(&self.keyframes)
            .map(|_| ())
            .map_err(|e| ParamError::new("keyframes", e.index, e.to_string()))
    }

    fn is_contact(&self) -> bool {
        true
    }

    fn resolve(&self, pass: &mut ContactPass<'_>) -> Result<usize, ContactError> {
        let Some(placed) = self.placed() else {
            return Ok(0);
        };
        let end = pass.state.time;
        let offset = pass.offset;
        if let Some(thickness) = self.thickness {
            pass.offset = thickness;
        }
        if let Some(sequence) = &placed.sequence {
            let moment = sequence.moment(end - pass.substep as f64, end);
            let deforming = Deforming {
                moment: &moment,
                friction: self.friction,
            };
            let particles = pass.state.pos.len();
            let moved = placed.with_memory(particles, Some(&moment), |m| {
                resolve_remembering(&deforming, pass, m)
            });
            let moved = moved + placed.with_edge_memory(|m| deforming.push_edges(pass, m));
            pass.offset = offset;
            return Ok(moved);
        }
        let posed = Posed {
            placed,
            start: placed.motion.at(end - pass.substep as f64),
            end: placed.motion.at(end),
            friction: self.friction,
        };
        let particles = pass.state.pos.len();
        let moved = placed.with_memory(particles, None, |m| resolve_remembering(&posed, pass, m));
        let moved = moved + placed.with_edge_memory(|m| posed.push_edges(pass, m));
        pass.offset = offset;
        Ok(moved)
    }

    fn is_solid(&self) -> bool {
        self.placed().is_some()
    }

    /// Where the obstacle is at `t`: posed by its keyframes, or its sequence's surface
    /// then.
    fn surface(&self, p: Vec3, t: f64) -> Option<(f32, Vec3, Vec3)> {
        let placed = self.placed()?;
        if let Some(sequence) = &placed.sequence {
            let moment = sequence.moment(t, t);
            let then = Deforming {
                moment: &moment,
                friction: self.friction,
            };
            return Some(then.surface_at(p));
        }
        let pose = placed.motion.at(t);
        let then = Posed {
            placed,
            start: pose,
            end: pose,
            friction: self.friction,
        };
        Some(then.surface_at(p))
    }

    fn clearance(&self, offset: f32) -> f32 {
        self.thickness.unwrap_or(offset)
    }

    /// A rigid obstacle's box at rest carried by its pose at `t` (its eight corners); a
    /// sequence's is taken as unbounded.
    fn shell(&self, t: f64, offset: f32) -> Option<(Vec3, Vec3)> {
        let placed = self.placed()?;
        let unbounded = Some((Vec3::NEG_INFINITY, Vec3::INFINITY));
        if placed.sequence.is_some() {
            return unbounded;
        }
        let Some((lo, hi)) = placed.surface.bounds() else {
            return unbounded;
        };
        let pose = placed.motion.at(t);
        let corner = |k: usize| {
            let pick = |bit: usize, axis: usize| if k & bit == 0 { lo[axis] } else { hi[axis] };
            pose.apply(placed.pivot, Vec3::new(pick(1, 0), pick(2, 1), pick(4, 2)))
        };
        let (lo, hi) = (0..8)
            .map(corner)
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(c), hi.max(c))
            });
        Some((lo - Vec3::splat(offset), hi + Vec3::splat(offset)))
    }

    fn guard(&self, up: Vec3, _cloth: &ClothState) -> GuardShare {
        let Some(placed) = self.placed() else {
            return GuardShare::default();
        };
        if let Some(sequence) = &placed.sequence {
            return GuardShare {
                floor: sequence.lowest(up),
                surface_speed: sequence.fastest(),
                flow_speed: 0.0,
            };
        }
        let vertices = placed.surface.vertices();
        let lowest = vertices.iter().map(|v| v.dot(up)).reduce(f32::min);
        if !placed.motion.moves() {
            return GuardShare {
                floor: lowest,
                ..GuardShare::default()
            };
        }
        // Moving: sampled over the motion, its lowest reach below the pivot and the
        // fastest any point moves (the translation's speed plus the spin times the reach).
        let reach = (vertices.iter())
            .map(|v| v.distance(placed.pivot))
            .fold(0.0f32, f32::max);
        let end = placed.motion.end();
        let poses = (0..=256).map(|i| placed.motion.at(end * i as f64 / 256.0));
        let (mut floor, mut surface_speed) = (lowest, 0.0f32);
        for pose in poses {
            let centre = (placed.pivot + pose.translation).dot(up) - reach;
            floor = floor.map(|f| f.min(centre));
            surface_speed = surface_speed.max(pose.velocity.length() + pose.spin.length() * reach);
        }
        GuardShare {
            floor,
            surface_speed,
            flow_speed: 0.0,
        }
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    fn suggested(_cloth: &ClothBox) -> Self {
        Self::new("obstacle.obj")
    }
}
