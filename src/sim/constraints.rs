//! The constraint view of the springs, for position-based integrators.

use std::ops::Range;

use glam::Vec3;

/// Distance constraints `|x_b − x_a| = rest`, flat arrays in the springs' order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DistanceConstraints {
    pub a: Vec<u32>,
    pub b: Vec<u32>,
    /// Rest length, metres.
    pub rest: Vec<f32>,
    /// Compliance `1/k`, m/N (0 would be inextensible).
    pub compliance: Vec<f32>,
    /// The spring's dashpot, N·s/m, for constraint damping.
    pub damping: Vec<f32>,
}

impl DistanceConstraints {
    pub fn len(&self) -> usize {
        self.a.len()
    }

    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// The same constraints reordered in *colours*: a run of constraints of which no two
    /// share a particle, then the next run. Gauss–Seidel may visit constraints in any order;
    /// in this one, neighbours in the sweep do not wait on each other's result, so the
    /// processor works on several at once (and the colours are what a parallel sweep
    /// needs). Greedy: each constraint, in the given order, takes the first colour neither
    /// of its particles has yet; at most 64, the last one taking what is left over.
    pub fn coloured(&self) -> Coloured {
        let mut used = vec![0u64; self.particles()];
        let colour: Vec<u32> = (self.a.iter().zip(&self.b))
            .map(|(&a, &b)| {
                let (a, b) = (a as usize, b as usize);
                let free = !(used[a] | used[b]);
                let c = free.trailing_zeros().min(COLOURS - 1);
                used[a] |= 1 << c;
                used[b] |= 1 << c;
                c
            })
            .collect();
        let mut order: Vec<usize> = (0..self.len()).collect();
        order.sort_by_key(|&k| colour[k]);
        let sorted: Vec<u32> = order.iter().map(|&k| colour[k]).collect();
        let colours = sorted
            .chunk_by(|x, y| x == y)
            .scan(0, |end, run| {
                let start = *end;
                *end += run.len();
                Some((start..*end, run[0] < COLOURS - 1))
            })
            .collect();
        Coloured {
            constraints: self.subset(&order),
            colours,
        }
    }

    /// One more than the largest particle a constraint names.
    fn particles(&self) -> usize {
        let last = self.a.iter().chain(&self.b).max();
        last.map_or(0, |&p| p as usize + 1)
    }

    /// Constraints `ks`, in that order.
    fn subset(&self, ks: &[usize]) -> Self {
        let pick = |v: &[f32]| ks.iter().map(|&k| v[k]).collect();
        Self {
            a: ks.iter().map(|&k| self.a[k]).collect(),
            b: ks.iter().map(|&k| self.b[k]).collect(),
            rest: pick(&self.rest),
            compliance: pick(&self.compliance),
            damping: pick(&self.damping),
        }
    }

    fn append(&mut self, other: Self) {
        self.a.extend(other.a);
        self.b.extend(other.b);
        self.rest.extend(other.rest);
        self.compliance.extend(other.compliance);
        self.damping.extend(other.damping);
    }

    /// The same constraints for a sweep in which two threads need to meet only once: the
    /// particles are cut in two halves where the fewest constraints cross (by index, or at
    /// the median of their `positions` along an axis); the constraints within each half come first
    /// (half 0, then half 1), then the *seam* (those with a particle on each side), each of
    /// the three [coloured](Self::coloured). The halves share no particle, so one thread
    /// can sweep each at the same time, and the seam after them; the order does not depend
    /// on how many threads there are.
    pub fn halves(&self, positions: &[Vec3]) -> Halves {
        let side = halves_of(self, positions);
        let side_of = |p: u32| side.get(p as usize).copied();
        let mut classes: [Vec<usize>; 3] = Default::default();
        for (k, (&a, &b)) in self.a.iter().zip(&self.b).enumerate() {
            let class = match (side_of(a), side_of(b)) {
                (Some(x), Some(y)) if x == y => x as usize,
                _ => 2,
            };
            classes[class].push(k);
        }
        let mut constraints = Self::default();
        let [half_0, half_1, seam] = classes.map(|ks| {
            let Coloured {
                constraints: c,
                colours,
            } = self.subset(&ks).coloured();
            let offset = constraints.len();
            constraints.append(c);
            let shift = |r: Range<usize>| r.start + offset..r.end + offset;
            colours.into_iter().map(|(r, i)| (shift(r), i)).collect()
        });
        Halves {
            constraints,
            halves: [half_0, half_1],
            seam,
            particles: self.particles(),
        }
    }
}

/// Each particle's half (0 or 1), cut where the fewest constraints cross: by index (the
/// first half of the particles, which keeps each half's data together in memory, so the
/// threads write to different cache lines), or at the median along x, y or z (for meshes
/// whose numbering wanders); the first of these wins a tie.
fn halves_of(c: &DistanceConstraints, positions: &[Vec3]) -> Vec<u8> {
    let n = positions.len();
    let by_index: Vec<u8> = (0..n).map(|p| u8::from(p >= n / 2)).collect();
    let by_axis = (0..3).map(|axis| {
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&p, &q| {
            positions[p][axis]
                .total_cmp(&positions[q][axis])
                .then(p.cmp(&q))
        });
        let mut side = vec![0; n];
        for &p in &order[n / 2..] {
            side[p] = 1;
        }
        side
    });
    let crossing = |side: &[u8]| {
        let side_of = |p: u32| side.get(p as usize);
        (c.a.iter().zip(&c.b))
            .filter(|&(&a, &b)| side_of(a).is_none() || side_of(a) != side_of(b))
            .count()
    };
    std::iter::once(by_index)
        .chain(by_axis)
        .min_by_key(|side| crossing(side))
        .unwrap_or_default()
}

/// Constraints in two halves that share no particle, and the seam between them
/// ([`DistanceConstraints::halves`]): each part's colours, as in `Coloured`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Halves {
    pub constraints: DistanceConstraints,
    pub halves: [Vec<(Range<usize>, bool)>; 2],
    pub seam: Vec<(Range<usize>, bool)>,
    /// One more than the largest particle a constraint names.
    pub particles: usize,
}

/// Constraints in colour order, with where each colour lies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Coloured {
    pub constraints: DistanceConstraints,
    /// Each colour's constraints, in order, and whether no two of them share a particle
    /// (false only for the last colour, should a mesh need more than 64).
    pub colours: Vec<(Range<usize>, bool)>,
}

/// Most colours [`DistanceConstraints::coloured`] uses (a grid's 12-neighbour stencil needs
/// about 13).
const COLOURS: u32 = 64;

#[cfg(test)]
mod tests {
    use super::*;

    /// How many runs `c` splits into when a run ends just before a constraint that shares a
    /// particle with it.
    fn independent_runs(c: &DistanceConstraints) -> usize {
        let mut seen = std::collections::HashSet::new();
        let mut runs = 0;
        for (&a, &b) in c.a.iter().zip(&c.b) {
            if runs == 0 || seen.contains(&a) || seen.contains(&b) {
                runs += 1;
                seen.clear();
            }
            seen.insert(a);
            seen.insert(b);
        }
        runs
    }

    /// A grid of `n` × `n` particles, each tied to its neighbours at (1, 0), (0, 1), (1, 1),
    /// (2, 0) and (0, 2), and each row's end to the next row's start (so particles differ
    /// in degree); every constraint has its own values.
    fn grid(n: u32) -> DistanceConstraints {
        let mut c = DistanceConstraints::default();
        for j in 0..n {
            for i in 0..n {
                for (di, dj) in [(1, 0), (0, 1), (1, 1), (2, 0), (0, 2)] {
                    if i + di < n && j + dj < n {
                        c.a.push(j * n + i);
                        c.b.push((j + dj) * n + i + di);
                        let k = c.a.len() as f32;
                        c.rest.push(k);
                        c.compliance.push(1.0 / k);
                        c.damping.push(2.0 * k);
                    }
                }
            }
        }
        for (i, j) in (0..n - 1).map(|j| (j * n + n - 1, j * n + n)) {
            c.a.push(i);
            c.b.push(j);
            c.rest.push(0.5);
            c.compliance.push(2.0);
            c.damping.push(1.0);
        }
        c
    }

    /// Each constraint with its own values, in a fixed order (to compare reorderings).
    fn as_set(c: &DistanceConstraints) -> Vec<(u32, u32, u32, u32, u32)> {
        let mut v: Vec<_> = (0..c.len())
            .map(|k| {
                let (a, b) = (c.a[k], c.b[k]);
                (
                    a,
                    b,
                    c.rest[k].to_bits(),
                    c.compliance[k].to_bits(),
                    c.damping[k].to_bits(),
                )
            })
            .collect();
        v.sort_unstable();
        v
    }

    /// Checks `halves`: the same constraints as `c`; every colour free of repeated
    /// particles; no particle in both halves; every seam constraint across them. Returns
    /// the constraints in half 0, half 1 and the seam.
    fn check_halves(c: &DistanceConstraints, halves: &Halves) -> [usize; 3] {
        let h = &halves.constraints;
        assert_eq!(as_set(c), as_set(h));
        let parts = [&halves.halves[0], &halves.halves[1], &halves.seam];
        let mut end = 0;
        let particles = parts.map(|colours| {
            let mut all = std::collections::HashSet::new();
            for (range, independent) in colours {
                assert!(*independent);
                assert_eq!(range.start, end, "the parts tile the constraints in order");
                end = range.end;
                let mut seen = std::collections::HashSet::new();
                for k in range.clone() {
                    assert!(seen.insert(h.a[k]) && seen.insert(h.b[k]));
                    all.extend([h.a[k], h.b[k]]);
                }
            }
            all
        });
        assert_eq!(end, c.len());
        assert!(particles[0].is_disjoint(&particles[1]));
        for (range, _) in &halves.seam {
            for k in range.clone() {
                let ends = [h.a[k], h.b[k]];
                assert!(!(0..2).any(|s| ends.iter().all(|p| particles[s].contains(p))));
            }
        }
        parts.map(|colours| colours.iter().map(|(r, _)| r.len()).sum())
    }

    #[test]
    fn halves_share_no_particle_and_only_a_thin_seam_crosses_even_when_numbering_wanders() {
        let n = 30u32;
        let c = grid(n);
        let positions: Vec<Vec3> = (0..n * n)
            .map(|p| Vec3::new((p % n) as f32, (p / n) as f32, 0.0))
            .collect();
        // Balanced halves; the seam is the constraints across one cut of the grid (under
        // 5 per particle along it), not the half that a careless cut would leave there.
        let [h0, h1, seam] = check_halves(&c, &c.halves(&positions));
        assert!(h0.abs_diff(h1) < c.len() / 20, "{h0} / {h1}");
        assert!(seam > 0 && seam < 5 * n as usize, "{seam} across the seam");
        // Cut by number, so each half's particles lie together in memory: also when (without
        // the ties from row to row) a cut down the columns would be as thin.
        let by_number = || (0..n * n).map(|p| u8::from(p >= n * n / 2));
        assert!(halves_of(&c, &positions).into_iter().eq(by_number()));
        let square: Vec<usize> = (0..c.len() - (n as usize - 1)).collect();
        let square = c.subset(&square);
        assert!(halves_of(&square, &positions).into_iter().eq(by_number()));
        // The same cloth numbered in a scrambled order: cut in space instead.
        let scramble = |p: u32| (p * 7919) % (n * n);
        let mut scrambled = c.clone();
        for p in scrambled.a.iter_mut().chain(scrambled.b.iter_mut()) {
            *p = scramble(*p);
        }
        let mut moved = vec![Vec3::ZERO; positions.len()];
        for (p, x) in positions.iter().enumerate() {
            moved[scramble(p as u32) as usize] = *x;
        }
        let [h0, h1, seam] = check_halves(&scrambled, &scrambled.halves(&moved));
        assert!(h0.abs_diff(h1) < c.len() / 20, "{h0} / {h1}");
        assert!(seam > 0 && seam < 5 * n as usize, "{seam} across the seam");
    }

    #[test]
    fn colouring_reorders_a_grid_into_few_runs_without_shared_particles() {
        let c = grid(30);
        let Coloured {
            constraints: coloured,
            colours,
        } = c.coloured();
        // The colours tile the constraints, and within each no particle repeats.
        assert_eq!(colours.len(), independent_runs(&coloured));
        assert_eq!(colours.last().map(|c| c.0.end), Some(c.len()));
        for (range, independent) in &colours {
            assert!(*independent);
            let mut seen = std::collections::HashSet::new();
            for k in range.clone() {
                assert!(seen.insert(coloured.a[k]) && seen.insert(coloured.b[k]));
            }
        }
        // The 10-neighbour stencil's degree is 10: the greedy colouring stays near it.
        assert!(independent_runs(&c) > 1000);
        let runs = independent_runs(&coloured);
        assert!(runs <= 14, "{runs} runs");
        // The same constraints, each with its own values.
        assert_eq!(as_set(&c), as_set(&coloured));
    }
}
