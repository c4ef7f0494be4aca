//! The one-way floors of the design, checked on the source: the renderer draws plain data and
//! imports neither the simulation nor the scenes; the simulation, the cloth and the mesh know
//! nothing of graphics or windows.

use std::path::Path;

/// Every `.rs` file under `src/<dir>`, with its text.
fn sources(dir: &str) -> Vec<(String, String)> {
    fn walk(path: &Path, out: &mut Vec<(String, String)>) {
        for entry in std::fs::read_dir(path).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                out.push((path.display().to_string(), text));
            }
        }
    }
    let mut out = Vec::new();
    walk(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(dir),
        &mut out,
    );
    assert!(!out.is_empty(), "no sources under src/{dir}");
    out
}

/// Lines of code (not comments) in `dir` that mention any of `words`.
fn offending_lines(dir: &str, words: &[&str]) -> Vec<String> {
    sources(dir)
        .into_iter()
        .flat_map(|(file, text)| {
            text.lines()
                .enumerate()
                .filter(|(_, l)| !l.trim_start().starts_with("//"))
                .filter(|(_, l)| words.iter().any(|w| l.contains(w)))
                .map(|(n, l)| format!("{file}:{}: {}", n + 1, l.trim()))
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn the_renderer_imports_neither_sim_nor_scene() {
    let bad = offending_lines(
        "render",
        &[
            "crate::sim",
            "crate::scene",
            "super::super::sim",
            "super::super::scene",
        ],
    );
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn sim_cloth_and_mesh_use_no_graphics_or_window_crate() {
    for dir in ["sim", "cloth", "mesh"] {
        let bad = offending_lines(dir, &["wgpu", "egui", "eframe", "winit"]);
        assert!(bad.is_empty(), "{}", bad.join("\n"));
    }
}
