//! Scene files: TOML describing the cloth, its pins, the solver, the material and the
//! effects. The built-in scenarios are such files too (`assets/scenes/`). Unknown keys are
//! errors; every error names the file, the line and column, and the key.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::cloth::MassDistribution;
use crate::mesh::{GridBends, GridOrientation};
use crate::sim::{
    ClothSprings, ContactConfig, Effect, GuardPolicy, IntegratorKind, Keyframe, Material,
    Precision, RigidMotion, SimParams, SolverConfig, StepConfig,
};

use super::error::SceneError;
use super::locate::{Step, find_key, line_column, locate};

/// A scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub name: String,
    #[serde(default)]
    pub summary: String,
    pub cloth: ClothSpec,
    #[serde(default)]
    pub pins: PinSpec,
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(default)]
    pub material: MaterialSpec,
    /// The effects the scene lists (never the cloth's springs, which every scene has).
    #[serde(default)]
    pub effects: Vec<Effect>,
    /// Particles moved along keyframes (moving pins).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub handles: Vec<HandleSpec>,
}

/// A handle: particles chosen as `[pins]` chooses them, moved along keyframes about a pivot.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HandleSpec {
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub corners: Vec<Corner>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub edges: Vec<Edge>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub indices: Vec<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub region: Option<Region>,
    /// What its rotations turn about, metres (default: the chosen particles' centre at the
    /// start).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pivot: Option<[f32; 3]>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub keyframes: Vec<Keyframe>,
}

impl HandleSpec {
    /// The particles it chooses, as a pin rule.
    pub fn selection(&self) -> PinSpec {
        PinSpec {
            corners: self.corners.clone(),
            edges: self.edges.clone(),
            indices: self.indices.clone(),
            region: self.region,
        }
    }
}

/// The cloth: an OBJ file or a generated grid, and where it goes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClothSpec {
    /// An OBJ file, relative to the scene file (or absolute).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obj: Option<PathBuf>,
    /// A rectangular grid of quads.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<GridShape>,
    /// The plane the cloth is turned into (its thinnest axis becomes the plane's normal).
    #[serde(default = "horizontal")]
    pub orientation: GridOrientation,
    /// Where the centre of its bounding box goes, metres (default: the origin).
    #[serde(default)]
    pub center: [f32; 3],
    /// Welding tolerance for an OBJ, a fraction of its size (default 1e-6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weld_tolerance: Option<f32>,
}

fn horizontal() -> GridOrientation {
    GridOrientation::Horizontal
}

/// A grid: `quads` per side (or `[across, down]`), `size` metres per side (or `[w, h]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridShape {
    pub quads: OneOrTwo<u32>,
    pub size: OneOrTwo<f32>,
    /// Which pairs get bend springs (default: across each interior edge).
    #[serde(default, skip_serializing_if = "is_default")]
    pub bend: GridBends,
    /// Copies of the grid stacked one above another (default 1), `spacing` metres apart.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub layers: u32,
    /// Metres between stacked layers (with `layers`).
    #[serde(
        default = "default_spacing",
        skip_serializing_if = "is_default_spacing"
    )]
    pub spacing: f32,
}

fn one() -> u32 {
    1
}

fn is_one(n: &u32) -> bool {
    *n == 1
}

fn default_spacing() -> f32 {
    0.05
}

fn is_default_spacing(s: &f32) -> bool {
    *s == default_spacing()
}

fn is_default<T: Default + PartialEq>(value: &T) -> bool {
    *value == T::default()
}

/// One number for both directions, or two.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum OneOrTwo<T> {
    One(T),
    Two([T; 2]),
}

impl<T: Copy> OneOrTwo<T> {
    pub fn pair(&self) -> [T; 2] {
        match *self {
            OneOrTwo::One(x) => [x, x],
            OneOrTwo::Two(p) => p,
        }
    }
}

/// A corner of the cloth, as seen in its plane (for a horizontal cloth "top" is the back).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Corner {
    TopLeft,
    TopRight,
    BottomLeft,
    BottomRight,
}

/// An edge of the cloth, likewise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Edge {
    Top,
    Bottom,
    Left,
    Right,
}

/// Which particles are pinned: the union of every rule given.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PinSpec {
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub corners: Vec<Corner>,
    /// Every particle along these edges.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub edges: Vec<Edge>,
    /// Particle indices.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub indices: Vec<u32>,
    /// Every particle inside this box (placed coordinates, metres).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub region: Option<Region>,
}

/// An axis-aligned box, metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

/// The solver: integrator, steps, and how it solves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverSpec {
    pub integrator: IntegratorKind,
    /// Frame time step, seconds.
    pub dt: f32,
    pub substeps: u32,
    /// Collision thickness against colliders, metres.
    pub collision_offset: f32,
    pub tolerance: f32,
    pub max_iterations: u32,
    pub newton_iterations: u32,
    pub newton_tolerance: f32,
    pub xpbd_iterations: u32,
    pub vbd_iterations: u32,
    /// What the state, forces and integrators compute in: `"f32"` or `"f64"`.
    pub precision: Precision,
    pub guard: GuardPolicy,
}

impl Default for SolverSpec {
    fn default() -> Self {
        let p = SimParams::default();
        Self {
            integrator: p.step.integrator,
            dt: p.step.dt,
            substeps: p.step.substeps,
            collision_offset: p.contact.offset,
            tolerance: p.solver.tolerance,
            max_iterations: p.solver.max_iterations,
            newton_iterations: p.solver.newton_iterations,
            newton_tolerance: p.solver.newton_tolerance,
            xpbd_iterations: p.solver.xpbd_iterations,
            vbd_iterations: p.solver.vbd_iterations,
            precision: p.solver.precision,
            guard: p.guard,
        }
    }
}

/// A value per spring kind.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerKind {
    pub structural: f32,
    pub shear: f32,
    pub bend: f32,
}

impl From<[f32; 3]> for PerKind {
    fn from(v: [f32; 3]) -> Self {
        Self {
            structural: v[0],
            shear: v[1],
            bend: v[2],
        }
    }
}

impl From<PerKind> for [f32; 3] {
    fn from(v: PerKind) -> Self {
        [v.structural, v.shear, v.bend]
    }
}

/// The cloth's material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MaterialSpec {
    /// Areal density, kg/m².
    pub density: f32,
    /// Spring stiffness per kind, N/m (`bend` acts with `bending` by springs).
    pub stiffness: PerKind,
    /// Spring damping per kind, N·s/m.
    pub damping: PerKind,
    /// How the mass is shared: `lumped` by triangle area (default) or `uniform`.
    #[serde(skip_serializing_if = "is_default")]
    pub masses: MassDistribution,
}

impl Default for MaterialSpec {
    fn default() -> Self {
        let p = SimParams::default();
        Self {
            density: p.material.density,
            stiffness: p.material.stiffness.into(),
            damping: p.material.damping.into(),
            masses: MassDistribution::Lumped,
        }
    }
}

/// A scene file read from disk: the parsed file and where it was (for relative paths).
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedSceneFile {
    pub file: SceneFile,
    pub path: PathBuf,
    /// The file's text, to point into.
    pub text: String,
}

/// The path to a key of `[cloth] grid`.
fn grid_key(key: &'static str) -> Vec<Step> {
    vec![Step::Key("cloth"), Step::Key("grid"), Step::Key(key)]
}

impl SceneFile {
    /// Parses scene-file text; `path` names it in errors.
    ///
    /// # Errors
    /// [`SceneError::File`] with the line, column and key of the first problem: TOML
    /// syntax, an unknown key, a wrong type, or a value out of range.
    pub fn parse(text: &str, path: &Path) -> Result<SceneFile, SceneError> {
        let file: SceneFile = toml::from_str(text).map_err(|e| {
            let start = e.span().map_or(0, |s| s.start);
            // An unknown key inside a table is reported at the table; point at the key.
            let unknown = e
                .message()
                .strip_prefix("unknown field `")
                .and_then(|rest| rest.split('`').next())
                .and_then(|key| find_key(text, start, key));
            let (line, column) = line_column(text, unknown.unwrap_or(start));
            SceneError::File {
                path: path.to_path_buf(),
                line,
                column,
                message: e.message().trim().replace('\n', " "),
            }
        })?;
        file.check().map_err(|(path_in_file, message)| {
            let (line, column) = locate(text, &path_in_file);
            let key = match path_in_file.last() {
                Some(Step::Key(key)) => key,
                _ => "keyframes",
            };
            // A message that already names its key (`dt` = …) is shown as it is.
            let message = if message.starts_with('`') {
                message
            } else {
                format!("`{key}`: {message}")
            };
            SceneError::File {
                path: path.to_path_buf(),
                line,
                column,
                message,
            }
        })?;
        Ok(file)
    }

    /// Reads and parses a scene file.
    ///
    /// # Errors
    /// [`SceneError::Read`] or [`SceneError::File`].
    pub fn load(path: &Path) -> Result<LoadedSceneFile, SceneError> {
        let meta = std::fs::metadata(path).map_err(|e| SceneError::Read {
            path: path.to_path_buf(),
            detail: e.to_string(),
        })?;
        // Scene files are small; refuse anything else before reading it.
        if !meta.is_file() || meta.len() > 1 << 20 {
            return Err(SceneError::Read {
                path: path.to_path_buf(),
                detail: "not a regular file of at most 1 MiB".into(),
            });
        }
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::Read {
            path: path.to_path_buf(),
            detail: e.to_string(),
        })?;
        Ok(LoadedSceneFile {
            file: Self::parse(&text, path)?,
            path: path.to_path_buf(),
            text,
        })
    }

    /// Where in `text` (this file's) the key `key` of effect `effect` (from 0) is.
    pub(super) fn effect_key_at(text: &str, effect: usize, key: &'static str) -> (usize, usize) {
        locate(
            text,
            &[Step::Key("effects"), Step::At(effect), Step::Key(key)],
        )
    }

    /// The file as TOML text.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_else(|e| format!("# cannot write scene: {e}\n"))
    }

    /// Values the types cannot rule out: where the first bad one is and why.
    fn check(&self) -> Result<(), (Vec<Step>, String)> {
        use Step::{At, Key};
        let bad = |path: Vec<Step>, why: &str| Err((path, why.to_string()));
        match (&self.cloth.obj, &self.cloth.grid) {
            (Some(_), Some(_)) | (None, None) => {
                return bad(vec![Key("cloth")], "give exactly one of `obj` or `grid`");
            }
            (None, Some(g)) => {
                let [qx, qy] = g.quads.pair();
                let [sx, sy] = g.size.pair();
                if qx == 0 || qy == 0 || qx > 2048 || qy > 2048 {
                    return bad(grid_key("quads"), "must be in 1..=2048");
                }
                if !(sx.is_finite() && sy.is_finite() && sx > 0.0 && sy > 0.0) {
                    return bad(grid_key("size"), "must be positive metres");
                }
                if !(1..=64).contains(&g.layers) {
                    return bad(grid_key("layers"), "must be in 1..=64");
                }
                let height = g.spacing * (g.layers - 1) as f32;
                if !(g.spacing.is_finite() && g.spacing > 0.0 && height < sx.min(sy)) {
                    return bad(
                        grid_key("spacing"),
                        "must be positive metres, the stack (spacing × (layers − 1)) less \
                         than the grid's shorter side",
                    );
                }
            }
            (Some(_), None) => {}
        }
        if !self.cloth.center.iter().all(|c| c.is_finite()) {
            return bad(vec![Key("cloth"), Key("center")], "must be finite metres");
        }
        for (i, e) in self.effects.iter().enumerate() {
            if let Err(e) = e.check() {
                let mut path = vec![Key("effects"), At(i), Key(e.name)];
                // A keyframe's problem is at that keyframe (its value is its place).
                if let ("keyframes", Ok(k)) = (e.name, e.value.parse::<usize>()) {
                    path.push(At(k));
                    return bad(path, &e.rule);
                }
                let detail = format!("`{}` = {} {}", e.name, e.value, e.rule);
                return Err((path, detail));
            }
        }
        if let Some(twice) = crate::sim::listed_twice(&self.effects) {
            let path = vec![Key("effects"), At(twice.again), Key("type")];
            return Err((path, format!("`{}` {}", twice.kind, twice.rule())));
        }
        for (h, handle) in self.handles.iter().enumerate() {
            let at = |key| vec![Key("handles"), At(h), Key(key)];
            if let Some(pivot) = handle.pivot
                && !pivot.iter().all(|c| c.is_finite())
            {
                return bad(at("pivot"), "must be finite metres");
            }
            if let Err(e) = RigidMotion::new(&handle.keyframes) {
                let mut path = at("keyframes");
                path.push(At(e.index));
                return bad(path, &e.to_string());
            }
        }
        // A grid's shortest rest edge is known before it is built (an OBJ's is checked when
        // the scene is built).
        if let Some(g) = &self.cloth.grid {
            let ([qx, qy], [sx, sy]) = (g.quads.pair(), g.size.pair());
            let edge = (sx / qx as f32).min(sy / qy as f32);
            for (i, e) in self.effects.iter().enumerate() {
                if let Effect::SelfCollision(s) = e
                    && let Err(too_thick) = s.fits(edge)
                {
                    // Named as the file names it: `thickness` = …
                    let message = too_thick.to_string();
                    let message = message.trim_start_matches("self-collision ");
                    return bad(vec![Key("effects"), At(i), Key("thickness")], message);
                }
            }
        }
        // Solver and material values, checked as the simulation will check them.
        if let Err(e) = self.params().validate() {
            // `solver.tolerance` is `tolerance` in [solver], `guard.x` is `x` in
            // [solver.guard], the material's are in [material].
            let key = e.name.rsplit('.').next().unwrap_or(e.name);
            let path = match e.name.split_once('.') {
                Some(("guard", _)) => vec![Key("solver"), Key("guard"), Key(key)],
                _ if ["stiffness", "damping", "density"].contains(&key) => {
                    vec![Key("material"), Key(key)]
                }
                _ => vec![Key("solver"), Key(key)],
            };
            let detail = format!("`{key}` = {} {}", e.value, e.rule);
            return Err((path, detail));
        }
        Ok(())
    }

    /// The simulation parameters the file gives.
    pub fn params(&self) -> SimParams {
        let s = &self.solver;
        SimParams {
            step: StepConfig {
                dt: s.dt,
                substeps: s.substeps,
                integrator: s.integrator,
            },
            material: Material {
                stiffness: self.material.stiffness.into(),
                damping: self.material.damping.into(),
                density: self.material.density,
            },
            contact: ContactConfig {
                offset: s.collision_offset,
            },
            guard: s.guard.clone(),
            solver: SolverConfig {
                tolerance: s.tolerance,
                max_iterations: s.max_iterations,
                newton_iterations: s.newton_iterations,
                newton_tolerance: s.newton_tolerance,
                xpbd_iterations: s.xpbd_iterations,
                vbd_iterations: s.vbd_iterations,
                precision: s.precision,
            },
        }
    }

    /// The effects the file lists, with the cloth's springs first.
    pub fn effects(&self) -> Vec<Effect> {
        std::iter::once(Effect::Springs(ClothSprings))
            .chain(self.effects.iter().cloned())
            .collect()
    }

    /// This file with its solver, material, effects and pins replaced by those of a running
    /// simulation (what "save the current setup" writes).
    pub fn with_setup(
        &self,
        params: &SimParams,
        effects: &[Effect],
        pins: Option<&[u32]>,
    ) -> SceneFile {
        let mut file = self.clone();
        file.solver = SolverSpec {
            integrator: params.step.integrator,
            dt: params.step.dt,
            substeps: params.step.substeps,
            collision_offset: params.contact.offset,
            tolerance: params.solver.tolerance,
            max_iterations: params.solver.max_iterations,
            newton_iterations: params.solver.newton_iterations,
            newton_tolerance: params.solver.newton_tolerance,
            xpbd_iterations: params.solver.xpbd_iterations,
            vbd_iterations: params.solver.vbd_iterations,
            precision: params.solver.precision,
            guard: params.guard.clone(),
        };
        file.material = MaterialSpec {
            density: params.material.density,
            stiffness: params.material.stiffness.into(),
            damping: params.material.damping.into(),
            masses: self.material.masses,
        };
        // The springs are every scene's; handles are written as `[[handles]]`.
        file.effects = (effects.iter())
            .filter(|e| !matches!(e, Effect::Springs(_) | Effect::Handle(_)))
            .cloned()
            .collect();
        if let Some(pins) = pins {
            file.pins = PinSpec {
                indices: pins.to_vec(),
                ..PinSpec::default()
            };
        }
        file
    }
}
