//! The glue between a running simulation and the renderer: the plain frame description of
//! a simulation's current state and the camera that frames its scene. The renderer imports
//! neither `sim` nor `scene`; callers (the app, the CLI, tests) build its input here.

use glam::{Mat4, Quat, Vec3};

use crate::render::{Frame, MeshShape, OrbitCamera, Shape, SpringLines};
use crate::scene::Simulation;
use crate::sim::Effect;

/// The frame to draw for `sim`'s current state.
pub fn frame(sim: &Simulation) -> Frame<'_> {
    let model = sim.model();
    let springs = &model.springs;
    Frame {
        positions: &sim.state().pos,
        device_positions: None,
        uvs: &model.uvs,
        triangles: &model.triangles,
        springs: SpringLines {
            a: &springs.a,
            b: &springs.b,
            rest: &springs.rest,
            kind: &springs.kind,
        },
        pinned: &model.pins,
        shapes: shapes(sim.effects(), sim.state().time),
        meshes: meshes(sim.effects(), sim.state().time),
    }
}

/// The mesh obstacles among `effects` as meshes to draw, where their motion has them at
/// simulated time `time`.
pub fn meshes(effects: &[Effect], time: f64) -> Vec<MeshShape<'_>> {
    (effects.iter())
        .filter_map(|e| match e {
            Effect::Obstacle(o) => o.placed(),
            _ => None,
        })
        .map(|placed| {
            let pose = placed.motion.at(time);
            let pivot = placed.pivot;
            let (vertices, deforms) = placed.vertices_at(time);
            MeshShape {
                id: std::ptr::from_ref(placed) as usize,
                vertices,
                deforms,
                triangles: placed.surface.triangles(),
                transform: Mat4::from_translation(pivot + pose.translation)
                    * Mat4::from_quat(pose.rotation)
                    * Mat4::from_translation(-pivot),
            }
        })
        .collect()
}

/// The solids among `effects` as shapes to draw at simulated time `time` (spinning spheres
/// turned).
pub fn shapes(effects: &[Effect], time: f64) -> Vec<Shape> {
    effects
        .iter()
        .filter_map(|e| match e {
            Effect::Sphere(s) => Some(Shape::Sphere {
                center: s.center,
                radius: s.radius,
                rotation: Quat::from_axis_angle(
                    s.spin.try_normalize().unwrap_or(Vec3::Y),
                    s.spin.length() * time as f32,
                ),
            }),
            Effect::Plane(p) => Some(Shape::Plane {
                point: p.point,
                normal: p.unit_normal(),
            }),
            // Mesh obstacles are drawn as meshes (`meshes`).
            Effect::Obstacle(_)
            | Effect::Handle(_)
            | Effect::Springs(_)
            | Effect::Gravity(_)
            | Effect::AirDamping(_)
            | Effect::Bending(_)
            | Effect::Wind(_)
            | Effect::SelfCollision(_) => None,
        })
        .collect()
}

/// The scene's default camera for a picture of `aspect` = width / height: it frames where
/// the cloth goes over its motion ([`Simulation::motion_points`]).
pub fn default_camera(sim: &Simulation, aspect: f32) -> OrbitCamera {
    OrbitCamera::framing(&sim.motion_points(), aspect)
}
