//! A mesh obstacle as one cloth meets it: its gentle edges and vertices that the cloth's
//! edges and triangles can reach between their particles kept off as its creases and tips
//! are ([`ClothSpan`]).

use super::{Obstacle, Placed, Shape};
use crate::sim::obstacle::{ClothSpan, Fitted, Reached};

impl Obstacle {
    /// This obstacle as a cloth of `span` meets it (the same file, placement and motion;
    /// a surface that keeps that cloth off what it can reach, with memories of its own),
    /// or `None` where its creases and tips already hold all of it. What it measured and
    /// gave is remembered ([`Fitted`]): asked again for the same span (another stepper for
    /// the same scene) the answer is the same reading, and asked for another thickness it
    /// takes no walk again.
    pub fn reaching(&self, span: &ClothSpan) -> Option<Obstacle> {
        let placed = self.placed()?;
        let frames = placed.sequence.iter().flat_map(|s| s.frames());
        let keeping_off = |reached: &Reached| placed.keeping_off(reached);
        // A fit that panicked elsewhere leaves nothing to trust: fit anew, remember nothing.
        let answer = match placed.reached.lock() {
            Ok(mut fitted) => fitted.answer((&placed.surface, frames), span, keeping_off),
            Err(_) => Fitted::default().answer((&placed.surface, frames), span, keeping_off),
        };
        answer.map(|placed| Obstacle {
            shape: Shape(Some(placed)),
            ..self.clone()
        })
    }
}

impl Placed {
    /// Whether a cloth may ever reach more of it than its creases and tips: two of its
    /// faces meet at an edge neither flat nor a crease, or it is a sequence (whose later
    /// frames may bend where frame 0 is flat).
    pub fn is_gentle(&self) -> bool {
        self.sequence.is_some() || self.surface.is_gentle()
    }

    /// Whether fitting it to a cloth left walks kept ([`Fitted::holds_walks`]).
    #[cfg(test)]
    pub(crate) fn holds_walks(&self) -> bool {
        self.reached.lock().is_ok_and(|f| f.holds_walks())
    }

    /// This placement with its surface keeping off the edges and vertices `reached` (a
    /// sequence's in all its frames), or `None` where that adds nothing.
    fn keeping_off(&self, reached: &Reached) -> Option<Placed> {
        let surface = self.surface.keeping_off(reached)?;
        let sequence = (self.sequence.as_ref()).map(|s| s.over(surface.clone()));
        Some(Placed {
            surface,
            motion: self.motion.clone(),
            pivot: self.pivot,
            sequence,
            memory: Default::default(),
            edge_memory: Default::default(),
            reached: std::sync::Mutex::new(Fitted::passing()),
        })
    }
}
