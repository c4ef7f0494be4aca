//! A grid cloth at another resolution (`--quads N`): the same scene with finer or coarser
//! quads, its self-collision thickness kept in proportion to the spacing when the grid gets
//! finer.

use crate::sim::Effect;

use super::error::SceneError;
use super::file::{OneOrTwo, SceneFile};

impl SceneFile {
    /// Gives the grid cloth `quads` quads along its longer side (the shorter in proportion,
    /// at least one). Where that makes the quads smaller, the self-collision thickness
    /// shrinks by the same factor, so it keeps its share of the spacing.
    ///
    /// # Errors
    /// [`SceneError::Resize`] for a cloth that is not a grid, or `quads` outside 1..=2048.
    pub fn resize_grid(&mut self, quads: u32) -> Result<(), SceneError> {
        let refuse = |why: &str| SceneError::Resize {
            scene: self.name.clone(),
            why: why.to_string(),
        };
        if !(1..=2048).contains(&quads) {
            return Err(refuse("--quads must be in 1..=2048"));
        }
        let Some(grid) = self.cloth.grid.as_mut() else {
            return Err(refuse(
                "its cloth is an OBJ file, not a grid; --quads resizes a grid cloth",
            ));
        };
        let [qx, qy] = grid.quads.pair();
        let longer = qx.max(qy);
        let scale = |q: u32| ((q as f64 * quads as f64 / longer as f64).round() as u32).max(1);
        grid.quads = if qx == qy {
            OneOrTwo::One(quads)
        } else {
            OneOrTwo::Two([scale(qx), scale(qy)])
        };
        let finer = longer as f32 / quads as f32;
        if finer < 1.0 {
            for effect in &mut self.effects {
                if let Effect::SelfCollision(s) = effect {
                    s.thickness *= finer;
                }
            }
        }
        Ok(())
    }
}
