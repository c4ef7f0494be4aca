//! A mutable slice that a team's members take disjoint parts of.

use super::ranges::clamped;

/// A slice that members take disjoint parts of, each its own.
pub struct Disjoint<'a, T> {
    start: *mut T,
    len: usize,
    _slice: std::marker::PhantomData<&'a mut [T]>,
}

// SAFETY: members only reach the elements through `part`, whose contract keeps their
// parts disjoint; `T: Send` lets each part be used on another thread.
unsafe impl<T: Send> Sync for Disjoint<'_, T> {}

impl<'a, T> Disjoint<'a, T> {
    pub fn new(slice: &'a mut [T]) -> Self {
        Self {
            start: slice.as_mut_ptr(),
            len: slice.len(),
            _slice: std::marker::PhantomData,
        }
    }

    /// The first element, for kernels that gather through raw pointers (they must keep
    /// [`Disjoint::part`]'s contract themselves).
    pub fn as_ptr(&self) -> *mut T {
        self.start
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Elements `range` (clamped to the slice).
    ///
    /// # Safety
    /// No two parts in use at the same time may overlap.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn part(&self, range: std::ops::Range<usize>) -> &mut [T] {
        let range = clamped(range, self.len);
        // SAFETY: in bounds (clamped); disjoint from other parts by the caller's contract.
        unsafe { std::slice::from_raw_parts_mut(self.start.add(range.start), range.len()) }
    }

    /// Element `i`.
    ///
    /// # Safety
    /// As [`Disjoint::part`]: no other member uses element `i` at the same time; `i` is in
    /// bounds.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn at(&self, i: usize) -> &mut T {
        debug_assert!(i < self.len);
        // SAFETY: by the caller's contract.
        unsafe { &mut *self.start.add(i) }
    }
}
