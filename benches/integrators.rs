//! Time per step of every integrator on the `hanging` scene with square grid cloths of
//! 32², 64² and 128² particles: one criterion group per integrator, one benchmark per size.

use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

use clothsim::mesh::{GridOrientation, GridSpec, MeshBuild};
use clothsim::scene::{Scene, Simulation};
use clothsim::sim::IntegratorKind;

/// A square grid with `n × n` particles.
fn grid(n: u32) -> MeshBuild {
    GridSpec::square(n - 1, 1.0, GridOrientation::Horizontal, glam::Vec3::ZERO)
        .build()
        .expect("valid grid")
        .into()
}

/// Steps taken from one start before it is restored (untimed): long enough to keep the
/// integrators' kept values warm, short enough that an explicit method at a step beyond
/// its limit does not reach NaN (whose arithmetic would time differently).
const RESTART_EVERY: u64 = 20;

fn step(c: &mut Criterion) {
    for kind in IntegratorKind::ALL {
        let mut group = c.benchmark_group(format!("step/{}", kind.name()));
        group.sample_size(10);
        for n in [32u32, 64, 128] {
            let mut scene = Scene::with_cloth("hanging", &grid(n), "grid").expect("registered");
            scene.params.step.integrator = kind;
            let mut sim = Simulation::new(scene);
            // Start from a swinging state rather than the rest pose.
            for _ in 0..10 {
                sim.substep().expect("a step");
            }
            let start = sim.state().clone();
            group.bench_with_input(BenchmarkId::from_parameter(n * n), &n, |b, _| {
                b.iter_custom(|iters| {
                    let mut total = Duration::ZERO;
                    for i in 0..iters {
                        if i % RESTART_EVERY == 0 {
                            sim.modify_state(|s| s.clone_from(&start));
                        }
                        let t = Instant::now();
                        let _ = sim.substep();
                        total += t.elapsed();
                    }
                    total
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, step);
criterion_main!(benches);
