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
                springs: self.force_pass(p, v),
                h,
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
