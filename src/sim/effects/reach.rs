//! Each mesh obstacle as the cloth meets it: the gentle edges and vertices of its surface
//! that the cloth's edges and triangles can reach between their particles, kept off as its
//! creases and tips are ([`ClothSpan`]). Fitted to the cloth's rest shape grown by
//! [`GROWTH`], its triangles taken as if folded flat (no fold outgrows the fit), and again
//! wherever the cloth is stretched past what they were fitted to.

use glam::Vec3;

use super::registry::Effect;
use crate::cloth::ClothModel;
use crate::sim::obstacle::ClothSpan;

/// How much longer than measured the cloth's edges (and its triangles' levers) may grow
/// before the obstacles must be fitted to it again.
pub const GROWTH: f32 = 1.25;

/// `effects` with each mesh obstacle fitted to a cloth of `span` (its own thickness where
/// it has one, else `span`'s), [`super::Obstacle::reaching`]: the same effects (the same
/// readings) where nothing more is within reach.
pub fn fitted_to_cloth(effects: &[Effect], span: ClothSpan) -> Vec<Effect> {
    (effects.iter())
        .map(|e| match e {
            Effect::Obstacle(o) if o.is_loaded() => {
                let thickness = o.thickness.unwrap_or(span.thickness);
                let span = ClothSpan { thickness, ..span };
                o.reaching(&span)
                    .map_or_else(|| e.clone(), Effect::Obstacle)
            }
            _ => e.clone(),
        })
        .collect()
}

/// `span` with its triangles' lever as long as its longest edge: how far a triangle folded
/// flat reaches without stretching (its lever, the lesser of its circumradius and its
/// longest edge, grows as it flattens). A fit to it holds however the cloth folds: only a
/// stretch outgrows it.
fn folded(span: ClothSpan) -> ClothSpan {
    ClothSpan {
        lever: span.lever.max(span.edge),
        ..span
    }
}

/// The span a stepper's obstacles were last fitted to, whether any of them has gentle parts
/// (else nothing is ever fitted again), and the cloth's triangle edges, by their particles
/// (what a stretch is measured on: the model's mesh edges).
#[derive(Clone, Debug, Default)]
pub struct Reach {
    span: Option<ClothSpan>,
    gentle: bool,
    edges: Vec<[u32; 2]>,
}

impl Reach {
    /// `effects` fitted to `model`'s rest shape grown by [`GROWTH`] and folded (`folded`),
    /// keeping `offset` (where an obstacle has no thickness of its own).
    pub fn fit(&mut self, effects: &[Effect], model: &ClothModel, offset: f32) -> Vec<Effect> {
        let span = ClothSpan::of(&model.rest_positions, &model.triangles, GROWTH, offset);
        let fitted = self.fit_to(effects, folded(span));
        // The cloth's edges (its first springs), to measure its stretch on, only where it
        // is measured.
        self.edges.clear();
        if self.gentle {
            let (a, b) = (&model.springs.a, &model.springs.b);
            let edges = (a.iter().zip(b).take(model.mesh_edges)).map(|(&a, &b)| [a, b]);
            self.edges.extend(edges);
        }
        fitted
    }

    /// `effects` (as last fitted) fitted again where the cloth at `pos` has stretched past
    /// the span they were fitted to (its longest edge, measured on the edges of the model
    /// last fitted to): to its longest edge grown by [`GROWTH`], folded; `None` where it
    /// has not, or no obstacle has gentle parts. Cheap enough for every substep: a pass
    /// over the cloth's edges.
    pub fn outgrown(&mut self, effects: &[Effect], pos: &[Vec3]) -> Option<Vec<Effect>> {
        let fitted = self.span.filter(|_| self.gentle)?;
        // Only a stretch outgrows a fit: no triangle's lever exceeds its longest edge. (A
        // cloth gone non-finite spans nothing and outgrows nothing: the guard deals with it.)
        let at = |i: u32| pos.get(i as usize).copied();
        let longest = (self.edges.iter())
            .filter_map(|&[a, b]| Some(at(a)?.distance_squared(at(b)?)))
            .fold(0.0f32, f32::max)
            .sqrt();
        if longest <= fitted.edge {
            return None;
        }
        let edge = longest * GROWTH;
        Some(self.fit_to(effects, folded(ClothSpan { edge, ..fitted })))
    }

    /// Whether a cloth growing could ever have the obstacles fitted again: they were
    /// fitted, and some has gentle parts.
    pub fn watches(&self) -> bool {
        self.gentle && self.span.is_some()
    }

    fn fit_to(&mut self, effects: &[Effect], span: ClothSpan) -> Vec<Effect> {
        self.span = Some(span);
        self.gentle = effects.iter().any(|e| match e {
            Effect::Obstacle(o) => o.placed().is_some_and(|p| p.is_gentle()),
            _ => false,
        });
        fitted_to_cloth(effects, span)
    }
}

/// A closed prism of 40 narrow faces (each turning 9° from the next), 30 cm in radius, along
/// the x axis (`obstacle::prism`), as a mesh obstacle: a rail, for tests.
#[cfg(test)]
pub(crate) fn rail() -> Effect {
    let (positions, triangles) = crate::sim::obstacle::prism(40, 0.3);
    let soup = crate::mesh::PolygonSoup {
        positions,
        uvs: None,
        face_indices: triangles.iter().flatten().copied().collect(),
        face_arities: vec![3; triangles.len()],
    };
    let mut rail = super::Obstacle::new("rail.obj");
    rail.load_mesh(&soup).unwrap();
    Effect::Obstacle(rail)
}

/// A block 1.6 m square and 30 cm tall whose top is flat in frame 0 and rises 4.7° to an
/// apex in frame 1 (an OBJ sequence of one frame a second, written into `dir`), as a mesh
/// obstacle: a roof that rises, for tests.
#[cfg(test)]
pub(crate) fn rising_roof(dir: &std::path::Path) -> Effect {
    let (half, base) = (0.8f32, 0.3f32);
    for (k, rise) in [0.0, half * 4.7f32.to_radians().tan()]
        .into_iter()
        .enumerate()
    {
        let mut text = String::new();
        for y in [0.0, base] {
            for [x, z] in [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]] {
                text += &format!("v {} {y} {}\n", half * x, half * z);
            }
        }
        text += &format!("v 0 {} 0\n", base + rise);
        text += "f 1 2 3\nf 1 3 4\nf 5 6 2\nf 5 2 1\nf 6 7 3\nf 6 3 2\nf 7 8 4\nf 7 4 3\n\
                 f 8 5 1\nf 8 1 4\nf 5 9 6\nf 6 9 7\nf 7 9 8\nf 8 9 5\n";
        std::fs::write(dir.join(format!("roof_{k}.obj")), text).unwrap();
    }
    let mut roof = super::Obstacle::sequence("roof_%d.obj", 1.0, false);
    roof.load(Some(dir)).unwrap();
    Effect::Obstacle(roof)
}

/// A cloth of 10 cm quads, 1 m square and 2 m up, kept `thickness` off solids, and its
/// state at rest but moving out from its middle so fast that a frame (forces none) ends
/// with it at 1.8 times its size (within the guard's limits), for tests.
#[cfg(test)]
pub(crate) fn growing_cloth(
    thickness: f32,
) -> (ClothModel, crate::sim::SimParams, crate::cloth::ClothState) {
    use crate::mesh::{GridOrientation, GridSpec};
    let at = Vec3::new(0.0, 2.0, 0.0);
    let mesh = GridSpec::square(10, 1.0, GridOrientation::Horizontal, at)
        .build()
        .unwrap();
    let model = ClothModel::new(&mesh, 0.2, &[]);
    let mut params = crate::sim::SimParams::default();
    params.contact.offset = thickness;
    let mut state = crate::cloth::ClothState::at_rest(&model);
    for (v, p) in state.vel.iter_mut().zip(&state.pos) {
        *v = (*p - at) * 0.8 / params.step.dt;
    }
    (model, params, state)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{GridOrientation, GridSpec};

    /// A horizontal cloth 1 m square of 10 cm quads about the origin: its mesh and model.
    fn metre_of_10_cm_quads() -> (crate::mesh::ClothMesh, ClothModel) {
        let mesh = GridSpec::square(10, 1.0, GridOrientation::Horizontal, Vec3::ZERO)
            .build()
            .unwrap();
        let model = ClothModel::new(&mesh, 0.2, &[]);
        (mesh, model)
    }

    fn kept_off(effects: &[Effect]) -> usize {
        match &effects[0] {
            Effect::Obstacle(o) => o.placed().unwrap().surface.sharp_edges().len(),
            _ => unreachable!(),
        }
    }

    /// A cloth of 10 cm quads and a 4 cm thickness cannot reach the rail's ridges at rest
    /// (its diagonals, 14 cm, grown by a quarter, dip at most 2.3 cm into it by the bound,
    /// under three quarters of the thickness), so only the creases round its ends are kept
    /// off.
    /// Grown to twice its size it can, and the rail is fitted to it again: its
    /// 40 ridges kept off too. Grown by a tenth (within the quarter it was fitted with), not
    /// at all, or gone non-finite, nothing is fitted again. The scene's rail keeps the
    /// walks it was measured by (for another thickness); a rail fitted already, fitted
    /// again as the cloth grows on to three times its size, keeps none (red where it does).
    #[test]
    fn a_cloth_grown_past_its_fit_has_the_obstacles_fitted_again() {
        let (mesh, model) = metre_of_10_cm_quads();
        let mut reach = Reach::default();
        let fitted = reach.fit(&[rail()], &model, 0.04);
        assert_eq!(kept_off(&fitted), 80, "the ends' rims");
        let grown = |by: f32| mesh.positions.iter().map(|&p| p * by).collect::<Vec<_>>();
        assert!(reach.outgrown(&fitted, &mesh.positions).is_none());
        assert!(reach.outgrown(&fitted, &grown(1.1)).is_none());
        assert!(reach.outgrown(&fitted, &grown(f32::NAN)).is_none());
        let refitted = reach.outgrown(&fitted, &grown(2.0)).unwrap();
        assert_eq!(kept_off(&refitted), 120);
        // Fitted to the grown cloth, the same growth asks for nothing more.
        assert!(reach.outgrown(&refitted, &grown(2.0)).is_none());
        let holds_walks = |effects: &[Effect]| match &effects[0] {
            Effect::Obstacle(o) => o.placed().unwrap().holds_walks(),
            _ => unreachable!(),
        };
        assert!(reach.outgrown(&refitted, &grown(3.0)).is_some());
        assert!(holds_walks(&fitted) && !holds_walks(&refitted));
    }

    /// The rail fitted to a cloth of 12 cm edges (6 cm lever) 1 cm thick keeps off its 40
    /// ridges besides the 80 edges of its rims; 1.01 cm thick, the cloth reaches the same
    /// edges, and the fit is the same one, not built again (a slider dragged a little); 2
    /// cm thick, it reaches none, and the rail is its own; back to 9 mm, the ridges again,
    /// in a fit of its own. Red with the answer built again wherever the span changed.
    #[test]
    fn a_thickness_that_changes_nothing_reached_keeps_the_fit() {
        let rail = [rail()];
        let fitted = |thickness| {
            let span = ClothSpan {
                edge: 0.12,
                lever: 0.06,
                thickness,
            };
            fitted_to_cloth(&rail, span)
        };
        let placed = |effects: &[Effect]| match &effects[0] {
            Effect::Obstacle(o) => o.placed().unwrap() as *const _,
            _ => unreachable!(),
        };
        let (one, more, two) = (fitted(0.01), fitted(0.0101), fitted(0.02));
        assert_eq!(kept_off(&one), 120);
        assert_eq!(kept_off(&more), 120);
        assert!(std::ptr::eq(placed(&one), placed(&more)));
        assert_eq!(kept_off(&two), 80);
        assert!(std::ptr::eq(placed(&two), placed(&rail)));
        let back = fitted(0.009);
        assert_eq!(kept_off(&back), 120);
        assert!(!std::ptr::eq(placed(&back), placed(&one)));
    }

    /// A roof of four faces rising 4.7° to an apex 1.6 m across (no crease, no tip by its
    /// faces), as a mesh obstacle.
    fn low_roof() -> Effect {
        let rise = 0.8 * 4.7f32.to_radians().tan();
        let soup = crate::mesh::PolygonSoup {
            positions: vec![
                Vec3::new(-0.8, 0.0, -0.8),
                Vec3::new(0.8, 0.0, -0.8),
                Vec3::new(0.8, 0.0, 0.8),
                Vec3::new(-0.8, 0.0, 0.8),
                Vec3::new(0.0, rise, 0.0),
            ],
            uvs: None,
            face_indices: vec![0, 4, 1, 1, 4, 2, 2, 4, 3, 3, 4, 0],
            face_arities: vec![3; 4],
        };
        let mut roof = crate::sim::Obstacle::new("roof.obj");
        roof.load_mesh(&soup).unwrap();
        Effect::Obstacle(roof)
    }

    /// Whether the roof's apex is kept off as a tip.
    fn apex_kept_off(effects: &[Effect]) -> bool {
        let Effect::Obstacle(o) = &effects[0] else {
            unreachable!()
        };
        let mut found = false;
        let (lo, hi) = (Vec3::new(-0.01, 0.0, -0.01), Vec3::new(0.01, 0.1, 0.01));
        o.placed()
            .unwrap()
            .surface
            .tips()
            .in_box(lo, hi, |_| found = true);
        found
    }

    /// A cloth of 10 cm quads over the low roof, 1.6 cm thick. At rest its triangles'
    /// lever is 7.1 cm (half a diagonal), and by the bound one over the apex leaves more
    /// than three quarters of the thickness; but a triangle folded flat across its
    /// diagonal, stretched nowhere, has a lever of 14.1 cm, and leaves less. So the fit
    /// takes each triangle's lever as long as the cloth's longest edge and keeps the apex
    /// off from the start, and a cloth folded flat (its triangles' lever up to 14.1 cm, no
    /// edge longer) outgrows nothing: nothing is fitted again in the middle of a run. (With
    /// the rest lever fitted, the apex is not kept off; with the lever's growth outgrowing
    /// the fit, the folded cloth is fitted again.)
    #[test]
    fn a_fit_holds_however_the_cloth_folds() {
        let (mesh, model) = metre_of_10_cm_quads();
        let mut reach = Reach::default();
        let fitted = reach.fit(&[low_roof()], &model, 0.016);
        assert!(apex_kept_off(&fitted));
        // Folded like an accordion onto the line of one diagonal: no edge longer, every
        // triangle flat, the lever of those along it the diagonal's length.
        let along = Vec3::new(1.0, 0.0, 1.0).normalize();
        let folded: Vec<Vec3> = (mesh.positions.iter())
            .map(|p| along * p.dot(along))
            .collect();
        let lever = ClothSpan::of(&folded, &model.triangles, 1.0, 0.016).lever;
        assert!((lever - 0.1f32.hypot(0.1)).abs() < 1e-4, "{lever}");
        assert!(reach.outgrown(&fitted, &folded).is_none());
    }
}
