//! Particle → spring adjacency in compressed sparse row form, for per-particle gathers
//! (each particle sums over its own springs: parallel without write conflicts).

use super::springs::Springs;

/// For particle `p`, its springs are `spring[offsets[p]..offsets[p+1]]` and the particle at
/// the other end of each is in `other` at the same place. `sign` is +1 where `p` is the
/// spring's first end (`a`) and −1 where it is the second (`b`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Adjacency {
    pub offsets: Vec<u32>,
    pub spring: Vec<u32>,
    pub other: Vec<u32>,
    pub sign: Vec<f32>,
}

impl Adjacency {
    /// Builds the adjacency of `springs` over `particles` particles; each particle's list
    /// is in spring order, so gathers are deterministic.
    pub fn new(particles: usize, springs: &Springs) -> Self {
        Self::of_pairs(particles, &springs.a, &springs.b)
    }

    /// The adjacency of the pairs `(a[e], b[e])` (springs, constraints) over `particles`
    /// particles, as [`Adjacency::new`].
    ///
    /// # Panics
    /// If a pair names a particle `≥ particles`.
    pub fn of_pairs(particles: usize, a: &[u32], b: &[u32]) -> Self {
        let mut count = vec![0u32; particles + 1];
        for (&a, &b) in a.iter().zip(b) {
            count[a as usize + 1] += 1;
            count[b as usize + 1] += 1;
        }
        for p in 0..particles {
            count[p + 1] += count[p];
        }
        let offsets = count.clone();
        let total = offsets[particles] as usize;
        let mut next = count;
        let (mut spring, mut other, mut sign) = (vec![0; total], vec![0; total], vec![0.0; total]);
        for (e, (&a, &b)) in a.iter().zip(b).enumerate() {
            for (p, q, s) in [(a, b, 1.0), (b, a, -1.0)] {
                let slot = next[p as usize] as usize;
                next[p as usize] += 1;
                spring[slot] = e as u32;
                other[slot] = q;
                sign[slot] = s;
            }
        }
        Self {
            offsets,
            spring,
            other,
            sign,
        }
    }

    /// The slots of particle `p`.
    pub fn range(&self, p: usize) -> std::ops::Range<usize> {
        self.offsets[p] as usize..self.offsets[p + 1] as usize
    }
}
