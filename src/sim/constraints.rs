//! The constraint view of the springs, for position-based integrators.

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
        let particles = self.a.iter().chain(&self.b).map(|&p| p as usize + 1).max();
        let mut used = vec![0u64; particles.unwrap_or(0)];
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
        let pick = |v: &[f32]| order.iter().map(|&k| v[k]).collect();
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
            constraints: Self {
                a: order.iter().map(|&k| self.a[k]).collect(),
                b: order.iter().map(|&k| self.b[k]).collect(),
                rest: pick(&self.rest),
                compliance: pick(&self.compliance),
                damping: pick(&self.damping),
            },
            colours,
        }
    }
}

/// Constraints in colour order, with where each colour lies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Coloured {
    pub constraints: DistanceConstraints,
    /// Each colour's constraints, in order, and whether no two of them share a particle
    /// (false only for the last colour, should a mesh need more than 64).
    pub colours: Vec<(std::ops::Range<usize>, bool)>,
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

    #[test]
    fn colouring_reorders_a_grid_into_few_runs_without_shared_particles() {
        let n = 30u32;
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
            // A row's end and the next row's start, so particles differ in degree.
            c.a.push(i);
            c.b.push(j);
            c.rest.push(0.5);
            c.compliance.push(2.0);
            c.damping.push(1.0);
        }
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
        let set = |c: &DistanceConstraints| {
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
        };
        assert_eq!(set(&c), set(&coloured));
    }
}
