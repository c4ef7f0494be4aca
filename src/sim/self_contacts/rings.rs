//! Each particle's ring, for the certificates ([`super::certify`]), and its triangles, for
//! the refresh's search of the triangles around the particles that left their boxes.

/// Each particle's ring: the other particles of the triangles it is a corner of,
/// `ring[start[i]..start[i + 1]]`, each once, in increasing order; the other two corners
/// of its first triangle, whose frame turns the reference; and the triangles it is a
/// corner of, in increasing order.
#[derive(Clone, Debug, Default)]
pub(super) struct Rings {
    pub(super) start: Vec<u32>,
    pub(super) ring: Vec<u32>,
    pub(super) first: Vec<[u32; 2]>,
    around_start: Vec<u32>,
    around: Vec<u32>,
}

impl Rings {
    pub(super) fn build(particles: usize, triangles: &[[u32; 3]]) -> Rings {
        let (around_start, around) = crate::mesh::triangles_around(particles, triangles);
        let mut rings = Rings {
            start: Vec::with_capacity(particles + 1),
            ring: Vec::new(),
            first: Vec::with_capacity(particles),
            around_start: Vec::new(),
            around: Vec::new(),
        };
        rings.start.push(0);
        let mut one = Vec::new();
        for i in 0..particles {
            one.clear();
            let (from, to) = (around_start[i] as usize, around_start[i + 1] as usize);
            let first = (around[from..to].first()).map_or([i as u32; 2], |&t| {
                let t = triangles[t as usize];
                let k = t.iter().position(|&j| j as usize == i).unwrap_or(0);
                [t[(k + 1) % 3], t[(k + 2) % 3]]
            });
            rings.first.push(first);
            for &t in &around[from..to] {
                one.extend(triangles[t as usize].iter().filter(|&&j| j as usize != i));
            }
            one.sort_unstable();
            one.dedup();
            rings.ring.extend_from_slice(&one);
            rings.start.push(rings.ring.len() as u32);
        }
        (rings.around_start, rings.around) = (around_start, around);
        rings
    }

    /// The triangles particle `i` is a corner of.
    pub(super) fn triangles_of(&self, i: usize) -> &[u32] {
        &self.around[self.around_start[i] as usize..self.around_start[i + 1] as usize]
    }

    /// Particle `i`'s ring, as the range of entries it takes.
    pub(super) fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.start[i] as usize..self.start[i + 1] as usize
    }
}
