//! The cloth's edges (its structural and shear springs) in colours: an order in which each
//! run of edges shares no particle, so that a pass over them one edge after another (the
//! CPU's) and one run at a time with the run's edges side by side (the GPU's) visit them
//! in the same order and give the same result. The GPU colours the cloth's triangles the
//! same way ([`colour_greedily`]).

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
        let edges = (0..edges.min(springs.len())).map(|e| [springs.a[e], springs.b[e]]);
        let (order, runs) = colour_greedily(particles, edges);
        let ends = (order.iter())
            .map(|&e| [springs.a[e as usize], springs.b[e as usize]])
            .collect();
        EdgeColours { order, ends, runs }
    }
}

/// `items` (each the particles it moves, of `particles`) coloured greedily in their order:
/// each takes the lowest colour none of its particles has yet. Returns their numbers colour
/// after colour, and each colour's range of them with whether its items may share a
/// particle (the last, past 64 colours).
pub fn colour_greedily<const K: usize>(
    particles: usize,
    items: impl Iterator<Item = [u32; K]>,
) -> (Vec<u32>, Vec<(Range<usize>, bool)>) {
    let mut used = vec![0u64; particles];
    let mut by_colour: Vec<Vec<u32>> = vec![Vec::new(); MOST + 1];
    for (k, item) in items.enumerate() {
        let taken = item.iter().fold(0, |m, &p| m | used[p as usize]);
        let colour = (!taken).trailing_zeros() as usize;
        if colour < MOST {
            item.iter().for_each(|&p| used[p as usize] |= 1 << colour);
        }
        by_colour[colour].push(k as u32);
    }
    let (mut order, mut runs) = (Vec::new(), Vec::new());
    for (colour, list) in by_colour.into_iter().enumerate() {
        if !list.is_empty() {
            let start = order.len();
            order.extend(list);
            runs.push((start..order.len(), colour == MOST));
        }
    }
    (order, runs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid's triangles, each once, in colours whose triangles share no particle; a
    /// greedy colouring of a grid (six triangles round a vertex) needs few colours.
    #[test]
    fn a_grids_triangles_in_colours_share_no_particle() {
        let n = 9u32;
        let id = |i: u32, j: u32| i * (n + 1) + j;
        let triangles: Vec<[u32; 3]> = (0..n * n)
            .flat_map(|q| {
                let (i, j) = (q / n, q % n);
                let (a, b, c, d) = (id(i, j), id(i, j + 1), id(i + 1, j), id(i + 1, j + 1));
                [[a, b, d], [a, d, c]]
            })
            .collect();
        let particles = ((n + 1) * (n + 1)) as usize;
        let (order, runs) = colour_greedily(particles, triangles.iter().copied());
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..triangles.len() as u32).collect::<Vec<_>>());
        assert!((3..=12).contains(&runs.len()), "{} colours", runs.len());
        for (range, shared) in &runs {
            assert!(!shared);
            let mut touched = vec![false; particles];
            for &t in &order[range.clone()] {
                for p in triangles[t as usize] {
                    assert!(!touched[p as usize], "triangle {t} shares particle {p}");
                    touched[p as usize] = true;
                }
            }
        }
    }

    /// Past the colours a greedy pass can give, the rest go to one last run, which says
    /// its items may share particles.
    #[test]
    fn items_past_the_last_colour_share_one_run() {
        let fan: Vec<[u32; 2]> = (1..=MOST as u32 + 3).map(|k| [0, k]).collect();
        let (order, runs) = colour_greedily(MOST + 4, fan.into_iter());
        assert_eq!(order.len(), MOST + 3);
        assert_eq!(runs.len(), MOST + 1);
        assert_eq!(runs.last(), Some(&(MOST..MOST + 3, true)));
    }
}
