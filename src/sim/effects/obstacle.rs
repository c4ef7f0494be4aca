//! An obstacle of any shape: a triangle mesh from an OBJ file, placed (scale, then rotate,
//! then translate, about the OBJ's own origin) and optionally moved through keyframes. The
//! cloth may not pass it; the cloth does not push it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Quat, Vec3};

use super::effect_kind::{ClothBox, ContactPass, EffectKind, GuardShare};
use super::solid::{Solid, default_friction, resolve};
use crate::mesh::{ObjError, PolygonSoup, parse_obj, read_obj};
use crate::sim::motion::{AxisAngle, Keyframe, Pose, RigidMotion};
use crate::sim::obstacle::Surface;
use crate::sim::param_error::ParamError;
use crate::sim::self_contacts::ContactError;

/// A mesh obstacle as a scene file gives it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// The OBJ file (relative to the scene file); metres.
    pub obj: PathBuf,
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

/// The placed surface and its motion about `pivot`.
#[derive(Debug)]
pub struct Placed {
    pub surface: Surface,
    pub motion: RigidMotion,
    pub pivot: Vec3,
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
            shape: Shape::default(),
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

    /// Reads its OBJ (`base` is where a relative path starts) and places it.
    ///
    /// # Errors
    /// The OBJ's [`ObjError`] (naming its file and line), or [`ObstacleError::Setting`] for a
    /// placement or motion that [`EffectKind::check`] refuses.
    pub fn load(&mut self, base: Option<&Path>) -> Result<(), ObstacleError> {
        let path = base.map_or_else(|| self.obj.clone(), |b| b.join(&self.obj));
        self.check().map_err(|error| ObstacleError::Setting {
            path: path.clone(),
            error,
        })?;
        self.place(&read_obj(&path)?, &path)
    }

    /// As [`Obstacle::load`], from the text of its OBJ (a built-in mesh).
    ///
    /// # Errors
    /// As [`Obstacle::load`].
    pub fn load_text(&mut self, text: &str) -> Result<(), ObstacleError> {
        let path = self.obj.clone();
        self.check().map_err(|error| ObstacleError::Setting {
            path: path.clone(),
            error,
        })?;
        self.place(&parse_obj(text, &path)?, &path)
    }

    /// Places `soup` (read from `path`) as the obstacle says.
    fn place(&mut self, soup: &PolygonSoup, path: &Path) -> Result<(), ObstacleError> {
        let setting = |error| ObstacleError::Setting {
            path: path.to_path_buf(),
            error,
        };
        let soup = soup.triangulated();
        let rotation = self.rotation();
        let vertices = (soup.positions.iter())
            .map(|&p| rotation * (p * self.scale) + self.translate)
            .collect();
        let triangles = (soup.face_indices.chunks_exact(3))
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let motion = RigidMotion::new(&self.keyframes)
            .map_err(|e| setting(ParamError::new("keyframes", e.index, e.to_string())))?;
        self.shape = Shape(Some(Arc::new(Placed {
            surface: Surface::new(vertices, triangles),
            motion,
            pivot: self.translate,
        })));
        Ok(())
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
    /// Keeps every cloth edge (its structural and shear springs) the thickness from the
    /// obstacle's sharp edges where it ends the substep: the two particles are moved apart
    /// from the edge in proportion to how near each is to the nearest point, which moves by
    /// exactly what was missing; their velocity towards the edge is removed, with Coulomb
    /// friction along it. Returns how many cloth edges it moved.
    fn push_edges(&self, pass: &mut ContactPass<'_>) -> usize {
        let edges = self.placed.surface.sharp_edges();
        if edges.is_empty() {
            return 0;
        }
        let (pivot, thickness, mu) = (self.placed.pivot, pass.offset, self.friction);
        let (springs, inv_mass) = (&pass.model.springs, &pass.model.inv_mass);
        let state = &mut *pass.state;
        let mut moved = 0;
        for e in 0..pass.model.bend_start() {
            let (i, j) = (springs.a[e] as usize, springs.b[e] as usize);
            let free = [inv_mass[i] > 0.0, inv_mass[j] > 0.0].map(f32::from);
            if free == [0.0, 0.0] {
                continue;
            }
            let (a, b) = (state.pos[i], state.pos[j]);
            let local = [a, b].map(|p| self.end.unapply(pivot, p));
            let Some(hit) = edges.nearest(local[0], local[1], thickness) else {
                continue;
            };
            let away = hit.on_segment - hit.on_edge;
            if hit.distance <= thickness * 1e-3 || hit.distance >= thickness {
                continue;
            }
            let n = self.end.rotation * (away / hit.distance);
            let share = [1.0 - hit.along, hit.along];
            let weight = share[0] * share[0] * free[0] + share[1] * share[1] * free[1];
            if weight <= 0.0 {
                continue;
            }
            let lift = (thickness - hit.distance) / weight;
            let v_surface = self
                .end
                .velocity_at(pivot, self.end.apply(pivot, hit.on_edge));
            for (k, p) in [i, j].into_iter().enumerate() {
                let part = share[k] * free[k];
                if part <= 0.0 {
                    continue;
                }
                state.pos[p] += n * (lift * part);
                let v_rel = state.vel[p] - v_surface;
                let vn = v_rel.dot(n);
                if vn < 0.0 {
                    let v_t = v_rel - vn * n;
                    let speed = v_t.length();
                    let keep = if speed > 0.0 {
                        (1.0 - mu * part * (-vn) / speed).max(0.0)
                    } else {
                        0.0
                    };
                    state.vel[p] = v_surface + (1.0 - part) * vn * n + keep * v_t;
                }
            }
            moved += 1;
        }
        moved
    }
}

impl Solid for Posed<'_> {
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
        self.contact(from, to, offset).map(|(at, _, _)| at)
    }

    /// The move seen from the obstacle (start and end each in its frame at that time), so
    /// a moving obstacle sweeps particles along as a still one stops them.
    fn contact(&self, from: Vec3, to: Vec3, offset: f32) -> Option<(Vec3, Vec3, Vec3)> {
        let pivot = self.placed.pivot;
        let (a, b) = (self.start.unapply(pivot, from), self.end.unapply(pivot, to));
        let caught = self.placed.surface.catch(a, b, offset)?;
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
        let posed = Posed {
            placed,
            start: placed.motion.at(end - pass.substep as f64),
            end: placed.motion.at(end),
            friction: self.friction,
        };
        let offset = pass.offset;
        if let Some(thickness) = self.thickness {
            pass.offset = thickness;
        }
        let moved = resolve(&posed, pass) + posed.push_edges(pass);
        pass.offset = offset;
        Ok(moved)
    }

    fn surface(&self, p: Vec3) -> Option<(f32, Vec3, Vec3)> {
        let placed = self.placed()?;
        let still = Posed {
            placed,
            start: Pose::REST,
            end: Pose::REST,
            friction: self.friction,
        };
        Some(still.surface_at(p))
    }

    fn guard(&self, up: Vec3) -> GuardShare {
        let Some(placed) = self.placed() else {
            return GuardShare::default();
        };
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
        Err("mesh obstacles")
    }

    fn suggested(_cloth: &ClothBox) -> Self {
        Self::new("obstacle.obj")
    }
}
