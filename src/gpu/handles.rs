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

    /// The targets of a submission of `substeps` substeps of `h` seconds from `time`:
    /// per substep, per slot, the position and the velocity where the handle has the
    /// particle at the substep's end (the clock advanced as the CPU's, by `h` in f64).
    pub(super) fn targets(&self, time: f64, h: f32, substeps: u32) -> Vec<[f32; 4]> {
        let mut out = Vec::with_capacity(2 * self.slots.len() * substeps as usize);
        let mut t = time;
        for _ in 0..substeps {
            t += h as f64;
            let poses: Vec<_> = self.handles.iter().map(|h| h.motion.at(t)).collect();
            for &(_, k, rest) in &self.slots {
                let (pose, pivot) = (&poses[k], self.handles[k].pivot);
                let at = pose.apply(pivot, rest);
                out.push(at.extend(0.0).to_array());
                out.push(pose.velocity_at(pivot, at).extend(0.0).to_array());
            }
        }
        out
    }
}
