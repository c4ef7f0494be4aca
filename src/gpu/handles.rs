//! Handles (moving pins) on the GPU: the host computes, for every substep of a submission,
//! where each carried particle is at the substep's end and how fast it moves there (the
//! CPU's [`Handle::place`] arithmetic on the same clock), and the substep puts each pinned
//! carried particle there, its slot among the targets kept in its velocity's fourth
//! component.

use glam::Vec3;

use crate::sim::{Effect, Handle};

/// The particles the handles of a scene carry: per slot the particle, its handle and where
/// it was at the start. A particle two handles carry is the later one's, as on the CPU
/// (which places it twice, the later last). After them, a slot for a held particle the
/// pointer moved between frames: the particle, where it was moved to and its velocity
/// (its state was sent with it where it was moved from, so the first substep carries it
/// the rest of the way and the contacts see the move).
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Carried {
    handles: Vec<Handle>,
    slots: Vec<(u32, usize, Vec3)>,
    held: Option<(u32, Vec3, Vec3)>,
}

impl Carried {
    /// The handles among `effects`.
    pub(super) fn of(effects: &[Effect]) -> Self {
        let handles: Vec<Handle> = (effects.iter())
            .filter_map(|e| match e {
                Effect::Handle(h) => Some(h.clone()),
                _ => None,
            })
            .collect();
        let mut slots: Vec<(u32, usize, Vec3)> = Vec::new();
        for (k, h) in handles.iter().enumerate() {
            for (&p, &rest) in h.particles.iter().zip(&h.rest) {
                match slots.iter_mut().find(|s| s.0 == p) {
                    Some(slot) => *slot = (p, k, rest),
                    None => slots.push((p, k, rest)),
                }
            }
        }
        Self {
            handles,
            slots,
            held: None,
        }
    }

    /// These handles, with the held particle's slot as in `old`.
    pub(super) fn holding_as(mut self, old: &Carried) -> Self {
        self.hold(old.held);
        self
    }

    /// Gives held particle `particle` a slot that keeps it `at` (m) moving at `velocity`
    /// (m/s), or none (`None`, or a particle a handle carries: the handle places it).
    /// Returns whether the particle has the slot.
    pub(super) fn hold(&mut self, held: Option<(u32, Vec3, Vec3)>) -> bool {
        self.held = held.filter(|&(p, _, _)| self.slots.iter().all(|s| s.0 != p));
        self.held.is_some()
    }

    /// Carried particles, the held one among them.
    pub(super) fn len(&self) -> usize {
        self.slots.len() + usize::from(self.held.is_some())
    }

    /// Per particle of `count`, its slot + 1 (0 when no handle carries it), as the shader
    /// reads it.
    pub(super) fn stamps(&self, count: usize) -> Vec<f32> {
        let mut stamps = vec![0.0; count];
        let held = self.held.map(|h| h.0);
        for (slot, p) in self.slots.iter().map(|s| s.0).chain(held).enumerate() {
            if let Some(s) = stamps.get_mut(p as usize) {
                *s = (slot + 1) as f32;
            }
        }
        stamps
    }

    /// Into `out`, the targets of a submission of `substeps` substeps of `h` seconds from
    /// `time`: per substep, per slot, the position and the velocity where the handle has
    /// the particle at the substep's end (the clock advanced as the CPU's, by `h` in f64;
    /// the held particle's: where it was moved to).
    /// Each handle's pose is found once a substep; `out` keeps its storage.
    pub(super) fn targets(&self, (time, h, substeps): (f64, f32, u32), out: &mut Vec<[f32; 4]>) {
        let n = self.len();
        out.clear();
        out.resize(2 * n * substeps as usize, [0.0; 4]);
        let mut t = time;
        for step in out.chunks_exact_mut((2 * n).max(1)) {
            t += h as f64;
            for (k, handle) in self.handles.iter().enumerate() {
                let pose = handle.motion.at(t);
                let mine = (self.slots.iter().enumerate()).filter(|(_, s)| s.1 == k);
                for (slot, &(_, _, rest)) in mine {
                    let at = pose.apply(handle.pivot, rest);
                    step[2 * slot] = at.extend(0.0).to_array();
                    step[2 * slot + 1] = pose.velocity_at(handle.pivot, at).extend(0.0).to_array();
                }
            }
            if let Some((_, at, velocity)) = self.held {
                let slot = self.slots.len();
                step[2 * slot] = at.extend(0.0).to_array();
                step[2 * slot + 1] = velocity.extend(0.0).to_array();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A held particle gets the slot after the handles', with its target and velocity in
    /// every substep; one a handle carries gets none (the handle places it, as on the CPU),
    /// and letting go takes the slot away.
    #[test]
    fn a_held_particle_has_the_slot_after_the_handles_unless_a_handle_carries_it() {
        let handle = Handle {
            particles: vec![1],
            rest: vec![Vec3::X],
            pivot: Vec3::ZERO,
            motion: Default::default(),
        };
        let mut carried = Carried::of(&[Effect::Handle(handle)]);
        let (at, velocity) = (Vec3::new(0.5, 2.0, 0.0), Vec3::new(0.0, -3.0, 0.0));
        assert!(!carried.hold(Some((1, at, velocity))));
        assert_eq!(carried.stamps(4), [0.0, 1.0, 0.0, 0.0]);
        assert!(carried.hold(Some((3, at, velocity))));
        assert_eq!(carried.stamps(4), [0.0, 1.0, 0.0, 2.0]);
        let mut targets = Vec::new();
        carried.targets((0.0, 0.01, 2), &mut targets);
        for step in targets.chunks_exact(4) {
            assert_eq!(
                step[0],
                [1.0, 0.0, 0.0, 0.0],
                "the handle's, standing still"
            );
            assert_eq!(
                [step[2], step[3]],
                [at, velocity].map(|v| v.extend(0.0).to_array())
            );
        }
        assert!(!carried.hold(None));
        assert_eq!(carried.len(), 1);
    }
}
