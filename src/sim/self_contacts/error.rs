//! What self-contact refuses.

/// A state self-contact refuses: one it cannot bin, or one blown up past the guard's limits.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    #[error("particle {particle} has a non-finite position")]
    NonFinite { particle: usize },
    #[error(
        "triangle {triangle} spans {extent:.3e} m, more than a million times the cloth's \
         cell of {cell:.3e} m: the state has blown up"
    )]
    Extent {
        triangle: usize,
        extent: f32,
        cell: f32,
    },
    #[error(
        "a spring stretched by {:.0} % (limit {:.0} %), and {pairs} pairs for {particles} \
         particles to keep apart: the state has blown up",
        100.0 * strain,
        100.0 * limit
    )]
    Stretched {
        strain: f32,
        limit: f32,
        pairs: usize,
        particles: usize,
    },
    #[error("self-collision handles at most {most} triangles; this cloth has {triangles}")]
    TooMany { triangles: usize, most: usize },
}
