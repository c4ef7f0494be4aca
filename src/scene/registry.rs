//! The scenario registry: one table feeds the GUI, the CLI, the tests and the benches.

use glam::Vec3;

use crate::mesh::GridOrientation;
use crate::sim::{Collider, Effect, SimParams};

/// Which particles a scenario pins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PinRule {
    None,
    /// The two corners of the cloth's top edge: the highest edge of a vertical cloth, the
    /// back (−z) edge of a horizontal one.
    TopCorners,
}

/// Everything a scenario decides besides the cloth mesh itself.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioSetup {
    /// The plane the cloth is turned into (its thinnest axis becomes this plane's normal).
    pub orientation: GridOrientation,
    /// Where the centre of the cloth's bounding box is placed, metres.
    pub center: Vec3,
    pub pins: PinRule,
    pub params: SimParams,
    pub effects: Vec<Effect>,
}

/// One entry of the registry.
pub struct Scenario {
    pub name: &'static str,
    pub summary: &'static str,
    setup: fn() -> ScenarioSetup,
}

impl Scenario {
    /// The scenario's placement, pins, parameters and effects.
    pub fn setup(&self) -> ScenarioSetup {
        (self.setup)()
    }
}

/// Radius and centre of the sphere in the sphere scenarios: it rests 5 cm above the ground.
const SPHERE_RADIUS: f32 = 0.4;
const SPHERE_CENTER: Vec3 = Vec3::new(0.0, 0.45, 0.0);

fn ground() -> Effect {
    Effect::Collider(Collider::Plane {
        point: Vec3::ZERO,
        normal: Vec3::Y,
        friction: 0.4,
    })
}

fn cloth_forces() -> Vec<Effect> {
    vec![Effect::Gravity, Effect::Springs, Effect::AirDamping]
}

fn hanging() -> ScenarioSetup {
    ScenarioSetup {
        // Starts horizontal, held by two corners: it swings down and hangs in folds.
        orientation: GridOrientation::Horizontal,
        center: Vec3::new(0.0, 1.8, 0.0),
        pins: PinRule::TopCorners,
        params: SimParams::default(),
        effects: cloth_forces(),
    }
}

fn sphere_drop() -> ScenarioSetup {
    let mut effects = cloth_forces();
    effects.push(Effect::Collider(Collider::Sphere {
        center: SPHERE_CENTER,
        radius: SPHERE_RADIUS,
        spin: Vec3::ZERO,
        friction: 0.5,
    }));
    effects.push(ground());
    ScenarioSetup {
        orientation: GridOrientation::Horizontal,
        center: Vec3::new(0.0, 1.3, 0.0),
        pins: PinRule::None,
        params: SimParams::default(),
        effects,
    }
}

fn rotating_sphere() -> ScenarioSetup {
    let mut effects = cloth_forces();
    effects.push(Effect::Collider(Collider::Sphere {
        center: SPHERE_CENTER,
        radius: SPHERE_RADIUS,
        spin: Vec3::new(0.0, 2.0, 0.0),
        friction: 0.6,
    }));
    effects.push(ground());
    ScenarioSetup {
        orientation: GridOrientation::Horizontal,
        // Just above the sphere's top: the cloth settles onto it and is carried round.
        center: SPHERE_CENTER + Vec3::new(0.0, SPHERE_RADIUS + 0.03, 0.0),
        pins: PinRule::None,
        params: SimParams::default(),
        effects,
    }
}

/// All built-in scenarios, in menu order.
pub static SCENARIOS: &[Scenario] = &[
    Scenario {
        name: "hanging",
        summary: "a cloth held by two corners swings down and hangs",
        setup: hanging,
    },
    Scenario {
        name: "sphere-drop",
        summary: "a cloth falls onto a static sphere and drapes over it",
        setup: sphere_drop,
    },
    Scenario {
        name: "rotating-sphere",
        summary: "a cloth rests on a sphere spinning at 2 rad/s and is dragged round by friction",
        setup: rotating_sphere,
    },
];

/// Looks a scenario up by name.
pub fn scenario(name: &str) -> Option<&'static Scenario> {
    SCENARIOS.iter().find(|s| s.name == name)
}
