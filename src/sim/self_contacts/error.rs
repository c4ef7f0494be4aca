//! What self-contact refuses.

/// A state contact detection cannot bin.
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
    #[error("self-collision handles at most {most} triangles; this cloth has {triangles}")]
    TooMany { triangles: usize, most: usize },
}
