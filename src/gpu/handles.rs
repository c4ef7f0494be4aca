//! Handles (moving pins) on the GPU: the host computes, for every substep of a submission,
//! where each carried particle is at the substep's end and how fast it moves there (the
//! CPU's [`Handle::place`] arithmetic on the same clock), and the substep puts each pinned
//! carried particle there, its slot among the targets kept in its velocity's fourth
//! component.

use glam::Vec3;

use crate::sim::{Effect, Handle};

/// The particles the handles of a scene carry: per slot the particle, its handle and where
/// it was at the start. A particle two handles carry is the later one's, as on the CPU
/// (which places it twice, the later last).
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Carried {
    handles: Vec<Handle>,
    slots: Vec<(u32, usize, Vec3)>,
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
        Self { handles, slots }
    }

    /// Carried particles.
    pub(super) fn len(&self) -> usize {
        self.slots.len()
    }

    /// Per particle of `count`, its slot + 1 (0 when no handle carries it), as the shader
    /// reads it.
    pub(super) fn stamps(&self, count: usize) -> Vec<f32> {
        let mut stamps = vec![0.0; count];
        for (slot, &(p, _, _)) in self.slots.iter().enumerate() {
            if let Some(s) = stamps.get_mut(p as usize) {
                *s = (slot + 1) as f32;
            }
        }
        stamps
    }

    /// Into `out`, the targets of a submission of `substeps` substeps of `h` seconds from
    /// `time`: per substep, per slot, the position and the velocity where the handle has
    /// the particle at the substep's end (the clock advanced as the CPU's, by `h` in f64).
    /// Each handle's pose is found once a substep; `out` keeps its storage.
    pub(super) fn targets(&self, (time, h, substeps): (f64, f32, u32), out: &mut Vec<[f32; 4]>) {
        let n = self.slots.len();
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
        }
    }
}
