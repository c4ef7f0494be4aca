//! A mesh obstacle as one cloth meets it: its gentle edges and vertices that the cloth's
//! edges and triangles can reach between their particles kept off as its creases and tips
//! are ([`ClothSpan`]).

use std::sync::Arc;

use super::{Obstacle, Placed, Shape};
use crate::sim::obstacle::ClothSpan;

impl Obstacle {
    /// This obstacle as a cloth of `span` meets it (the same file, placement and motion;
    /// a surface that keeps that cloth off what it can reach, with memories of its own),
    /// or `None` where its creases and tips already hold all of it. The last span asked
    /// for is remembered with its answer: asked again (another stepper for the same
    /// scene), the answer is the same reading.
    pub fn reaching(&self, span: &ClothSpan) -> Option<Obstacle> {
        let placed = self.placed()?;
        let mut reached = placed.reached.lock().ok();
        let known = (reached.as_deref())
            .and_then(|r| r.as_ref())
            .filter(|(asked, _)| asked == span)
            .map(|(_, answer)| answer.clone());
        let answer = known.unwrap_or_else(|| {
            let answer = placed.reaching(span).map(Arc::new);
            if let Some(reached) = reached.as_deref_mut() {
                *reached = Some((*span, answer.clone()));
            }
            answer
        });
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

    /// This placement with its surface fitted to a cloth of `span` (a sequence's to what
    /// the cloth can reach in any of its frames), or `None` where that adds nothing.
    fn reaching(&self, span: &ClothSpan) -> Option<Placed> {
        let frames = self.sequence.iter().flat_map(|s| s.frames());
        let surface = self.surface.reaching_over(span, frames)?;
        let sequence = (self.sequence.as_ref()).map(|s| s.over(surface.clone()));
        Some(Placed {
            surface,
            motion: self.motion.clone(),
            pivot: self.pivot,
            sequence,
            memory: Default::default(),
            edge_memory: Default::default(),
            reached: Default::default(),
        })
    }
}
