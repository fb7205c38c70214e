//! A counting global allocator for the allocation tests of the root test binaries: every
//! `alloc` and `realloc` on the current thread increments [`allocations`].

use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::cell::Cell;

struct Counting;
thread_local! {
    // per thread: the test harness may allocate on its own threads meanwhile (seen under load)
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { SysAlloc.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { SysAlloc.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { SysAlloc.realloc(p, l, n) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Heap allocations made so far on this thread.
pub fn allocations() -> usize {
    ALLOCS.with(|c| c.get())
}
