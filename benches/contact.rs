//! Cost of one frame of a 64 × 64 cloth resting on a mesh sphere of about 1 000 and of
//! about 100 000 triangles (the scene of `clothsim bench --obstacles`, which times the
//! obstacle phase alone against the springs). The tree over the triangles keeps the larger
//! obstacle's frame from growing with its triangles. And one frame of `crumple` folding onto
//! itself (the scene of `clothsim bench --crumple`).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

use clothsim::bench_contact::{CONTACT_TRIANGLES, contact_scene};

fn resting(c: &mut Criterion) {
    let mut group = c.benchmark_group("contact/frame");
    group.sample_size(10);
    for triangles in CONTACT_TRIANGLES {
        // Built in the closure, which runs only where the bench is asked for: settling the
        // larger scene takes minutes.
        group.bench_with_input(
            BenchmarkId::new("sphere", triangles),
            &triangles,
            |b, &n| {
                let mut sim = contact_scene(n).expect("the bench scene builds and settles");
                b.iter(|| sim.step_frame().expect("stable"))
            },
        );
    }
    group.finish();
}

/// One frame of `crumple` at 32 × 32 quads as it lands in folds (its 41st, from the same
/// state every time, the solver's buffers warm): the self-contact pass, its recheck and the
/// solids against the rest of the step.
fn crumpling(c: &mut Criterion) {
    let mut group = c.benchmark_group("contact/crumple");
    group.sample_size(10);
    let scene = clothsim::scene::Scene::open_resized(
        "crumple",
        None,
        &clothsim::mesh::ImportOptions::default(),
        Some(32),
    )
    .expect("the built-in scene builds");
    let mut sim = clothsim::scene::Simulation::new(scene);
    for _ in 0..40 {
        sim.step_frame().expect("stable");
    }
    let (landing, frames) = (sim.state().clone(), sim.frames());
    group.bench_function("frame-32", |b| {
        b.iter_custom(|iters| {
            let mut total = std::time::Duration::ZERO;
            for _ in 0..iters {
                sim.adopt_state(&landing, frames);
                let start = std::time::Instant::now();
                sim.step_frame().expect("stable");
                total += start.elapsed();
            }
            total
        });
    });
    group.finish();
}

criterion_group!(benches, resting, crumpling);
criterion_main!(benches);
