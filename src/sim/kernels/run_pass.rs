//! What a block pass computes for each run of springs: their forces, their system blocks,
//! or those blocks times a vector. Each is one loop over contiguous arrays that the compiler
//! vectorises.

use std::ops::Range;

use super::components::{Components, at};
use crate::cloth::Real;
use crate::parallel::Disjoint;

/// Springs' system blocks `α·I + β·n nᵀ` in run order: `[α, β, n.x, n.y, n.z]`, one array
/// each ([`SpringRuns::add_system_blocks`](super::SpringRuns::add_system_blocks) writes them,
/// [`SpringRuns::add_block_products`](super::SpringRuns::add_block_products) reads them).
pub type Projectors<R = f32> = [Vec<R>; 5];

/// What a block pass does with each run: `run` gets the run's two ranges of ends, its
/// springs (run order) and its slices of the block's buffers at its first ends and at its
/// second ends (where what it puts is subtracted), which it overwrites (`WRITE`: `0 + x`,
/// the bits of adding to zero) or adds to.
pub(super) trait RunPass<R: Real>: Sync {
    fn run<const WRITE: bool>(
        &self,
        ends: [Range<usize>; 2],
        springs: Range<usize>,
        first: [&mut [R]; 3],
        second: [&mut [R]; 3],
    );
}

/// The spring forces (see [`kernel`]).
#[derive(Clone, Copy)]
pub(super) struct ForcePass<'a, R: Real> {
    pub(super) rest: &'a [R],
    pub(super) k: &'a [R],
    pub(super) c: &'a [R],
    pub(super) p: &'a Components<R>,
    pub(super) v: &'a Components<R>,
}

impl<R: Real> RunPass<R> for ForcePass<'_, R> {
    #[inline(always)]
    fn run<const WRITE: bool>(
        &self,
        [ea, eb]: [Range<usize>; 2],
        springs: Range<usize>,
        first: [&mut [R]; 3],
        second: [&mut [R]; 3],
    ) {
        let (p, v) = (self.p, self.v);
        kernel::<R, WRITE>(
            at(p, &ea),
            at(p, &eb),
            at(v, &ea),
            at(v, &eb),
            [
                &self.rest[springs.clone()],
                &self.k[springs.clone()],
                &self.c[springs],
            ],
            first,
            second,
        );
    }
}

/// Block products `S_e·u_other` at both ends (see
/// [`SpringRuns::add_block_products`](super::SpringRuns::add_block_products)).
pub(super) struct ProductPass<'a, R: Real> {
    pub(super) s: &'a Projectors<R>,
    pub(super) u: &'a Components<R>,
}

impl<R: Real> RunPass<R> for ProductPass<'_, R> {
    #[inline(always)]
    fn run<const WRITE: bool>(
        &self,
        [ea, eb]: [Range<usize>; 2],
        springs: Range<usize>,
        first: [&mut [R]; 3],
        second: [&mut [R]; 3],
    ) {
        let (s, u) = (self.s, self.u);
        let n = springs.len();
        let [al, be, nx, ny, nz]: [&[R]; 5] = std::array::from_fn(|k| &s[k][springs.clone()][..n]);
        let [ax, ay, az] = at(u, &(ea.start..ea.start + n));
        let [bx, by, bz] = at(u, &(eb.start..eb.start + n));
        let [f0, f1, f2] = first;
        let [t0, t1, t2] = second;
        let (f0, f1, f2) = (&mut f0[..n], &mut f1[..n], &mut f2[..n]);
        let (t0, t1, t2) = (&mut t0[..n], &mut t1[..n], &mut t2[..n]);
        let was = |o: R| if WRITE { R::ZERO } else { o };
        for j in 0..n {
            // Every input read before any output is written: the compiler need not prove
            // that the outputs alias none of them to keep them in registers.
            let (al, be, u) = (al[j], be[j], [nx[j], ny[j], nz[j]]);
            let (a, b) = ([ax[j], ay[j], az[j]], [bx[j], by[j], bz[j]]);
            // S·w = α·w + β(n·w)·n, n = u.
            let db = be * (u[0] * b[0] + u[1] * b[1] + u[2] * b[2]);
            let da = be * (u[0] * a[0] + u[1] * a[1] + u[2] * a[2]);
            f0[j] = was(f0[j]) + (al * b[0] + db * u[0]);
            f1[j] = was(f1[j]) + (al * b[1] + db * u[1]);
            f2[j] = was(f2[j]) + (al * b[2] + db * u[2]);
            // Subtracted when gathered.
            t0[j] = was(t0[j]) - (al * a[0] + da * u[0]);
            t1[j] = was(t1[j]) - (al * a[1] + da * u[1]);
            t2[j] = was(t2[j]) - (al * a[2] + da * u[2]);
        }
    }
}

/// The force on each spring's first end, for springs whose ends' positions and velocities
/// are given per component: `[k(|d| − l₀) + c(v_b − v_a)·d̂] d̂`, zero for coincident ends;
/// added to `first` (at the first ends) and to `second` (at the second ends, where it is
/// subtracted later). Computed as `g·d` with `g = [k(|d| − l₀) + c((v_b − v_a)·d)/|d|]/|d|`,
/// with fused multiply-adds: 27 operations a spring where `n = d/|d|` first took 36.
/// `WRITE`: overwrites `first` and `second` instead (with `g·d + 0`, the same bits as
/// adding to zeroed sums).
#[inline(always)]
fn kernel<R: Real, const WRITE: bool>(
    xa: [&[R]; 3],
    xb: [&[R]; 3],
    va: [&[R]; 3],
    vb: [&[R]; 3],
    params: [&[R]; 3],
    first: [&mut [R]; 3],
    second: [&mut [R]; 3],
) {
    let n = first[0].len();
    let [ox, oy, oz] = first;
    let (ox, oy, oz) = (&mut ox[..n], &mut oy[..n], &mut oz[..n]);
    let [tx, ty, tz] = second;
    let (tx, ty, tz) = (&mut tx[..n], &mut ty[..n], &mut tz[..n]);
    let (xax, xay, xaz) = (&xa[0][..n], &xa[1][..n], &xa[2][..n]);
    let (xbx, xby, xbz) = (&xb[0][..n], &xb[1][..n], &xb[2][..n]);
    let (vax, vay, vaz) = (&va[0][..n], &va[1][..n], &va[2][..n]);
    let (vbx, vby, vbz) = (&vb[0][..n], &vb[1][..n], &vb[2][..n]);
    let (rest, k, c) = (&params[0][..n], &params[1][..n], &params[2][..n]);
    for j in 0..n {
        let (dx, dy, dz) = (xbx[j] - xax[j], xby[j] - xay[j], xbz[j] - xaz[j]);
        let len = dz.mul_add(dz, dy.mul_add(dy, dx * dx)).sqrt();
        let inv = if len > R::TINY_LENGTH {
            R::ONE / len
        } else {
            R::ZERO
        };
        let (ux, uy, uz) = (vbx[j] - vax[j], vby[j] - vay[j], vbz[j] - vaz[j]);
        let along = uz.mul_add(dz, uy.mul_add(dy, ux * dx));
        let s = c[j].mul_add(along * inv, k[j] * (len - rest[j]));
        let g = s * inv;
        let was = |o: R| if WRITE { R::ZERO } else { o };
        ox[j] = g.mul_add(dx, was(ox[j]));
        oy[j] = g.mul_add(dy, was(oy[j]));
        oz[j] = g.mul_add(dz, was(oz[j]));
        tx[j] = g.mul_add(dx, was(tx[j]));
        ty[j] = g.mul_add(dy, was(ty[j]));
        tz[j] = g.mul_add(dz, was(tz[j]));
    }
}

/// The springs' system blocks (see
/// [`SpringRuns::add_system_blocks`](super::SpringRuns::add_system_blocks)): each spring's
/// `[α, β, n]` written at its place in run order, and `K_x·(v_b − v_a)` summed at its first
/// ends (and at its second, where it is subtracted).
pub(super) struct SystemPass<'a, 'b, R: Real> {
    /// The springs' strengths and the state, as the forces take them.
    pub(super) springs: ForcePass<'a, R>,
    pub(super) h: R,
    /// `[α, β, n.x, n.y, n.z]` in run order; each run writes its own springs' places.
    pub(super) blocks: [Disjoint<'b, R>; 5],
}

impl<R: Real> RunPass<R> for SystemPass<'_, '_, R> {
    #[inline(always)]
    fn run<const WRITE: bool>(
        &self,
        [ea, eb]: [Range<usize>; 2],
        springs: Range<usize>,
        first: [&mut [R]; 3],
        second: [&mut [R]; 3],
    ) {
        let ForcePass { rest, k, c, p, v } = self.springs;
        // SAFETY: a run's springs are its own places in run order; no other run writes them.
        let [al, be, nx, ny, nz] =
            (self.blocks.each_ref()).map(|b| unsafe { b.part(springs.clone()) });
        let ([f0, f1, f2], [t0, t1, t2]) = (first, second);
        system_kernel::<R, WRITE>(
            [at(p, &ea), at(p, &eb), at(v, &ea), at(v, &eb)],
            [rest, k, c].map(|s| &s[springs.clone()]),
            self.h,
            [al, be, nx, ny, nz],
            [f0, f1, f2, t0, t1, t2],
        );
    }
}

/// [`SystemPass`]'s loop: `ends` the positions at the first and second ends, then the
/// velocities; `blocks` as [`SystemPass::blocks`]; `sums` the three components at the
/// first ends, then at the second. The outputs come through [`system_kernel_in`]'s own
/// arguments, so that the compiler knows that none overlaps another: passed in arrays,
/// eleven of them, it would have to check at run time, and does not vectorise the loop.
#[inline(always)]
fn system_kernel<R: Real, const WRITE: bool>(
    ends: [[&[R]; 3]; 4],
    params: [&[R]; 3],
    h: R,
    [al, be, nx, ny, nz]: [&mut [R]; 5],
    [f0, f1, f2, t0, t1, t2]: [&mut [R]; 6],
) {
    system_kernel_in::<R, WRITE>(ends, params, h, al, be, nx, ny, nz, f0, f1, f2, t0, t1, t2);
}

/// [`system_kernel`] with each output its own argument.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn system_kernel_in<R: Real, const WRITE: bool>(
    ends: [[&[R]; 3]; 4],
    params: [&[R]; 3],
    h: R,
    al: &mut [R],
    be: &mut [R],
    nx: &mut [R],
    ny: &mut [R],
    nz: &mut [R],
    f0: &mut [R],
    f1: &mut [R],
    f2: &mut [R],
    t0: &mut [R],
    t1: &mut [R],
    t2: &mut [R],
) {
    let n = f0.len();
    let one = R::ONE;
    let [
        [xax, xay, xaz],
        [xbx, xby, xbz],
        [vax, vay, vaz],
        [vbx, vby, vbz],
    ] = ends.map(|e| e.map(|s| &s[..n]));
    let [rest, k, c] = params.map(|s| &s[..n]);
    let (al, be) = (&mut al[..n], &mut be[..n]);
    let (nx, ny, nz) = (&mut nx[..n], &mut ny[..n], &mut nz[..n]);
    let (f0, f1, f2) = (&mut f0[..n], &mut f1[..n], &mut f2[..n]);
    let (t0, t1, t2) = (&mut t0[..n], &mut t1[..n], &mut t2[..n]);
    let was = |o: R| if WRITE { R::ZERO } else { o };
    for j in 0..n {
        let (dx, dy, dz) = (xbx[j] - xax[j], xby[j] - xay[j], xbz[j] - xaz[j]);
        let len = (dx * dx + dy * dy + dz * dz).sqrt();
        // Coincident ends have no direction: their blocks and terms are zero.
        let live = len > R::TINY_LENGTH;
        let inv = if live { one / len } else { R::ZERO };
        let (ux, uy, uz) = (dx * inv, dy * inv, dz * inv);
        // `max(0, 1 − l₀/|d|)` as a select, which the compiler vectorises.
        let s = one - rest[j] * inv;
        let s = if s > R::ZERO { s } else { R::ZERO };
        // Read whether or not they are used: a read under a condition is not vectorised.
        let (kj, cj) = (k[j], c[j]);
        let kj = if live { kj } else { R::ZERO };
        let cj = if live { cj } else { R::ZERO };
        let (ks, kt) = (kj * s, kj * (one - s));
        let (wx, wy, wz) = (vbx[j] - vax[j], vby[j] - vay[j], vbz[j] - vaz[j]);
        let along = kt * (ux * wx + uy * wy + uz * wz);
        let (gx, gy, gz) = (
            wx * ks + ux * along,
            wy * ks + uy * along,
            wz * ks + uz * along,
        );
        (al[j], be[j]) = (h * h * ks, h * cj + h * h * kt);
        (nx[j], ny[j], nz[j]) = (ux, uy, uz);
        f0[j] = was(f0[j]) + gx;
        f1[j] = was(f1[j]) + gy;
        f2[j] = was(f2[j]) + gz;
        // Subtracted when gathered.
        t0[j] = was(t0[j]) + gx;
        t1[j] = was(t1[j]) + gy;
        t2[j] = was(t2[j]) + gz;
    }
}

/// The springs' blocks `α·I + β·n nᵀ` summed at both ends: their diagonal entries
/// (`xx, yy, zz`) or, with `OFF`, the entries off it (`xy, xz, yz`).
pub(super) struct DiagonalPass<'a, R: Real, const OFF: bool> {
    pub(super) blocks: &'a Projectors<R>,
}

impl<R: Real, const OFF: bool> RunPass<R> for DiagonalPass<'_, R, OFF> {
    #[inline(always)]
    fn run<const WRITE: bool>(
        &self,
        _ends: [Range<usize>; 2],
        springs: Range<usize>,
        first: [&mut [R]; 3],
        second: [&mut [R]; 3],
    ) {
        let n = springs.len();
        let [al, be, nx, ny, nz]: [&[R]; 5] =
            std::array::from_fn(|k| &self.blocks[k][springs.clone()][..n]);
        let [f0, f1, f2] = first;
        let [t0, t1, t2] = second;
        let (f0, f1, f2) = (&mut f0[..n], &mut f1[..n], &mut f2[..n]);
        let (t0, t1, t2) = (&mut t0[..n], &mut t1[..n], &mut t2[..n]);
        let was = |o: R| if WRITE { R::ZERO } else { o };
        for j in 0..n {
            let (a, b, x, y, z) = (al[j], be[j], nx[j], ny[j], nz[j]);
            let m = if OFF {
                [b * x * y, b * x * z, b * y * z]
            } else {
                [a + b * x * x, a + b * y * y, a + b * z * z]
            };
            f0[j] = was(f0[j]) + m[0];
            f1[j] = was(f1[j]) + m[1];
            f2[j] = was(f2[j]) + m[2];
            // Subtracted when gathered: both ends get `+m`.
            t0[j] = was(t0[j]) - m[0];
            t1[j] = was(t1[j]) - m[1];
            t2[j] = was(t2[j]) - m[2];
        }
    }
}
