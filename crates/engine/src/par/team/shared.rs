//! Arrays that the workers of a team region share: between two barriers each worker writes
//! places no other worker touches, and after a barrier every worker may read the whole array.
//! The borrow checker cannot see barriers, so the two accesses are `unsafe` and name the rule
//! their caller keeps; bounds are still checked.

use std::marker::PhantomData;
use std::ops::Range;

/// A mutable slice lent to every worker of a region.
pub struct SharedSlice<'a, T> {
    ptr: *mut T,
    len: usize,
    _slice: PhantomData<&'a mut [T]>,
}

// SAFETY: the slice is only reached through `range_mut` and `whole`, whose callers promise that
// no place is written by one worker while another reads or writes it (barriers separate them).
unsafe impl<T: Send + Sync> Sync for SharedSlice<'_, T> {}
unsafe impl<T: Send> Send for SharedSlice<'_, T> {}

impl<'a, T> SharedSlice<'a, T> {
    /// Lends `slice` to the workers for as long as it is borrowed.
    pub fn new(slice: &'a mut [T]) -> Self {
        SharedSlice {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            _slice: PhantomData,
        }
    }

    /// The `D` components of a field, each shared.
    pub fn each<const D: usize>(parts: [&'a mut [T]; D]) -> [SharedSlice<'a, T>; D] {
        parts.map(SharedSlice::new)
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the slice has no elements.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The places `range`, to write.
    ///
    /// # Safety
    /// Until the next barrier no other worker reads or writes any place of `range`, and this
    /// worker does not hold another reference into it.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn range_mut(&self, range: Range<usize>) -> &mut [T] {
        assert!(
            range.start <= range.end && range.end <= self.len,
            "places {range:?} outside 0..{}",
            self.len
        );
        // SAFETY: in bounds (checked); exclusive until the next barrier (the caller's promise).
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(range.start), range.len()) }
    }

    /// Every place, to read.
    ///
    /// # Safety
    /// Until the next barrier no worker writes any place (every write of the previous phase
    /// happened before the barrier that started this one).
    pub unsafe fn whole(&self) -> &[T] {
        // SAFETY: nobody writes until the next barrier (the caller's promise).
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

/// Each component's places `range`, to write (see [`SharedSlice::range_mut`]).
///
/// # Safety
/// As [`SharedSlice::range_mut`], for every component.
#[allow(clippy::mut_from_ref)]
pub unsafe fn ranges_mut<'s, T, const D: usize>(
    parts: &'s [SharedSlice<'_, T>; D],
    range: Range<usize>,
) -> [&'s mut [T]; D] {
    // SAFETY: the caller's promise, for every component.
    std::array::from_fn(|d| unsafe { parts[d].range_mut(range.clone()) })
}

/// Each component whole, to read (see [`SharedSlice::whole`]).
///
/// # Safety
/// As [`SharedSlice::whole`], for every component.
pub unsafe fn wholes<'s, T, const D: usize>(parts: &'s [SharedSlice<'_, T>; D]) -> [&'s [T]; D] {
    // SAFETY: the caller's promise, for every component.
    std::array::from_fn(|d| unsafe { parts[d].whole() })
}
