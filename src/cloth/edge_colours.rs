//! The cloth's edges (its structural and shear springs) in colours: an order in which each
//! run of edges shares no particle, so that a pass over them one edge after another (the
//! CPU's) and one run at a time with the run's edges side by side (the GPU's) visit them
//! in the same order and give the same result.

use std::ops::Range;

use super::Springs;

/// Colours a greedy pass can give before an edge goes to the last run, whose edges may
/// share particles (a particle with 64 edges or more).
const MOST: usize = 64;

/// The edges in colour order and each colour's run of them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EdgeColours {
    /// Spring numbers (all below the first bend spring), colour after colour.
    pub order: Vec<u32>,
    /// Each edge's two particles, in the same order (a pass reads them in turn rather than
    /// looking each spring up).
    pub ends: Vec<[u32; 2]>,
    /// Each colour's range of `order`, and whether its edges may share a particle (then
    /// they must be taken one after another).
    pub runs: Vec<(Range<usize>, bool)>,
}

impl EdgeColours {
    /// The first `edges` of `springs` over `particles` particles, coloured greedily in their
    /// order: each takes the lowest colour neither of its ends has yet.
    pub fn of(particles: usize, springs: &Springs, edges: usize) -> Self {
        let mut used = vec![0u64; particles];
        let mut by_colour: Vec<Vec<u32>> = vec![Vec::new(); MOST + 1];
        for e in 0..edges.min(springs.len()) {
            let (a, b) = (springs.a[e] as usize, springs.b[e] as usize);
            let colour = (!(used[a] | used[b])).trailing_zeros() as usize;
            if colour < MOST {
                used[a] |= 1 << colour;
                used[b] |= 1 << colour;
            }
            by_colour[colour].push(e as u32);
        }
        let mut out = EdgeColours::default();
        for (colour, list) in by_colour.into_iter().enumerate() {
            if !list.is_empty() {
                let start = out.order.len();
                out.order.extend(list);
                out.runs.push((start..out.order.len(), colour == MOST));
            }
        }
        (out.ends).extend(
            out.order
                .iter()
                .map(|&e| [springs.a[e as usize], springs.b[e as usize]]),
        );
        out
    }
}
