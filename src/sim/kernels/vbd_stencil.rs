//! What vertex block descent reads per particle: the springs that meet there, and the
//! particles in colours (no two of one colour joined by a spring), laid out for its sweep.

use std::ops::Range;

use crate::cloth::Adjacency;
use crate::sim::constraints::DistanceConstraints;

/// One spring seen from one of its ends (while the stencil is built).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Link {
    other: u32,
    rest: f32,
    k: f32,
    c: f32,
}

/// Where a particle's links are: `count` of them from `first`, `stride` apart.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Span {
    pub first: u32,
    pub count: u32,
    pub stride: u32,
}

/// The particles colour by colour, and each one's springs seen from it ("links"), laid out
/// for a sweep that visits them in that order.
///
/// Each colour's particles go in groups of eight (the rest after them one by one). A
/// group's links are interleaved: its eight particles' first links, then their second ones,
/// and so on, a particle with fewer links than the group's most padded with links to itself
/// of no strength; the eight are read as one SIMD register per quantity. Links are stored
/// in the order the sweep visits them (a colour's particles lie far apart in the mesh;
/// stored by particle number they would be fetched from all over memory).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stencil {
    /// The particles, colour by colour, ascending within a colour.
    pub order: Vec<u32>,
    /// Each colour's range of `order`.
    pub colours: Vec<Range<usize>>,
    /// Per entry of `order`, where its links are.
    pub spans: Vec<Span>,
    /// Per link: the particle at the other end, the rest length (m), stiffness (N/m) and
    /// dashpot (N·s/m).
    pub other: Vec<u32>,
    pub rest: Vec<f32>,
    pub k: Vec<f32>,
    pub c: Vec<f32>,
}

/// Particles per group.
pub const GROUP: usize = 8;

impl Stencil {
    /// The stencil of `springs` over `particles` particles. Colours are greedy in particle
    /// order: each particle takes the lowest colour none of its already coloured neighbours
    /// has (a 12-neighbour grid takes about a dozen).
    ///
    /// # Panics
    /// If a spring names a particle `≥ particles`.
    pub fn new(springs: &DistanceConstraints, particles: usize) -> Self {
        let stiffness = |e: usize| {
            let compliance = springs.compliance[e];
            if compliance > 0.0 {
                1.0 / compliance
            } else {
                0.0
            }
        };
        // Each particle's links, by particle number, in the springs' order.
        let adjacency = Adjacency::of_pairs(particles, &springs.a, &springs.b);
        let by_particle: Vec<Link> = (0..adjacency.spring.len())
            .map(|slot| {
                let e = adjacency.spring[slot] as usize;
                Link {
                    other: adjacency.other[slot],
                    rest: springs.rest[e],
                    k: stiffness(e),
                    c: springs.damping[e],
                }
            })
            .collect();
        let links_of = |p: u32| &by_particle[adjacency.range(p as usize)];
        let mut colour = vec![u32::MAX; particles];
        let mut taken = Vec::new();
        for p in 0..particles {
            taken.clear();
            taken.extend(links_of(p as u32).iter().map(|l| colour[l.other as usize]));
            colour[p] = (0..).find(|c| !taken.contains(c)).unwrap_or(0);
        }
        let mut order: Vec<u32> = (0..particles as u32).collect();
        order.sort_by_key(|&p| colour[p as usize]);
        let colours: Vec<Range<usize>> = order
            .chunk_by(|&p, &q| colour[p as usize] == colour[q as usize])
            .scan(0, |end, run| {
                let start = *end;
                *end += run.len();
                Some(start..*end)
            })
            .collect();
        let mut stencil = Self {
            order,
            colours,
            spans: vec![Span::default(); particles],
            ..Self::default()
        };
        for colour in stencil.colours.clone() {
            let grouped = colour.start + (colour.len() / GROUP) * GROUP;
            for group in (colour.start..grouped).step_by(GROUP) {
                let members: [u32; GROUP] = std::array::from_fn(|l| stencil.order[group + l]);
                let most = members.iter().map(|&p| links_of(p).len()).max();
                let first = stencil.other.len();
                for slot in 0..most.unwrap_or(0) {
                    for &p in &members {
                        let link = links_of(p).get(slot).copied();
                        stencil.push(link.unwrap_or(Link {
                            other: p,
                            ..Link::default()
                        }));
                    }
                }
                for (lane, &p) in members.iter().enumerate() {
                    stencil.spans[group + lane] = Span {
                        first: (first + lane) as u32,
                        count: links_of(p).len() as u32,
                        stride: GROUP as u32,
                    };
                }
            }
            for i in grouped..colour.end {
                let links = links_of(stencil.order[i]);
                stencil.spans[i] = Span {
                    first: stencil.other.len() as u32,
                    count: links.len() as u32,
                    stride: 1,
                };
                links.iter().for_each(|&l| stencil.push(l));
            }
        }
        stencil
    }

    fn push(&mut self, link: Link) {
        self.other.push(link.other);
        self.rest.push(link.rest);
        self.k.push(link.k);
        self.c.push(link.c);
    }

    /// The links of the `i`-th particle in the sweep's order, as indices into the link
    /// arrays.
    pub fn links_at(&self, i: usize) -> impl Iterator<Item = usize> + use<> {
        let Span {
            first,
            count,
            stride,
        } = self.spans[i];
        (0..count as usize).map(move |j| first as usize + j * stride as usize)
    }

    /// Whether `order[i..i + 8]` is one group (its links interleaved).
    pub fn group_at(&self, i: usize) -> bool {
        let (Some(head), Some(tail)) = (self.spans.get(i), self.spans.get(i + GROUP - 1)) else {
            return false;
        };
        head.stride == GROUP as u32 && tail.first == head.first + GROUP as u32 - 1
    }

    /// The group at `i`'s link slots (the most links of its particles).
    pub fn group_slots(&self, i: usize) -> usize {
        let counts = self.spans[i..i + GROUP].iter().map(|s| s.count as usize);
        counts.max().unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 5 × 5 grid's structural, shear and bend springs (the 12-neighbour stencil).
    fn grid_springs(side: u32) -> DistanceConstraints {
        let mut c = DistanceConstraints::default();
        let id = |i: u32, j: u32| i * side + j;
        for i in 0..side {
            for j in 0..side {
                for (di, dj) in [(0, 1), (1, 0), (1, 1), (1, -1), (0, 2), (2, 0)] {
                    let (ni, nj) = (i as i32 + di, j as i32 + dj);
                    if ni < side as i32 && (0..side as i32).contains(&nj) {
                        c.a.push(id(i, j));
                        c.b.push(id(ni as u32, nj as u32));
                        c.rest.push(1.0);
                        c.compliance.push(0.01);
                        c.damping.push(0.1);
                    }
                }
            }
        }
        c
    }

    #[test]
    fn no_spring_joins_two_particles_of_one_colour_and_every_particle_is_coloured_once() {
        let springs = grid_springs(5);
        let stencil = Stencil::new(&springs, 25);
        let mut colour_of = [usize::MAX; 25];
        for (c, range) in stencil.colours.iter().enumerate() {
            for &p in &stencil.order[range.clone()] {
                assert_eq!(colour_of[p as usize], usize::MAX, "particle {p} twice");
                colour_of[p as usize] = c;
            }
        }
        assert!(colour_of.iter().all(|&c| c != usize::MAX));
        for (&a, &b) in springs.a.iter().zip(&springs.b) {
            assert_ne!(colour_of[a as usize], colour_of[b as usize], "{a}–{b}");
        }
        // Each particle sees each of its springs once, with its strengths.
        let at = |p: u32| stencil.order.iter().position(|&q| q == p).unwrap();
        let link = stencil
            .links_at(at(6))
            .find(|&l| stencil.other[l] == 7)
            .unwrap();
        assert_eq!((stencil.k[link], stencil.c[link]), (100.0, 0.1));
        let degree = |p: u32| stencil.links_at(at(p)).count();
        assert_eq!(degree(12), 12, "an inner particle has 12 neighbours");
        assert!(
            stencil.colours.len() <= 13,
            "{} colours",
            stencil.colours.len()
        );
    }

    /// On a 20 × 20 grid most colours hold groups of eight: each particle still reads each
    /// of its springs once, and a group's padding is links to the particle itself of no
    /// strength.
    #[test]
    fn groups_interleave_their_links_and_pad_with_links_of_no_strength() {
        let springs = grid_springs(20);
        let stencil = Stencil::new(&springs, 400);
        let mut seen = vec![Vec::new(); 400];
        for (i, &p) in stencil.order.iter().enumerate() {
            for l in stencil.links_at(i) {
                seen[p as usize].push((stencil.other[l], stencil.k[l].to_bits()));
            }
        }
        let mut expected = vec![Vec::new(); 400];
        for e in 0..springs.len() {
            let (a, b, k) = (
                springs.a[e],
                springs.b[e],
                (1.0 / springs.compliance[e]).to_bits(),
            );
            expected[a as usize].push((b, k));
            expected[b as usize].push((a, k));
        }
        for (mut s, mut e) in seen.into_iter().zip(expected) {
            s.sort();
            e.sort();
            assert_eq!(s, e);
        }
        let groups: Vec<usize> = (stencil.colours.iter())
            .flat_map(|c| c.clone().step_by(GROUP))
            .filter(|&i| stencil.group_at(i))
            .collect();
        assert!(groups.len() >= 30, "{} groups", groups.len());
        let mut padded = 0;
        for &i in &groups {
            let first = stencil.spans[i].first as usize;
            for slot in 0..stencil.group_slots(i) {
                for lane in 0..GROUP {
                    let l = first + slot * GROUP + lane;
                    if slot >= stencil.spans[i + lane].count as usize {
                        padded += 1;
                        assert_eq!(stencil.other[l], stencil.order[i + lane]);
                        assert_eq!(
                            (stencil.k[l], stencil.c[l], stencil.rest[l]),
                            (0.0, 0.0, 0.0)
                        );
                    }
                }
            }
        }
        assert!(padded > 0, "the edge particles' groups are padded");
    }
}
