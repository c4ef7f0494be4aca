//! The exact intersection check after every frame, as the window runs it: on the stepping
//! thread ([`super::stepping`]), so that the view never waits for it, its counts shown in
//! the status bar.

use super::stepping::{Checked, SimThread};

/// Whether the check runs, and what it found since it was turned on or the run began.
#[derive(Clone, Debug, Default)]
pub struct IntersectionCheck {
    on: bool,
    found: Option<Checked>,
}

impl IntersectionCheck {
    /// Whether every frame stepped is checked.
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// What the check found (none: it is off, or has checked no frame of this run yet).
    pub fn found(&self) -> Option<&Checked> {
        self.found.as_ref().filter(|_| self.on)
    }

    /// Turns the check on or off, on the stepping `thread` too: the frames it steps from
    /// now on are checked, or none. What was found before is forgotten.
    pub(super) fn set(&mut self, on: bool, thread: &SimThread) {
        self.on = on;
        self.found = None;
        thread.check_intersections(on);
    }

    /// Takes in what the stepping thread found since the window last looked.
    pub(super) fn take(&mut self, checked: Option<Checked>) {
        if let Some(new) = checked {
            Checked::add(&mut self.found, new);
        }
    }

    /// A new run (a reset, another scene or cloth): what was found is forgotten.
    pub(super) fn restart(&mut self) {
        self.found = None;
    }
}

/// What the status bar says of `found`: none found after any frame checked, or the counts
/// after the last (the cloth's own pairs of triangles that meet, and the cloth's triangles
/// that meet a solid) and the most after any (each solid's own most, added).
pub fn intersections_text(found: Option<&Checked>) -> String {
    let Some(found) = found else {
        return "intersections: no frame checked yet".into();
    };
    if found.most.total() == 0 {
        return "intersections: none".into();
    }
    let solids = |i: &crate::sim::Intersections| i.obstacles.iter().sum::<usize>();
    format!(
        "intersections: {} self, {} with solids (most {}, {})",
        found.last.self_pairs,
        solids(&found.last),
        found.most.self_pairs,
        solids(&found.most)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::Intersections;

    fn counts(self_pairs: usize, obstacles: &[usize]) -> Intersections {
        Intersections {
            self_pairs,
            obstacles: obstacles.to_vec(),
        }
    }

    /// The counts after the last frame and the most after any, over what the thread sent
    /// in several looks; none where nothing was ever found.
    #[test]
    fn the_text_says_the_last_counts_and_the_most() {
        assert_eq!(
            intersections_text(None),
            "intersections: no frame checked yet"
        );
        let mut check = IntersectionCheck {
            on: true,
            found: None,
        };
        check.take(Some(counts(0, &[0, 0]).into()));
        assert_eq!(intersections_text(check.found()), "intersections: none");
        check.take(None);
        check.take(Some(
            Checked::from(counts(4, &[1, 0])).then(counts(2, &[0, 3]).into()),
        ));
        check.take(Some(counts(1, &[0, 0]).into()));
        assert_eq!(
            intersections_text(check.found()),
            "intersections: 1 self, 0 with solids (most 4, 4)"
        );
        check.restart();
        assert_eq!(check.found(), None);
        check.take(Some(counts(0, &[]).into()));
        assert_eq!(intersections_text(check.found()), "intersections: none");
        check.on = false;
        assert_eq!(check.found(), None, "off, it shows nothing");
    }
}
