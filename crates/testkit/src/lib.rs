//! # mbd-testkit
//!
//! Helpers shared by the workspace's test binaries: [`CountingAlloc`], a global allocator that
//! counts the heap allocations (and reallocations) of the current thread, for the tests that
//! prove a step allocates nothing. Per thread, because the test harness allocates on its own
//! threads meanwhile.
//!
//! ```
//! // in a test binary:
//! // #[global_allocator]
//! // static GLOBAL: mbd_testkit::CountingAlloc = mbd_testkit::CountingAlloc;
//! let n = mbd_testkit::allocations_during(|| {
//!     let _ = 1 + 1;
//! });
//! assert_eq!(n, 0);
//! ```
#![warn(missing_docs)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

/// A global allocator that defers to the system allocator and counts every `alloc` and
/// `realloc` of the current thread ([`allocations`]). Install it in a test binary with
/// `#[global_allocator]`; without it the counter stays at 0.
#[derive(Clone, Copy, Debug, Default)]
pub struct CountingAlloc;

// SAFETY: every call defers to the system allocator with the caller's arguments; the counter
// is a thread-local cell (`try_with`: no panic while the thread's locals are torn down).
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(p, l, n) }
    }
}

/// Heap allocations (and reallocations) made so far on this thread while [`CountingAlloc`]
/// is the global allocator.
pub fn allocations() -> usize {
    ALLOCS.with(|c| c.get())
}

/// The allocations `f` makes on this thread.
pub fn allocations_during<F: FnOnce()>(f: F) -> usize {
    let before = allocations();
    f();
    allocations() - before
}
