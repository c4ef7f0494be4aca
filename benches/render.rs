//! Frame time of the renderer: a 100 × 100-particle cloth with every overlay at 1280 × 720
//! on the software adapter (Mesa llvmpipe on a machine without GPU), including readback.

use criterion::{Criterion, criterion_group, criterion_main};

use clothsim::device::AdapterPreference;
use clothsim::mesh::{GridOrientation, GridSpec, MeshBuild};
use clothsim::render::{Offscreen, RenderOptions};
use clothsim::scene::{Scene, Simulation};
use clothsim::view;

fn render(c: &mut Criterion) {
    let mesh = GridSpec::square(99, 1.0, GridOrientation::Horizontal, glam::Vec3::ZERO)
        .build()
        .expect("valid grid");
    let scene = Scene::with_cloth("sphere-drop", &MeshBuild::from(mesh), "grid 100x100")
        .expect("registered");
    let mut sim = Simulation::new(scene);
    sim.run(1.0);
    let mut off = Offscreen::new(1280, 720, AdapterPreference::Software).expect("software adapter");
    let camera = view::default_camera(&sim, off.aspect());
    let mut group = c.benchmark_group("render/1280x720/100x100");
    group.sample_size(10);
    for (name, overlays) in [
        ("mesh", ""),
        ("all-overlays", "springs,bend,particles,wireframe"),
    ] {
        let options = RenderOptions::default()
            .with_overlays(overlays)
            .expect("known overlays");
        group.bench_function(name, |b| {
            b.iter(|| {
                off.render(&view::frame(&sim), &camera, &options)
                    .expect("render")
            })
        });
    }
    // Draw only (no readback): what the GUI pays per frame.
    let options = RenderOptions::default()
        .with_overlays("springs,bend,particles,wireframe")
        .expect("known");
    group.bench_function("all-overlays-no-readback", |b| {
        b.iter(|| {
            let frame = view::frame(&sim);
            off.renderer.render(
                &off.gpu.device,
                &off.gpu.queue,
                &off.target,
                &camera,
                &frame,
                &options,
            );
            off.gpu
                .device
                .poll(wgpu::PollType::wait_indefinitely())
                .expect("poll");
        })
    });
    group.finish();
}

criterion_group!(benches, render);
criterion_main!(benches);
