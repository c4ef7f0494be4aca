// The cloth as every compute shader of the GPU backend reads it (prepended to them when
// their pipelines are built): a particle's state and a spring end. The constants are the
// host's (src/gpu/packing.rs; a test compares them).

// Low bits of a spring end's `other` that hold its strength class.
const CLASS_BITS: u32 = 4u;
// Strength classes the table holds: 1 << CLASS_BITS.
const CLASSES: u32 = 16u;

struct Particle {
    // xyz: position (m); w: inverse mass (1/kg), 0 for a pinned particle.
    x: vec4<f32>,
    // xyz: velocity (m/s).
    v: vec4<f32>,
}

struct Neighbour {
    // Low CLASS_BITS bits: the strength class; the bits above: the other end's index.
    other: u32,
    // Rest length (m).
    rest: f32,
}
