//! A scene: a placed cloth, its parameters and the effects that act on it — everything a
//! [`super::Simulation`] starts from — built from a scene file.

use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};

use crate::cloth::{ClothModel, ClothState};
use crate::mesh::{
    self, ClothMesh, GridOrientation, GridSpec, ImportOptions, MeshBuild, bounds, thinnest_axis,
};
use crate::sim::{
    Effect, Handle, ObstacleError, ParamError, RigidMotion, SimParams, Sphere, thickness_fits,
};

use super::error::{PinError, SceneError};
use super::file::{Corner, Edge, HandleSpec, LoadedSceneFile, PinSpec, SceneFile};
use super::registry::{BUILTIN_SCENES, builtin_mesh, scenario};

/// The default cloth: a 1 m × 1 m square of 24 × 24 quads (see `assets/README.md`).
pub const DEFAULT_CLOTH_OBJ: &str = include_str!("../../assets/cloth.obj");
/// Name the default cloth goes by in messages.
pub const DEFAULT_CLOTH_NAME: &str = "assets/cloth.obj";

/// Everything needed to start a simulation. A [`super::Simulation`] takes it over; from
/// then on the simulation owns these values.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The file it was built from (with the cloth it actually has): what saving writes.
    pub file: SceneFile,
    /// Name of the scene.
    pub scenario: String,
    /// Where the cloth came from (a file path, or the grid it was generated as).
    pub cloth_name: String,
    pub model: ClothModel,
    pub initial: ClothState,
    pub params: SimParams,
    pub effects: Vec<Effect>,
    /// The scene's pins (applied while pins are enabled).
    pub pins: Vec<u32>,
    /// Notes from import (dropped faces and the like).
    pub warnings: Vec<String>,
}

/// Reads the mesh of every obstacle `file` lists (`base`: where relative paths start; a
/// built-in scene, without one, finds its meshes among the built-in ones).
fn load_obstacles(
    file: &mut SceneFile,
    base: Option<&Path>,
) -> Result<(), (usize, &'static str, ObstacleError)> {
    for (k, effect) in file.effects.iter_mut().enumerate() {
        if let Effect::Obstacle(obstacle) = effect
            && !obstacle.is_loaded()
        {
            let key = if obstacle.frames.is_some() {
                "frames"
            } else {
                "obj"
            };
            let located = |e| (k, key, e);
            // A built-in scene's meshes are the program's own.
            match base {
                None => obstacle.load_with(None, &builtin_mesh).map_err(located)?,
                Some(base) => {
                    obstacle.load(Some(base)).map_err(located)?;
                    // From here on the paths read from where the program runs (saving
                    // makes them relative to the saved file again).
                    if let Some(pattern) = &obstacle.frames {
                        obstacle.frames = Some(base.join(pattern).display().to_string());
                    } else {
                        obstacle.obj = base.join(&obstacle.obj);
                    }
                }
            }
        }
    }
    Ok(())
}

/// The file of `loaded` with its obstacles read; one that cannot be is pointed at in the
/// scene file, by the key that names its mesh (or the setting refused).
fn with_obstacles(loaded: &LoadedSceneFile) -> Result<SceneFile, SceneError> {
    let mut file = loaded.file.clone();
    load_obstacles(&mut file, loaded.path.parent()).map_err(|(k, key, error)| {
        let key = match &error {
            ObstacleError::Setting { error, .. } => error.name,
            ObstacleError::Obj(_) => key,
        };
        let (line, column) = SceneFile::effect_key_at(&loaded.text, k, key);
        SceneError::File {
            path: loaded.path.clone(),
            line,
            column,
            message: format!("obstacle: {error}"),
        }
    })?;
    Ok(file)
}

impl Scene {
    /// A built-in scene.
    ///
    /// # Errors
    /// [`SceneError::UnknownScenario`].
    pub fn builtin(name: &str) -> Result<Scene, SceneError> {
        Self::from_file(lookup(name)?.clone(), None)
    }

    /// A built-in scene or a scene file: `what` is a path when it ends in `.toml`.
    ///
    /// # Errors
    /// [`SceneError::UnknownScenario`], or the file's errors.
    pub fn open(what: &str) -> Result<Scene, SceneError> {
        if what.ends_with(".toml") {
            Self::from_loaded(&SceneFile::load(Path::new(what))?)
        } else {
            Self::builtin(what)
        }
    }

    /// A built-in scene or a scene file (`what` ends in `.toml`), with its own cloth or, when
    /// given, the cloth of an OBJ file imported with `options`.
    ///
    /// # Errors
    /// [`SceneError::UnknownScenario`], the scene file's errors, or the OBJ's.
    pub fn open_with_obj(
        what: &str,
        obj: Option<&Path>,
        options: &ImportOptions,
    ) -> Result<Scene, SceneError> {
        Self::open_resized(what, obj, options, None)
    }

    /// As [`Scene::open_with_obj`], with the grid cloth resized to `quads` quads along its
    /// longer side when given ([`SceneFile::resize_grid`]).
    ///
    /// # Errors
    /// As [`Scene::open_with_obj`], and [`SceneError::Resize`].
    pub fn open_resized(
        what: &str,
        obj: Option<&Path>,
        options: &ImportOptions,
        quads: Option<u32>,
    ) -> Result<Scene, SceneError> {
        let (mut file, base) = if what.ends_with(".toml") {
            let loaded = SceneFile::load(Path::new(what))?;
            let base = loaded.path.parent().map(Path::to_path_buf);
            (with_obstacles(&loaded)?, base)
        } else {
            (lookup(what)?.clone(), None)
        };
        if let Some(quads) = quads {
            if obj.is_some() {
                return Err(SceneError::Resize {
                    scene: file.name.clone(),
                    why: "--quads resizes a grid cloth; it cannot go with --obj".into(),
                });
            }
            file.resize_grid(quads)?;
        }
        match obj {
            Some(path) => {
                let cloth = mesh::load_obj_with(path, options)?;
                let mut file = file;
                load_obstacles(&mut file, base.as_deref()).map_err(|(_, _, e)| e)?;
                file.cloth.grid = None;
                file.cloth.obj = Some(path.to_path_buf());
                Self::with_mesh(file, &cloth, &path.display().to_string())
            }
            None => Self::from_file(file, base.as_deref()),
        }
    }

    /// A scene file read from disk (an OBJ it names is found beside it).
    ///
    /// # Errors
    /// The cloth's [`mesh::ObjError`], or [`SceneError::Pins`].
    pub fn from_loaded(loaded: &LoadedSceneFile) -> Result<Scene, SceneError> {
        Self::from_file(with_obstacles(loaded)?, loaded.path.parent())
    }

    /// A scene from a parsed file; `base` is where relative paths start.
    ///
    /// # Errors
    /// The cloth's [`mesh::ObjError`], or [`SceneError::Pins`].
    pub fn from_file(mut file: SceneFile, base: Option<&Path>) -> Result<Scene, SceneError> {
        load_obstacles(&mut file, base).map_err(|(_, _, e)| e)?;
        let (cloth, name) = match (&file.cloth.obj, &file.cloth.grid) {
            (Some(obj), _) => {
                let path = base.map_or_else(|| obj.clone(), |b| b.join(obj));
                let options = ImportOptions {
                    weld_tolerance: file
                        .cloth
                        .weld_tolerance
                        .unwrap_or(ImportOptions::default().weld_tolerance),
                };
                let build = mesh::load_obj_with(&path, &options)?;
                let name = path.display().to_string();
                file.cloth.obj = Some(path);
                (build, name)
            }
            (None, Some(grid)) => {
                let [qx, qy] = grid.quads.pair();
                let [sx, sy] = grid.size.pair();
                let spec = GridSpec {
                    quads_x: qx,
                    quads_y: qy,
                    size_x: sx,
                    size_y: sy,
                    orientation: GridOrientation::Horizontal,
                    center: Vec3::ZERO,
                };
                let mut mesh = spec.build_with(grid.bend)?;
                let mut name = format!("{qx}×{qy}-quad grid, {sx}×{sy} m");
                if grid.layers > 1 {
                    mesh = mesh.stacked(grid.layers, Vec3::Y * grid.spacing);
                    name = format!("{} layers of {name}, {} m apart", grid.layers, grid.spacing);
                }
                (MeshBuild::from(mesh), name)
            }
            // `SceneFile::parse` refuses this; a file built in code may still have it.
            (None, None) => {
                return Err(SceneError::NoCloth {
                    scene: file.name.clone(),
                });
            }
        };
        Self::with_mesh(file, &cloth, &name)
    }

    /// A built-in scene with the cloth of an OBJ file.
    ///
    /// # Errors
    /// [`SceneError::UnknownScenario`], or the file's [`mesh::ObjError`].
    pub fn with_obj(name: &str, path: &Path) -> Result<Scene, SceneError> {
        Self::with_obj_options(name, path, &ImportOptions::default())
    }

    /// As [`Scene::with_obj`], importing with `options`.
    ///
    /// # Errors
    /// As [`Scene::with_obj`].
    pub fn with_obj_options(
        name: &str,
        path: &Path,
        options: &ImportOptions,
    ) -> Result<Scene, SceneError> {
        let cloth = mesh::load_obj_with(path, options)?;
        Self::with_cloth(name, &cloth, &path.display().to_string())
    }

    /// A built-in scene around an already imported cloth (`cloth_name`: its file).
    ///
    /// # Errors
    /// [`SceneError::UnknownScenario`], [`SceneError::Pins`].
    pub fn with_cloth(
        name: &str,
        cloth: &MeshBuild,
        cloth_name: &str,
    ) -> Result<Scene, SceneError> {
        let mut file = lookup(name)?.clone();
        file.cloth.grid = None;
        file.cloth.obj = Some(PathBuf::from(cloth_name));
        Self::with_mesh(file, cloth, cloth_name)
    }

    /// Places `cloth` as `file` says, pins it, and builds model and initial state.
    ///
    /// # Errors
    /// [`SceneError::Pins`] for a pin index the cloth does not have,
    /// [`SceneError::Thickness`] for a self-collision thickness the cloth cannot take.
    pub fn with_mesh(
        file: SceneFile,
        cloth: &MeshBuild,
        cloth_name: &str,
    ) -> Result<Scene, SceneError> {
        let mut mesh = cloth.mesh.clone();
        let orientation = file.cloth.orientation;
        place(&mut mesh, orientation, Vec3::from(file.cloth.center));
        let mut pins = pins(&file.pins, &mesh.positions, orientation)?;
        let handles = handles(&file.handles, &mesh.positions, orientation, &pins)?;
        // Handled particles are pinned: the cloth does not move them, their handle does (and
        // the Pins switch frees them as it frees pins).
        pins.extend(handles.iter().flat_map(|h| h.particles.iter().copied()));
        pins.sort_unstable();
        pins.dedup();
        let params = file.params();
        let mut model = ClothModel::new(&mesh, params.material.density, &pins);
        if file.material.masses != model.masses {
            model.set_mass_distribution(file.material.masses);
        }
        let mut effects = file.effects();
        effects.extend(handles.into_iter().map(Effect::Handle));
        thickness_fits(&effects, &model).map_err(|error| SceneError::Thickness {
            cloth: cloth_name.to_string(),
            error,
        })?;
        let initial = ClothState::at_rest(&model);
        Ok(Scene {
            scenario: file.name.clone(),
            effects,
            file,
            cloth_name: cloth_name.to_string(),
            model,
            initial,
            params,
            pins,
            warnings: cloth.warnings.clone(),
        })
    }

    /// The sphere collider, if the scene has one (to adjust before simulating).
    pub fn sphere_mut(&mut self) -> Option<&mut Sphere> {
        self.effects.iter_mut().find_map(|e| match e {
            Effect::Sphere(s) => Some(s),
            _ => None,
        })
    }
}

fn lookup(name: &str) -> Result<&'static SceneFile, SceneError> {
    scenario(name).ok_or_else(|| SceneError::UnknownScenario {
        name: name.to_string(),
        available: BUILTIN_SCENES
            .iter()
            .map(|(n, _)| *n)
            .collect::<Vec<_>>()
            .join(", "),
    })
}

/// Turns the cloth so its thinnest axis becomes the orientation's normal (a proper rotation,
/// so winding and handedness survive), then moves its bounding-box centre to `center`.
/// Units are kept: an OBJ is read as metres.
fn place(mesh: &mut ClothMesh, orientation: GridOrientation, center: Vec3) {
    let (lo, hi) = bounds(&mesh.positions);
    let thin = thinnest_axis(lo, hi);
    // Columns are the images of x, y, z.
    let rotation = match (orientation, thin) {
        // Horizontal cloth stood up: −z (the back row) goes to +y (the top).
        (GridOrientation::Vertical, 1) => Mat3::from_cols(Vec3::X, Vec3::Z, -Vec3::Y),
        (GridOrientation::Vertical, 0) => Mat3::from_cols(-Vec3::Z, Vec3::Y, Vec3::X),
        // Vertical cloth laid down: the top (+y) goes to the back (−z).
        (GridOrientation::Horizontal, 2) => Mat3::from_cols(Vec3::X, -Vec3::Z, Vec3::Y),
        (GridOrientation::Horizontal, 0) => Mat3::from_cols(Vec3::Y, -Vec3::X, Vec3::Z),
        _ => Mat3::IDENTITY,
    };
    for p in &mut mesh.positions {
        *p = rotation * *p;
    }
    let (lo, hi) = bounds(&mesh.positions);
    let shift = center - 0.5 * (lo + hi);
    for p in &mut mesh.positions {
        *p += shift;
    }
}

/// How far below the top edge a point is, within the cloth's plane: down from the highest
/// y of a vertical cloth, forward from the back (lowest z) of a horizontal one.
fn depth(p: Vec3, lo: Vec3, hi: Vec3, orientation: GridOrientation) -> f32 {
    match orientation {
        GridOrientation::Vertical => hi.y - p.y,
        GridOrientation::Horizontal => p.z - lo.z,
    }
}

/// The handles `specs` make of the cloth at `pos`: each one's particles, their places, its
/// pivot (by default their centre) and its motion (checked when the file was read).
fn handles(
    specs: &[HandleSpec],
    pos: &[Vec3],
    orientation: GridOrientation,
    pinned: &[u32],
) -> Result<Vec<Handle>, SceneError> {
    let mut out = Vec::with_capacity(specs.len());
    for (i, spec) in specs.iter().enumerate() {
        let particles = pins(&spec.selection(), pos, orientation)?;
        if particles.is_empty() {
            return Err(PinError::EmptyHandle { handle: i + 1 }.into());
        }
        if let Some(&particle) = particles.iter().find(|p| pinned.contains(p)) {
            return Err(PinError::PinnedAndHandled {
                handle: i + 1,
                particle,
            }
            .into());
        }
        let rest: Vec<Vec3> = particles.iter().map(|&p| pos[p as usize]).collect();
        let centre = rest.iter().sum::<Vec3>() / rest.len() as f32;
        let motion = RigidMotion::new(&spec.keyframes).map_err(|e| {
            SceneError::Params(ParamError::new("keyframes", e.index, e.to_string()))
        })?;
        out.push(Handle {
            particles,
            rest,
            pivot: spec.pivot.map_or(centre, Vec3::from),
            motion,
        });
    }
    Ok(out)
}

/// The particles the pin rules select, sorted and unique.
fn pins(
    spec: &PinSpec,
    pos: &[Vec3],
    orientation: GridOrientation,
) -> Result<Vec<u32>, SceneError> {
    let (lo, hi) = bounds(pos);
    let size = (hi - lo).length().max(f32::MIN_POSITIVE);
    let full_depth = depth(
        match orientation {
            GridOrientation::Vertical => lo,
            GridOrientation::Horizontal => hi,
        },
        lo,
        hi,
        orientation,
    );
    let mut out = Vec::new();
    for corner in &spec.corners {
        let (x, bottom) = match corner {
            Corner::TopLeft => (lo.x, false),
            Corner::TopRight => (hi.x, false),
            Corner::BottomLeft => (lo.x, true),
            Corner::BottomRight => (hi.x, true),
        };
        // Nearest particle to the corner (ties to the lower index).
        let mut best = (f32::INFINITY, 0u32);
        for (i, p) in pos.iter().enumerate() {
            let d = depth(*p, lo, hi, orientation);
            let along = if bottom { full_depth - d } else { d };
            let score = (p.x - x).abs() + along;
            if score < best.0 {
                best = (score, i as u32);
            }
        }
        out.push(best.1);
    }
    let eps = 1e-4 * size;
    for edge in &spec.edges {
        for (i, p) in pos.iter().enumerate() {
            let d = depth(*p, lo, hi, orientation);
            let on = match edge {
                Edge::Top => d <= eps,
                Edge::Bottom => d >= full_depth - eps,
                Edge::Left => p.x <= lo.x + eps,
                Edge::Right => p.x >= hi.x - eps,
            };
            if on {
                out.push(i as u32);
            }
        }
    }
    if let Some(&bad) = spec.indices.iter().find(|&&i| i as usize >= pos.len()) {
        return Err(PinError::NoSuchParticle {
            index: bad,
            particles: pos.len(),
        }
        .into());
    }
    out.extend_from_slice(&spec.indices);
    if let Some(r) = spec.region {
        let (min, max) = (Vec3::from(r.min), Vec3::from(r.max));
        let before = out.len();
        out.extend(
            pos.iter()
                .enumerate()
                .filter(|(_, p)| p.cmpge(min).all() && p.cmple(max).all())
                .map(|(i, _)| i as u32),
        );
        // An empty region is a mistake (a typo in a bound), not a wish for no pins.
        if out.len() == before {
            return Err(PinError::EmptyRegion { min, max, lo, hi }.into());
        }
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}
