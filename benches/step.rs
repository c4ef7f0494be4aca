//! Cost of one simulation frame, per scenario × integrator × cloth resolution.
//! Built from the scenario registry, so a new scenario or integrator is benchmarked too.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

use clothsim::mesh::{GridOrientation, GridSpec, MeshBuild};
use clothsim::scene::{Scene, Simulation, scenarios};
use clothsim::sim::IntegratorKind;

/// A square grid with `n × n` particles.
fn grid(n: u32) -> MeshBuild {
    GridSpec::square(n - 1, 1.0, GridOrientation::Horizontal, glam::Vec3::ZERO)
        .build()
        .expect("valid grid")
        .into()
}

fn frame(c: &mut Criterion) {
    // The bench scene has its own matrix (benches/bench_scene.rs).
    for scenario in scenarios()
        .iter()
        .filter(|s| s.name != clothsim::bench::BENCH_SCENE)
    {
        let mut group = c.benchmark_group(format!("frame/{}", scenario.name));
        group.sample_size(10);
        for kind in IntegratorKind::ALL {
            for n in [25u32, 50, 100] {
                let mut scene =
                    Scene::with_cloth(&scenario.name, &grid(n), "grid").expect("registered");
                scene.params.step.integrator = kind;
                let mut sim = Simulation::new(scene);
                // Start from a moving, colliding state rather than the rest pose.
                sim.run(0.25);
                group.bench_with_input(BenchmarkId::new(kind.name(), n * n), &n, |b, _| {
                    b.iter(|| sim.step_frame().expect("stable"))
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, frame);
criterion_main!(benches);
