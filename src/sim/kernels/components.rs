//! Vectors stored one array per component (structure of arrays): what the vector loops of
//! the fast force path read and write.

use std::sync::{Mutex, MutexGuard};

use crate::parallel::each_part;

use crate::cloth::{Real, Vector};

/// x, y and z of a list of vectors, one array each (all the same length), in `f32` unless
/// said otherwise.
pub type Components<R = f32> = [Vec<R>; 3];

/// Copies the first `n` vectors of `src` into `out`, one array per component.
pub fn split<R: Real>(src: &[R::V3], out: &mut Components<R>, n: usize) {
    for (c, comp) in out.iter_mut().enumerate() {
        comp.clear();
        comp.extend(src[..n].iter().map(|v| v.to_array()[c]));
    }
}

/// Writes the vectors of `src` (one array per component) into `out`, as many as both hold:
/// the inverse of [`split`].
pub fn join<R: Real>(src: &Components<R>, out: &mut [R::V3]) {
    let [x, y, z] = src;
    for (i, o) in out
        .iter_mut()
        .enumerate()
        .take(x.len().min(y.len()).min(z.len()))
    {
        *o = R::V3::new(x[i], y[i], z[i]);
    }
}

/// Sets `out` to `n` zero vectors (filled by the team from [`each_part`]'s threshold on).
pub fn zeroed<R: Real>(out: &mut Components<R>, n: usize) {
    for comp in out.iter_mut() {
        comp.resize(n, R::ZERO);
    }
    let [x, y, z] = out;
    each_part([x, y, z], |_, parts| {
        parts.into_iter().for_each(|p| p.fill(R::ZERO))
    });
}

/// 3×3 blocks (one per particle or per spring) stored one array per entry, column-major:
/// entry `3c + r` is row `r` of column `c`.
pub type Blocks<R = f32> = [Vec<R>; 9];

/// The elements `range` of each of `N` arrays (a vector's components, a block's entries).
#[inline(always)]
pub fn at<'a, R: 'a, V: AsRef<[R]>, const N: usize>(
    arrays: &'a [V; N],
    range: &std::ops::Range<usize>,
) -> [&'a [R]; N] {
    arrays.each_ref().map(|a| &a.as_ref()[range.clone()])
}

/// `out_i = combine(M_i·u_i, out_i)` for every particle `i` (`M` one block per particle).
#[inline(always)]
pub fn blocks_times<R: Real>(
    m: &Blocks<R>,
    u: &Components<R>,
    out: &mut Components<R>,
    combine: impl Fn(R, R) -> R,
) {
    blocks_times_in(
        m.each_ref().map(|e| &e[..]),
        u.each_ref().map(|c| &c[..]),
        out.each_mut().map(|o| &mut o[..]),
        combine,
    );
}

/// [`blocks_times`] over slices: `m`, `u` and `out` one range of particles' elements (as
/// many particles as all of them hold).
#[inline(always)]
pub fn blocks_times_in<R: Real>(
    m: [&[R]; 9],
    u: [&[R]; 3],
    out: [&mut [R]; 3],
    combine: impl Fn(R, R) -> R,
) {
    let n = (u.iter().chain(&m).map(|v| v.len()))
        .chain(out.iter().map(|o| o.len()))
        .min()
        .unwrap_or(0);
    let [ux, uy, uz] = u.map(|c| &c[..n]);
    for (r, out) in out.into_iter().enumerate() {
        let (c0, c1, c2) = (&m[r][..n], &m[3 + r][..n], &m[6 + r][..n]);
        let out = &mut out[..n];
        for i in 0..n {
            out[i] = combine(c0[i] * ux[i] + c1[i] * uy[i] + c2[i] * uz[i], out[i]);
        }
    }
}

/// Buffers an evaluation reuses between calls through `&self` (not part of the value:
/// clones start empty and comparisons ignore them).
#[derive(Debug, Default)]
pub struct Scratch<T>(Mutex<T>);

impl<T: Default> Clone for Scratch<T> {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl<T> PartialEq for Scratch<T> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl<T> Scratch<T> {
    /// The buffers (a panic elsewhere while they were held leaves them usable).
    pub fn lock(&self) -> MutexGuard<'_, T> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}
