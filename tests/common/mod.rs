//! What the GPU test files share.

/// The largest distance between the same particle in `a` and `b`, metres.
pub fn farthest(a: &[glam::Vec3], b: &[glam::Vec3]) -> f32 {
    (a.iter().zip(b))
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

/// `scene` on the CPU and on the GPU (the software adapter): `frames` frames, then every
/// particle pushed sideways at 0.5 m/s (an outside change), then one frame more; how far
/// apart the two cloths end, metres.
#[allow(dead_code)] // Not every GPU test file pushes.
pub fn apart_after_a_push(scene: clothsim::scene::Scene, frames: usize) -> f32 {
    let mut cpu = clothsim::scene::Simulation::new(scene.clone());
    let (mut gpu, _) = clothsim::gpu::gpu_simulation(scene, true).expect("GPU backend");
    for sim in [&mut cpu, &mut gpu] {
        for _ in 0..frames {
            sim.step_frame().expect("frame");
        }
        sim.sync_state().expect("read back");
        sim.modify_state(|s| s.vel.iter_mut().for_each(|v| v.z += 0.5));
        sim.step_frame().expect("frame");
    }
    farthest(&cpu.state().pos, &gpu.state().pos)
}
