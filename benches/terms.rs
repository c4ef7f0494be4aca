//! Cost of one evaluation of the force terms that go a triangle or a hinge at a time (the
//! dihedral hinges and the wind) on a bent, moving cloth, in `f32` (their SIMD lanes) and
//! in `f64` (one at a time), beside the springs of the same cloth.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::{DVec3, Vec3};

use clothsim::cloth::ClothModel;
use clothsim::mesh::{GridOrientation, GridSpec};
use clothsim::sim::forces::{DihedralBending, ForceTerm, SpringForce};
use clothsim::sim::{Wind, WindForce};

/// An `n × n`-particle cloth, 1 m wide, standing like a flag, and a bent, moving state of
/// it (a ripple along it, the velocities of a wave).
fn cloth(n: u32) -> (ClothModel, Vec<Vec3>, Vec<Vec3>) {
    let mesh = GridSpec::square(n - 1, 1.0, GridOrientation::Vertical, Vec3::ZERO)
        .build()
        .expect("valid grid");
    let model = ClothModel::new(&mesh, 0.15, &[]);
    let pos = (model.rest_positions.iter())
        .map(|p| *p + Vec3::Z * (0.05 * (9.0 * p.x).sin() * (5.0 * p.y).cos()))
        .collect();
    let vel = (model.rest_positions.iter())
        .map(|p| Vec3::new(0.3, 0.1, (9.0 * p.x).cos()))
        .collect();
    (model, pos, vel)
}

fn terms(c: &mut Criterion) {
    let mut group = c.benchmark_group("terms");
    group.sample_size(20);
    let wind = Wind {
        velocity: Vec3::new(6.0, 0.0, 0.0),
        ..Wind::default()
    };
    for n in [32u32, 64, 128] {
        let (model, pos, vel) = cloth(n);
        let (dpos, dvel): (Vec<DVec3>, Vec<DVec3>) = (
            pos.iter().map(|p| p.as_dvec3()).collect(),
            vel.iter().map(|v| v.as_dvec3()).collect(),
        );
        let bending = DihedralBending::new(&model, 0.001);
        let wind = WindForce::new(wind, &model);
        let springs = SpringForce::new(&model.springs, [400.0, 150.0, 20.0], [0.02, 0.01, 0.002]);
        let mut f = vec![Vec3::ZERO; pos.len()];
        let mut df = vec![DVec3::ZERO; pos.len()];
        let id = |name: &str| BenchmarkId::new(name, n * n);
        group.bench_function(id("dihedral-f32"), |b| {
            b.iter(|| bending.add_forces::<f32>(&model, &pos, &mut f))
        });
        group.bench_function(id("dihedral-f64"), |b| {
            b.iter(|| bending.add_forces::<f64>(&model, &dpos, &mut df))
        });
        group.bench_function(id("wind-f32"), |b| {
            b.iter(|| ForceTerm::<f32>::add_forces(&wind, &model, &pos, &vel, 1.0, &mut f))
        });
        group.bench_function(id("wind-f64"), |b| {
            b.iter(|| ForceTerm::<f64>::add_forces(&wind, &model, &dpos, &dvel, 1.0, &mut df))
        });
        group.bench_function(id("springs-f32"), |b| {
            b.iter(|| ForceTerm::<f32>::add_forces(&springs, &model, &pos, &vel, 1.0, &mut f))
        });
    }
    group.finish();
}

criterion_group!(benches, terms);
criterion_main!(benches);
