//! The performance matrix of `clothsim bench` under criterion: one substep of the
//! `hanging-bench` cloth per size × integrator × thread count (and the GPU backend, when an
//! adapter is there). Substeps are timed from the state after one simulated frame, so the
//! cloth is moving. `cargo bench --bench bench_scene` (add `-- 'sie/64'` to pick rows).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

use clothsim::bench::bench_scene;
use clothsim::scene::Simulation;
use clothsim::sim::IntegratorKind;

fn matrix(c: &mut Criterion) {
    let kinds = [
        ("sie", IntegratorKind::SemiImplicitEuler),
        ("implicit", IntegratorKind::ImplicitEuler),
        ("xpbd", IntegratorKind::Xpbd),
        ("vbd", IntegratorKind::Vbd),
    ];
    for threads in [1usize, 2] {
        let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(threads).build() else {
            continue;
        };
        let mut group = c.benchmark_group(format!("hanging-bench/{threads}-threads"));
        group.sample_size(20);
        for (name, kind) in kinds {
            for n in [32u32, 64, 128] {
                let Ok(scene) = bench_scene(n, kind) else {
                    continue;
                };
                let mut sim = Simulation::new(scene);
                pool.install(|| {
                    let _ = sim.step_frame();
                });
                group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                    // Iterated on the pool: handing each substep to it would time the handoff.
                    pool.install(|| b.iter(|| sim.substep()))
                });
            }
        }
        group.finish();
    }
    let mut group = c.benchmark_group("hanging-bench/gpu");
    group.sample_size(20);
    for n in [32u32, 64, 128] {
        let Ok(scene) = bench_scene(n, IntegratorKind::SemiImplicitEuler) else {
            continue;
        };
        let Ok((mut sim, _)) = clothsim::gpu::gpu_simulation(scene, false) else {
            // No adapter with compute: nothing to time.
            return;
        };
        // One frame per iteration (one submission), waited for.
        group.bench_with_input(BenchmarkId::new("sie-frame", n), &n, |b, _| {
            b.iter(|| {
                let _ = sim.step_frame();
                let _ = sim.sync_state();
            })
        });
    }
    group.finish();
}

criterion_group!(benches, matrix);
criterion_main!(benches);
