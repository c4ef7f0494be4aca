//! The kinds of spring a cloth is made of.

/// What a spring models. Structural springs are polygon sides; shear springs are the
/// diagonals of quads (both of them) and of other polygons (the fan's); a bend spring joins
/// the two vertices opposite an interior edge.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub enum SpringKind {
    Structural,
    Shear,
    Bend,
}

impl SpringKind {
    /// All kinds, in the order per-kind parameter arrays use.
    pub const ALL: [SpringKind; 3] = [SpringKind::Structural, SpringKind::Shear, SpringKind::Bend];

    /// Index into per-kind parameter arrays.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name for tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            SpringKind::Structural => "structural",
            SpringKind::Shear => "shear",
            SpringKind::Bend => "bend",
        }
    }
}
