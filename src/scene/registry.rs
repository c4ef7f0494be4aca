//! The built-in scenes: TOML files in `assets/scenes/`, embedded in the binary and loaded by
//! the same code as any scene file. One table feeds the GUI, the CLI, the tests and the
//! benches.

use std::sync::OnceLock;

use super::file::SceneFile;

/// Name and text of every built-in scene, in menu order.
pub static BUILTIN_SCENES: &[(&str, &str)] = &[
    ("hanging", include_str!("../../assets/scenes/hanging.toml")),
    (
        "sphere-drop",
        include_str!("../../assets/scenes/sphere-drop.toml"),
    ),
    (
        "rotating-sphere",
        include_str!("../../assets/scenes/rotating-sphere.toml"),
    ),
    ("flag", include_str!("../../assets/scenes/flag.toml")),
    (
        "self-fold",
        include_str!("../../assets/scenes/self-fold.toml"),
    ),
    (
        "tablecloth",
        include_str!("../../assets/scenes/tablecloth.toml"),
    ),
    (
        "carousel",
        include_str!("../../assets/scenes/carousel.toml"),
    ),
    ("twist", include_str!("../../assets/scenes/twist.toml")),
    ("arm", include_str!("../../assets/scenes/arm.toml")),
    ("crumple", include_str!("../../assets/scenes/crumple.toml")),
    ("layers", include_str!("../../assets/scenes/layers.toml")),
    (
        "fast-fold",
        include_str!("../../assets/scenes/fast-fold.toml"),
    ),
    (
        "hanging-bench",
        include_str!("../../assets/scenes/hanging-bench.toml"),
    ),
    ("orders", include_str!("../../assets/scenes/orders.toml")),
];

/// One frame of the arm's OBJ sequence, by its number, as a built-in mesh.
macro_rules! arm_frame {
    ($number:literal) => {
        (
            concat!("arm/arm_", $number, ".obj"),
            include_str!(concat!("../../assets/meshes/arm/arm_", $number, ".obj")),
        )
    };
}

/// Name and text of every mesh the built-in scenes' obstacles use (`obj = "…"` in a built-in
/// scene names one of these); written by `assets/meshes/generate.py`.
pub static BUILTIN_MESHES: &[(&str, &str)] = &[
    ("table.obj", include_str!("../../assets/meshes/table.obj")),
    (
        "turntable.obj",
        include_str!("../../assets/meshes/turntable.obj"),
    ),
    arm_frame!("0000"),
    arm_frame!("0001"),
    arm_frame!("0002"),
    arm_frame!("0003"),
    arm_frame!("0004"),
    arm_frame!("0005"),
    arm_frame!("0006"),
    arm_frame!("0007"),
    arm_frame!("0008"),
    arm_frame!("0009"),
    arm_frame!("0010"),
    arm_frame!("0011"),
    arm_frame!("0012"),
    arm_frame!("0013"),
    arm_frame!("0014"),
    arm_frame!("0015"),
];

/// The text of a built-in mesh by its name.
pub fn builtin_mesh(name: &std::path::Path) -> Option<&'static str> {
    (BUILTIN_MESHES.iter())
        .find(|(n, _)| std::path::Path::new(n) == name)
        .map(|(_, text)| *text)
}

/// The built-in scenes, parsed once. They are part of the program and checked by the test
/// suite (`every_builtin_scene_file_parses`), so parsing them cannot fail at run time.
pub fn scenarios() -> &'static [SceneFile] {
    static PARSED: OnceLock<Vec<SceneFile>> = OnceLock::new();
    PARSED.get_or_init(|| {
        BUILTIN_SCENES
            .iter()
            .map(|(name, text)| {
                let path = std::path::PathBuf::from(format!("assets/scenes/{name}.toml"));
                SceneFile::parse(text, &path)
                    .unwrap_or_else(|e| unreachable!("built-in scene is invalid: {e}"))
            })
            .collect()
    })
}

/// A built-in scene by name.
pub fn scenario(name: &str) -> Option<&'static SceneFile> {
    scenarios().iter().find(|s| s.name == name)
}
