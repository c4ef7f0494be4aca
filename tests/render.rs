//! Rendering on the software adapter: golden images, capture geometry, PNG output errors.
//!
//! Goldens live in `tests/golden/`. On a mismatch the test writes `NAME.new.png` and
//! `NAME.diff.png` beside the golden; rerun with `UPDATE_GOLDEN=1` to accept new images.

use std::path::{Path, PathBuf};

use glam::Vec3;

use clothsim::device::AdapterPreference;
use clothsim::render::{
    CLEAR_COLOR, Offscreen, OrbitCamera, RenderError, RenderOptions, RgbaImage, save_png,
};
use clothsim::scene::{Scene, Simulation};
use clothsim::sim::Effect;
use clothsim::view;

/// Draws `sim` with its scene's default camera.
fn render_default(off: &mut Offscreen, sim: &Simulation, options: &RenderOptions) -> RgbaImage {
    let camera = view::default_camera(sim, off.aspect());
    off.render(&view::frame(sim), &camera, options).unwrap()
}

/// Golden size: the width is a multiple of 64 so rows need no copy padding on any backend.
const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

/// Mean absolute difference per channel (0–255) a golden may drift by. llvmpipe renders
/// these scenes bit-identically run to run on one machine (measured: 0.0); edges of
/// triangles and 1-px lines may move by a pixel between Mesa versions, which on these
/// images costs well under 1.0, while a real change (a missing overlay, a wrong light, a
/// moved cloth) costs several units.
const MEAN_TOLERANCE: f64 = 1.0;

fn offscreen() -> Offscreen {
    Offscreen::new(WIDTH, HEIGHT, AdapterPreference::Software)
        .expect("the software adapter (Mesa llvmpipe) must be available")
}

fn simulate(name: &str, seconds: f64) -> Simulation {
    let mut sim = Simulation::new(Scene::builtin(name).unwrap());
    sim.run(seconds);
    sim
}

fn golden_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"))
}

fn mean_difference(a: &RgbaImage, b: &RgbaImage) -> f64 {
    let total: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y) as u64)
        .sum();
    total as f64 / a.as_raw().len() as f64
}

fn check_golden(name: &str, image: &RgbaImage) {
    let path = golden_path(name);
    if std::env::var_os("UPDATE_GOLDEN").is_some() {
        image.save(&path).unwrap();
        return;
    }
    let golden = match image::open(&path) {
        Ok(g) => g.to_rgba8(),
        Err(e) => panic!(
            "{}: cannot open golden ({e}); run with UPDATE_GOLDEN=1 to create it",
            path.display()
        ),
    };
    assert_eq!(
        golden.dimensions(),
        image.dimensions(),
        "{name}: size changed; UPDATE_GOLDEN=1 accepts it"
    );
    let diff = mean_difference(&golden, image);
    if diff > MEAN_TOLERANCE {
        let new = path.with_extension("new.png");
        image.save(&new).unwrap();
        let diff_image = RgbaImage::from_fn(image.width(), image.height(), |x, y| {
            let (p, q) = (image.get_pixel(x, y), golden.get_pixel(x, y));
            let d = |i: usize| p[i].abs_diff(q[i]).saturating_mul(4);
            image::Rgba([d(0), d(1), d(2), 255])
        });
        diff_image.save(path.with_extension("diff.png")).unwrap();
        panic!(
            "{name}: mean difference {diff:.3} > {MEAN_TOLERANCE}; wrote {} and its .diff.png. \
             If the change is intended, rerun with UPDATE_GOLDEN=1 to accept it.",
            new.display()
        );
    }
}

#[test]
fn golden_scenarios() {
    let mut off = offscreen();
    for (name, seconds) in [
        ("hanging", 4.0),
        ("sphere-drop", 1.5),
        ("rotating-sphere", 1.0),
        ("tablecloth", 1.5),
    ] {
        let sim = simulate(name, seconds);
        let image = render_default(&mut off, &sim, &RenderOptions::default());
        check_golden(name, &image);
    }
}

#[test]
fn golden_every_overlay() {
    let mut off = offscreen();
    let sim = simulate("hanging", 0.5);
    let options = RenderOptions::default()
        .with_overlays("springs,bend,particles,wireframe")
        .unwrap();
    let image = render_default(&mut off, &sim, &options);
    check_golden("hanging-overlays", &image);
}

fn pixel(image: &RgbaImage, x: f32, y: f32) -> [u8; 4] {
    image.get_pixel(x as u32, y as u32).0
}

fn background() -> [u8; 3] {
    [CLEAR_COLOR.r, CLEAR_COLOR.g, CLEAR_COLOR.b].map(|c| (c * 255.0).round() as u8)
}

fn is_background(p: [u8; 4]) -> bool {
    p.iter().zip(background()).all(|(a, b)| a.abs_diff(b) <= 2)
}

#[test]
fn cloth_pixels_are_where_the_camera_says() {
    let mut off = offscreen();
    // sphere-drop starts with a flat 1 m cloth at y = 1.3, its front (+y) side up.
    let sim = Simulation::new(Scene::builtin("sphere-drop").unwrap());
    let centre = Vec3::new(0.0, 1.3, 0.0);
    let above = OrbitCamera {
        target: centre,
        yaw: 0.0,
        pitch: 1.2,
        distance: 3.0,
        ..OrbitCamera::default()
    };
    let options = RenderOptions {
        checker: false,
        colliders: false,
        ..RenderOptions::default()
    };
    let image = off.render(&view::frame(&sim), &above, &options).unwrap();
    let (cx, cy) = above.project(centre, WIDTH, HEIGHT).unwrap();
    let front = pixel(&image, cx, cy);
    assert!(
        front[0] as i32 > front[2] as i32 + 60,
        "centre should show the red front side, got {front:?}"
    );
    assert!(
        is_background(pixel(&image, 2.0, 2.0)),
        "corner should be background"
    );
    // Just beyond the cloth's edge (x = 0.5 m) there is background again.
    let (ox, oy) = above
        .project(centre + Vec3::new(0.6, 0.0, 0.0), WIDTH, HEIGHT)
        .unwrap();
    assert!(is_background(pixel(&image, ox, oy)));
    let (ix, iy) = above
        .project(centre + Vec3::new(0.4, 0.0, 0.0), WIDTH, HEIGHT)
        .unwrap();
    assert!(
        !is_background(pixel(&image, ix, iy)),
        "just inside the edge is cloth"
    );
    // Seen from below, the same spot shows the yellow back side (in shadow: the key light is
    // above, so only the ambient term lights it).
    let below = OrbitCamera {
        pitch: -1.2,
        ..above
    };
    let back = off.render(&view::frame(&sim), &below, &options).unwrap();
    let p = pixel(&back, cx, cy);
    assert!(
        p[1] as i32 > p[2] as i32 + 25 && p[0] as i32 > p[2] as i32 + 25,
        "back side should be yellow, got {p:?}"
    );
    // Hue: on the red front green is far below red; on the yellow back it nearly matches it.
    assert!(
        (front[1] as f32) < 0.6 * front[0] as f32,
        "front {front:?} should be red"
    );
    assert!(
        p[1] as f32 > 0.8 * p[0] as f32,
        "back {p:?} should be yellow"
    );
}

#[test]
fn overlays_change_the_image() {
    let mut off = offscreen();
    let sim = simulate("hanging", 0.3);
    let plain = render_default(&mut off, &sim, &RenderOptions::default());
    for overlay in ["springs", "strain", "particles", "wireframe"] {
        let options = RenderOptions::default().with_overlays(overlay).unwrap();
        let image = render_default(&mut off, &sim, &options);
        let changed = plain
            .pixels()
            .zip(image.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert!(changed > 500, "{overlay}: only {changed} pixels changed");
    }
    assert!(RenderOptions::default().with_overlays("sparkles").is_err());
}

#[test]
fn sphere_is_visible_in_sphere_drop() {
    let mut off = offscreen();
    let sim = Simulation::new(Scene::builtin("sphere-drop").unwrap());
    let camera = view::default_camera(&sim, off.aspect());
    let image = off
        .render(&view::frame(&sim), &camera, &RenderOptions::default())
        .unwrap();
    let sphere = (sim.effects().iter())
        .find_map(|e| match e {
            Effect::Sphere(s) => Some((s.center, s.radius)),
            _ => None,
        })
        .unwrap();
    // The point of the sphere's equator that faces the camera.
    let towards_eye = (camera.eye() - sphere.0) * Vec3::new(1.0, 0.0, 1.0);
    let p = sphere.0 + sphere.1 * 0.9 * towards_eye.normalize();
    let (x, y) = camera.project(p, WIDTH, HEIGHT).unwrap();
    let px = pixel(&image, x, y);
    assert!(
        px[2] as i32 > px[0] as i32 + 25,
        "sphere should be blue there, got {px:?}"
    );
    // Without colliders drawn, that pixel is ground or background, not blue sphere.
    let options = RenderOptions {
        colliders: false,
        ..RenderOptions::default()
    };
    let bare = off.render(&view::frame(&sim), &camera, &options).unwrap();
    assert!(is_background(pixel(&bare, x, y)));
}

#[test]
fn unwritable_output_is_an_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let image = RgbaImage::from_pixel(64, 8, image::Rgba([10, 20, 30, 255]));
    let missing = dir.path().join("no/such/dir/out.png");
    assert!(matches!(
        save_png(&image, &missing),
        Err(RenderError::MissingDirectory { .. })
    ));
    assert!(!missing.exists());
    // A directory in the way of the file name: the rename fails, the temp file is removed.
    let blocked = dir.path().join("taken.png");
    std::fs::create_dir(&blocked).unwrap();
    std::fs::write(blocked.join("keep"), b"x").unwrap();
    let err = save_png(&image, &blocked).unwrap_err();
    assert!(matches!(err, RenderError::Write { .. }), "{err}");
    assert!(err.to_string().contains("taken.png"));
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        leftovers,
        vec![std::ffi::OsString::from("taken.png")],
        "no temp file left"
    );
    // And a good path works and round-trips.
    let good = dir.path().join("ok.png");
    save_png(&image, &good).unwrap();
    assert_eq!(image::open(&good).unwrap().to_rgba8(), image);
}

#[test]
fn row_padding_is_stripped() {
    use clothsim::render::{padded_bytes_per_row, strip_row_padding};
    let (w, h) = (3u32, 2u32);
    let padded = padded_bytes_per_row(w);
    assert_eq!(padded, 256);
    let mut data = vec![0xEEu8; (padded * h) as usize];
    for r in 0..h as usize {
        for i in 0..(w * 4) as usize {
            data[r * padded as usize + i] = (r * 100 + i) as u8;
        }
    }
    let out = strip_row_padding(&data, w, h, padded);
    assert_eq!(out.len(), 24);
    assert_eq!(out[12], 100);
    assert!(!out.contains(&0xEE));
}

#[test]
fn the_target_resizes_and_rejects_impossible_sizes() {
    use clothsim::render::RenderTarget;
    let mut off = offscreen();
    let device = off.gpu.device.clone();
    assert!(
        !off.target.resize(&device, WIDTH, HEIGHT).unwrap(),
        "same size: nothing to do"
    );
    assert!(off.target.resize(&device, 128, 64).unwrap());
    assert_eq!(off.target.size(), (128, 64));
    let sim = Simulation::new(Scene::builtin("sphere-drop").unwrap());
    let image = render_default(&mut off, &sim, &RenderOptions::default());
    assert_eq!(image.dimensions(), (128, 64));
    assert!(
        image.pixels().any(|p| !is_background(p.0)),
        "the scene is drawn at the new size"
    );
    let samples = off.target.sample_count();
    assert!(matches!(
        RenderTarget::new(&device, 0, 64, samples),
        Err(RenderError::BadSize { .. })
    ));
    assert!(matches!(
        off.target.resize(&device, 64, 0),
        Err(RenderError::BadSize { .. })
    ));
}

/// Pixels that differ from the background.
fn cloth_mask(image: &RgbaImage) -> Vec<bool> {
    image.pixels().map(|p| !is_background(p.0)).collect()
}

/// Story: the default camera used to frame a loose box around the start pose, so a swinging
/// `hanging` cloth covered under 2 % of a 640×384 picture, in its top corner. It now frames
/// where the cloth goes: over four seconds of swinging the cloth never leaves the picture,
/// and it fills a good part of it.
#[test]
fn the_default_camera_keeps_the_swinging_cloth_in_view_and_large() {
    let (w, h) = (640u32, 384u32);
    let mut off = Offscreen::new(w, h, AdapterPreference::Software).unwrap();
    let mut sim = Simulation::new(Scene::builtin("hanging").unwrap());
    let camera = view::default_camera(&sim, off.aspect());
    let options = RenderOptions {
        colliders: false,
        ..RenderOptions::default()
    };
    let (mut largest, mut top, mut bottom) = (0.0f64, h, 0u32);
    for quarter in 1..=16 {
        while sim.state().time < 0.25 * quarter as f64 - 1e-6 {
            sim.step_frame().unwrap();
        }
        let image = off.render(&view::frame(&sim), &camera, &options).unwrap();
        let mask = cloth_mask(&image);
        let at = |x: u32, y: u32| mask[(y * w + x) as usize];
        let t = sim.state().time;
        let border =
            (0..w).any(|x| at(x, 0) || at(x, h - 1)) || (0..h).any(|y| at(0, y) || at(w - 1, y));
        assert!(
            !border,
            "t = {t:.2} s: the cloth touches the edge of the picture"
        );
        let covered = mask.iter().filter(|&&m| m).count() as f64 / mask.len() as f64;
        largest = largest.max(covered);
        for y in (0..h).filter(|&y| (0..w).any(|x| at(x, y))) {
            top = top.min(y);
            bottom = bottom.max(y);
        }
    }
    assert!(
        largest > 0.15,
        "the cloth covers at most {:.1} % of the picture",
        100.0 * largest
    );
    let span = (bottom - top) as f64 / h as f64;
    assert!(
        span > 0.6,
        "over its motion the cloth spans only {:.0} % of the height",
        100.0 * span
    );
}
