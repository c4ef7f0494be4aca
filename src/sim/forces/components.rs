//! Vectors stored one array per component (structure of arrays): what the vector loops of
//! the fast force path read and write.

use std::sync::{Mutex, MutexGuard};

use glam::Vec3;

/// x, y and z of a list of vectors, one array each (all the same length).
pub type Components = [Vec<f32>; 3];

/// Copies the first `n` vectors of `src` into `out`, one array per component.
pub fn split(src: &[Vec3], out: &mut Components, n: usize) {
    for (c, comp) in out.iter_mut().enumerate() {
        comp.clear();
        comp.extend(src[..n].iter().map(|v| v[c]));
    }
}

/// Sets `out` to `n` zero vectors.
pub fn zeroed(out: &mut Components, n: usize) {
    for comp in out {
        comp.clear();
        comp.resize(n, 0.0);
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
