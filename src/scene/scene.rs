//! A scene: a placed cloth, its parameters and the effects that act on it — everything a
//! [`super::Simulation`] starts from.

use std::path::Path;

use glam::{Mat3, Vec3};

use crate::cloth::{ClothModel, ClothState};
use crate::mesh::{self, ClothMesh, GridOrientation, MeshBuild, bounds, thinnest_axis};
use crate::sim::{Collider, Effect, SimParams};

use super::error::SceneError;
use super::registry::{PinRule, SCENARIOS, Scenario, ScenarioSetup, scenario};

/// The default cloth: a 1 m × 1 m square of 24 × 24 quads (see `assets/README.md`).
pub const DEFAULT_CLOTH_OBJ: &str = include_str!("../../assets/cloth.obj");
/// Name the default cloth goes by in messages.
pub const DEFAULT_CLOTH_NAME: &str = "assets/cloth.obj";

/// Everything needed to start a simulation. A [`super::Simulation`] takes it over; from
/// then on the simulation owns these values.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Registry name of the scenario.
    pub scenario: String,
    /// Where the cloth came from (a file path or the built-in asset).
    pub cloth_name: String,
    pub model: ClothModel,
    pub initial: ClothState,
    pub params: SimParams,
    pub effects: Vec<Effect>,
    /// The scenario's pins (applied while pins are enabled).
    pub pins: Vec<u32>,
    /// Notes from import (dropped faces and the like).
    pub warnings: Vec<String>,
}

impl Scene {
    /// Builds a registered scenario with its default cloth.
    ///
    /// # Errors
    /// [`SceneError::UnknownScenario`].
    pub fn builtin(name: &str) -> Result<Scene, SceneError> {
        let cloth = mesh::obj_from_str(DEFAULT_CLOTH_OBJ, DEFAULT_CLOTH_NAME)?;
        Self::with_cloth(name, &cloth, DEFAULT_CLOTH_NAME)
    }

    /// Builds a registered scenario with the cloth of an OBJ file.
    ///
    /// # Errors
    /// [`SceneError::UnknownScenario`], or the file's [`mesh::ObjError`].
    pub fn with_obj(name: &str, path: &Path) -> Result<Scene, SceneError> {
        Self::with_obj_options(name, path, &mesh::ImportOptions::default())
    }

    /// As [`Scene::with_obj`], importing with `options`.
    ///
    /// # Errors
    /// As [`Scene::with_obj`].
    pub fn with_obj_options(
        name: &str,
        path: &Path,
        options: &mesh::ImportOptions,
    ) -> Result<Scene, SceneError> {
        let cloth = mesh::load_obj_with(path, options)?;
        Self::with_cloth(name, &cloth, &path.display().to_string())
    }

    /// Builds a registered scenario around an already imported cloth.
    ///
    /// # Errors
    /// [`SceneError::UnknownScenario`].
    pub fn with_cloth(
        name: &str,
        cloth: &MeshBuild,
        cloth_name: &str,
    ) -> Result<Scene, SceneError> {
        let entry = lookup(name)?;
        Ok(Self::from_setup(entry, entry.setup(), cloth, cloth_name))
    }

    /// Places `cloth` as `setup` says and builds model and initial state.
    pub fn from_setup(
        entry: &'static Scenario,
        setup: ScenarioSetup,
        cloth: &MeshBuild,
        cloth_name: &str,
    ) -> Scene {
        let mut mesh = cloth.mesh.clone();
        place(&mut mesh, setup.orientation, setup.center);
        let pins = match setup.pins {
            PinRule::None => Vec::new(),
            PinRule::TopCorners => top_corners(&mesh.positions, setup.orientation),
        };
        let model = ClothModel::new(&mesh, setup.params.density, &pins);
        let initial = ClothState::at_rest(&model);
        Scene {
            scenario: entry.name.to_string(),
            cloth_name: cloth_name.to_string(),
            model,
            initial,
            params: setup.params,
            effects: setup.effects,
            pins,
            warnings: cloth.warnings.clone(),
        }
    }

    /// The sphere collider, if the scene has one (to adjust before simulating).
    pub fn sphere_mut(&mut self) -> Option<&mut Collider> {
        self.effects.iter_mut().find_map(|e| match e {
            Effect::Collider(c @ Collider::Sphere { .. }) => Some(c),
            _ => None,
        })
    }
}

fn lookup(name: &str) -> Result<&'static Scenario, SceneError> {
    scenario(name).ok_or_else(|| SceneError::UnknownScenario {
        name: name.to_string(),
        available: SCENARIOS
            .iter()
            .map(|s| s.name)
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

/// The two corners of the top edge: for a vertical cloth the particles nearest the top-left
/// and top-right corners of its bounding box in the x–y plane; for a horizontal cloth those
/// nearest the back-left and back-right corners in the x–z plane (ties go to the lower index).
fn top_corners(pos: &[Vec3], orientation: GridOrientation) -> Vec<u32> {
    let (lo, hi) = bounds(pos);
    // Distance below the top edge: down from max y, or forward from min z.
    let depth = |p: &Vec3| match orientation {
        GridOrientation::Vertical => hi.y - p.y,
        GridOrientation::Horizontal => p.z - lo.z,
    };
    let nearest = |corner_x: f32| {
        let mut best = (f32::INFINITY, 0u32);
        for (i, p) in pos.iter().enumerate() {
            let d = (p.x - corner_x).abs() + depth(p);
            if d < best.0 {
                best = (d, i as u32);
            }
        }
        best.1
    };
    let mut pins = vec![nearest(lo.x), nearest(hi.x)];
    pins.dedup();
    pins
}
