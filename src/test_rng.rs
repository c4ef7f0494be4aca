//! Deterministic pseudo-random numbers for unit tests.

/// Numbers in [0, 1) from a 64-bit linear congruential generator seeded with `seed`.
pub fn uniform(mut seed: u64) -> impl FnMut() -> f32 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Vectors with each coordinate in [−scale, scale), from [`uniform`] seeded with `seed`.
pub fn jitter(seed: u64) -> impl FnMut(f32) -> glam::Vec3 {
    let mut unit = uniform(seed);
    move |scale| {
        let mut coordinate = || (2.0 * unit() - 1.0) * scale;
        glam::Vec3::new(coordinate(), coordinate(), coordinate())
    }
}
