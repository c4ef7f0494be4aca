//! `clothsim scenes`: the built-in scenes, or what scene files hold.

use std::path::PathBuf;

use anyhow::Result;

use clothsim::scene::Scene;

/// The effects of a scene file, in words.
fn describe(file: &clothsim::scene::SceneFile) -> String {
    let effects: Vec<&str> = file.effects().iter().map(|e| e.phase()).collect();
    format!("{} [{}]", file.summary, effects.join(", "))
}

/// Lists the built-in scenes, or checks `files` and lists what they hold.
pub fn scenes(files: &[PathBuf]) -> Result<()> {
    if files.is_empty() {
        for s in clothsim::scene::scenarios() {
            println!("{:<16} {}", s.name, describe(s));
        }
        return Ok(());
    }
    for path in files {
        let loaded = clothsim::scene::SceneFile::load(path)?;
        // Building it checks the cloth and the pins too.
        let scene = Scene::from_loaded(&loaded)?;
        println!(
            "{}: {} — {} particles, {}",
            path.display(),
            loaded.file.name,
            scene.model.particle_count(),
            describe(&loaded.file)
        );
    }
    Ok(())
}
