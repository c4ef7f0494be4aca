//! What to draw: every overlay is a toggle.

use glam::Vec3;

/// How spring lines are coloured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SpringColoring {
    /// Structural blue, shear green, bend orange.
    ByKind,
    /// Rest length grey; stretched warm (red at +10 %); compressed cool (blue at −10 %).
    ByStrain,
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RenderOptions {
    /// The shaded cloth surface.
    pub mesh: bool,
    /// A checker from the UVs on the cloth, so stretching shows.
    pub checker: bool,
    /// Checker squares per UV unit.
    pub checker_scale: f32,
    /// Mesh edges as dark lines.
    pub wireframe: bool,
    /// Spring lines.
    pub springs: bool,
    pub spring_coloring: SpringColoring,
    /// Which spring kinds to draw `[structural, shear, bend]`.
    pub spring_kinds: [bool; 3],
    /// Particles as dots (pinned ones highlighted).
    pub particles: bool,
    /// Dot diameter, pixels.
    pub particle_size: f32,
    /// Sphere and ground plane.
    pub colliders: bool,
    /// Linear RGB of the cloth's front and back sides.
    pub front_color: Vec3,
    pub back_color: Vec3,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            mesh: true,
            checker: true,
            checker_scale: 8.0,
            wireframe: false,
            springs: false,
            spring_coloring: SpringColoring::ByKind,
            spring_kinds: [true, true, false],
            particles: false,
            particle_size: 4.0,
            colliders: true,
            front_color: Vec3::new(0.70, 0.09, 0.07),
            back_color: Vec3::new(0.85, 0.72, 0.35),
        }
    }
}

impl RenderOptions {
    /// Parses a comma-separated overlay list (`springs,particles,wireframe,strain,bend`).
    ///
    /// # Errors
    /// Names the unknown overlay and lists the known ones.
    pub fn with_overlays(mut self, list: &str) -> Result<Self, String> {
        for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            match item {
                "springs" => self.springs = true,
                "strain" => {
                    self.springs = true;
                    self.spring_coloring = SpringColoring::ByStrain;
                }
                "bend" => {
                    self.springs = true;
                    self.spring_kinds[2] = true;
                }
                "particles" => self.particles = true,
                "wireframe" => self.wireframe = true,
                "no-mesh" => self.mesh = false,
                "no-checker" => self.checker = false,
                other => {
                    return Err(format!(
                        "unknown overlay `{other}`; known: springs, strain, bend, particles, wireframe, no-mesh, no-checker"
                    ));
                }
            }
        }
        Ok(self)
    }
}
