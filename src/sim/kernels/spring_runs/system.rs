//! The springs' blocks of the implicit system, computed in run order: the same vector
//! loops and threads as the forces.

use crate::cloth::Real;
use crate::parallel::Disjoint;

use super::super::components::Components;
use super::super::run_pass::{DiagonalPass, Projectors, SystemPass};
use super::{GHOST, SpringRuns};

/// What [`SpringRuns::add_system_blocks`] adds per particle: the springs' blocks summed on
/// the diagonal and `Σ K_x·(v_other − v_self)`.
#[derive(Clone, Debug, Default)]
pub struct SystemSums<R: Real = f32> {
    /// `xx, yy, zz` of the summed blocks.
    pub diagonal: Components<R>,
    /// `xy, xz, yz` of the summed blocks (they are symmetric).
    pub off_diagonal: Components<R>,
    /// `(∂f/∂x)·v`, N/s.
    pub dfdx_v: Components<R>,
}

impl<R: Real> SpringRuns<R> {
    /// Each spring's definite system block `S_e = h·K_v + h²·K_x = α·I + β·n nᵀ` at
    /// positions `p` and velocities `v` (the blocks of
    /// [`SpringForce::add_to_system`](crate::sim::forces::SpringForce::add_to_system)),
    /// written to `blocks` in run order as `[α, β, n.x, n.y, n.z]` (zero for fillers and
    /// coincident ends), and added to `sums`: `S_e` on the diagonal at both ends and
    /// `K_x·(v_b − v_a)` at `a`, its negative at `b`. `sums` must hold every particle. In
    /// parallel as the forces are, with the same result on any number of threads.
    pub fn add_system_blocks(
        &self,
        p: &Components<R>,
        v: &Components<R>,
        h: R,
        blocks: &mut Projectors<R>,
        sums: &mut SystemSums<R>,
    ) {
        // Every place is written below (fillers too), so the blocks need no zeroing.
        for b in blocks.iter_mut() {
            b.resize(self.order.len(), R::ZERO);
        }
        let outs = [&sums.diagonal, &sums.off_diagonal, &sums.dfdx_v];
        let n = (p.iter().chain(v).chain(outs.into_iter().flatten()))
            .map(Vec::len)
            .fold(self.particles, usize::min);
        if self.runs.is_empty() || n < self.particles {
            blocks.iter_mut().for_each(|b| b.fill(R::ZERO));
            return;
        }
        let mut buffers = self.scratch.lock();
        let bufs = &mut buffers.blocks;
        {
            let pass = SystemPass {
                rest: &self.rest,
                k: &self.k,
                c: &self.c,
                h,
                p,
                v,
                blocks: blocks.each_mut().map(|b| Disjoint::new(&mut b[..])),
            };
            self.block_sums(bufs, |block, buf| self.block_pass(block, buf, &pass));
        }
        self.gather_components(bufs, &mut sums.dfdx_v, n);
        let on = DiagonalPass::<R, false> { blocks };
        self.block_sums(bufs, |block, buf| self.block_pass(block, buf, &on));
        self.gather_components(bufs, &mut sums.diagonal, n);
        let off = DiagonalPass::<R, true> { blocks };
        self.block_sums(bufs, |block, buf| self.block_pass(block, buf, &off));
        self.gather_components(bufs, &mut sums.off_diagonal, n);
    }

    /// Whether the runs were made for `particles` particles.
    pub fn covers(&self, particles: usize) -> bool {
        self.particles == particles
    }

    /// Each place in run order that holds a spring, with that spring's index as given to
    /// [`SpringRuns::new`].
    pub fn places(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (self.order.iter().enumerate())
            .filter(|&(_, &e)| e != GHOST)
            .map(|(place, &e)| (place, e as usize))
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::super::components::split;
    use super::*;

    /// One spring's block and `K_x·(v_b − v_a)` by the formula, spring by spring:
    /// `None` for coincident ends.
    fn by_formula(
        d: Vec3,
        w: Vec3,
        (rest, k, c, h): (f32, f32, f32, f32),
    ) -> Option<([f32; 5], Vec3)> {
        let len = d.length();
        if len <= 1e-9 {
            return None;
        }
        let n = d / len;
        let s = (1.0 - rest / len).max(0.0);
        let (alpha, beta) = (h * h * k * s, h * c + h * h * k * (1.0 - s));
        let dfdx_w = k * s * w + k * (1.0 - s) * n.dot(w) * n;
        Some(([alpha, beta, n.x, n.y, n.z], dfdx_w))
    }

    /// A 60 × 50 grid's stencil springs (ends in either order, several blocks) and some
    /// random ones, stretched and compressed (the transverse stiffness clamps), two of them
    /// with coincident ends: every spring's block in run order and the sums at its ends are
    /// the formula's, and one thread and two give the same bits.
    #[test]
    fn system_blocks_are_each_springs_by_the_formula_on_any_number_of_threads() {
        let (w, rows) = (60usize, 50usize);
        let n = w * rows;
        let mut rnd = crate::test_rng::uniform(4242);
        let mut pos: Vec<Vec3> = (0..n)
            .map(|p| Vec3::new((p % w) as f32, -((p / w) as f32), rnd()) * 0.01)
            .collect();
        let vel: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rnd(), rnd(), rnd()) - 0.5)
            .collect();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for p in 0..n {
            for (di, dj) in [(1, 0), (0, 1), (1, 1), (0, 2)] {
                let (i, j) = (p % w + di, p / w + dj);
                if i < w && j < rows {
                    let q = (j * w + i) as u32;
                    let (x, y) = if rnd() < 0.5 {
                        (p as u32, q)
                    } else {
                        (q, p as u32)
                    };
                    a.push(x);
                    b.push(y);
                }
            }
        }
        for _ in 0..300 {
            a.push((rnd() * n as f32) as u32 % n as u32);
            b.push((rnd() * n as f32) as u32 % n as u32);
        }
        // Coincident ends: particle 1 and 61 on top of their stencil neighbours 0 and 60.
        pos[1] = pos[0];
        pos[61] = pos[60];
        let rest: Vec<f32> = (0..a.len()).map(|_| 0.005 + 0.02 * rnd()).collect();
        let k: Vec<f32> = (0..a.len()).map(|_| 100.0 + 900.0 * rnd()).collect();
        let c: Vec<f32> = (0..a.len()).map(|_| 0.05 * rnd()).collect();
        let h = 1.0 / 240.0;
        let runs = SpringRuns::new(n, &a, &b, &rest, &k, &c);
        let (mut p, mut v) = (Components::default(), Components::default());
        split(&pos, &mut p, n);
        split(&vel, &mut v, n);
        let assemble = |runs: &SpringRuns| {
            let mut blocks = Projectors::default();
            let mut sums = SystemSums::default();
            for s in [&mut sums.diagonal, &mut sums.off_diagonal, &mut sums.dfdx_v] {
                *s = std::array::from_fn(|_| vec![0.0; n]);
            }
            runs.add_system_blocks(&p, &v, h, &mut blocks, &mut sums);
            (blocks, sums)
        };
        let (blocks, sums) = assemble(&runs);

        let (mut diagonal, mut dfdx) = (vec![[0.0f32; 6]; n], vec![Vec3::ZERO; n]);
        let mut want_blocks = vec![None; a.len()];
        let (mut stretched, mut compressed, mut coincident) = (0, 0, 0);
        for e in 0..a.len() {
            let (i, j) = (a[e] as usize, b[e] as usize);
            if i == j {
                continue;
            }
            let d = pos[j] - pos[i];
            let Some((block, g)) = by_formula(d, vel[j] - vel[i], (rest[e], k[e], c[e], h)) else {
                coincident += 1;
                want_blocks[e] = Some([0.0; 5]);
                continue;
            };
            if d.length() > rest[e] {
                stretched += 1;
            } else {
                compressed += 1;
            }
            let [al, be, x, y, z] = block;
            let entries = [
                al + be * x * x,
                al + be * y * y,
                al + be * z * z,
                be * x * y,
                be * x * z,
                be * y * z,
            ];
            for end in [i, j] {
                for (s, e) in diagonal[end].iter_mut().zip(entries) {
                    *s += e;
                }
            }
            dfdx[i] += g;
            dfdx[j] -= g;
            want_blocks[e] = Some(block);
        }
        assert!(stretched > 100 && compressed > 100 && coincident == 2);

        for (place, e) in runs.places() {
            let got = blocks.each_ref().map(|b| b[place]);
            let mut want = want_blocks[e].expect("a spring from a particle to itself has no place");
            // The runs take each spring from its lower-numbered end.
            if a[e] > b[e] {
                want[2..].iter_mut().for_each(|x| *x = -*x);
            }
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (g - w).abs() <= 1e-6 * (1.0 + w.abs()),
                    "spring {e}: {got:?} vs {want:?}"
                );
            }
        }
        let largest = |v: &[f32]| v.iter().fold(0.0f32, |m, x| m.max(x.abs()));
        let scale = diagonal.iter().map(|d| largest(d)).fold(0.0, f32::max);
        let g_scale = dfdx.iter().map(|g| g.length()).fold(0.0, f32::max);
        assert!(scale > 0.0 && g_scale > 0.0);
        for i in 0..n {
            let got = [
                sums.diagonal[0][i],
                sums.diagonal[1][i],
                sums.diagonal[2][i],
                sums.off_diagonal[0][i],
                sums.off_diagonal[1][i],
                sums.off_diagonal[2][i],
            ];
            for (g, w) in got.iter().zip(diagonal[i]) {
                assert!(
                    (g - w).abs() <= 1e-5 * scale,
                    "particle {i}: {got:?} vs {:?}",
                    diagonal[i]
                );
            }
            let g = Vec3::new(sums.dfdx_v[0][i], sums.dfdx_v[1][i], sums.dfdx_v[2][i]);
            assert!(
                (g - dfdx[i]).length() <= 1e-5 * g_scale,
                "particle {i}: {g} vs {}",
                dfdx[i]
            );
        }

        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool");
            let parallel = runs.clone().parallel_from(1);
            let (b2, s2) = pool.install(|| assemble(&parallel));
            assert!(b2 == blocks, "{threads} threads: the blocks");
            let same = [
                (&s2.diagonal, &sums.diagonal),
                (&s2.off_diagonal, &sums.off_diagonal),
                (&s2.dfdx_v, &sums.dfdx_v),
            ];
            assert!(
                same.iter().all(|(x, y)| x == y),
                "{threads} threads: the sums"
            );
        }
    }
}
