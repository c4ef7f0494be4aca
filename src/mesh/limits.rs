//! The limits import enforces before it reads or allocates anything large.

/// Largest OBJ file read, bytes (256 MiB).
pub const MAX_FILE_BYTES: u64 = 256 * 1024 * 1024;
/// Most vertex positions (`v` statements) in a file.
pub const MAX_VERTICES: usize = 4_000_000;
/// Most triangles the faces may make (an n-gon makes n − 2).
pub const MAX_TRIANGLES: usize = 8_000_000;
/// Largest coordinate magnitude, metres (1000 km). Far beyond any cloth; much larger values
/// would lose all precision in f32 and overflow when squared.
pub const MAX_COORDINATE: f32 = 1.0e6;
