//! # mbd-testkit
//!
//! Helpers shared by the workspace's test binaries: [`CountingAlloc`], a global allocator that
//! counts the heap allocations (and reallocations) of the current thread, for the tests that
//! prove a step allocates nothing (per thread, because the test harness allocates on its own
//! threads meanwhile); and [`gradient_error`], exact gradients of a function of `(q, v)`
//! against fourth-order central differences.
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

/// The largest difference between the gradients `gq`, `gv` of `f(q, v)` and fourth-order
/// central differences of `f` with step `d` in each coordinate of `q` and of `v`, relative to
/// the largest gradient entry (at least 1e-30).
///
/// ```
/// // f = q0^2 v0: gradients (2 q0 v0, q0^2)
/// let f = |q: &[f64], v: &[f64]| q[0] * q[0] * v[0];
/// let err = mbd_testkit::gradient_error(f, &[1.5], &[2.0], &[6.0], &[2.25], 1e-3);
/// assert!(err < 1e-10);
/// ```
pub fn gradient_error(
    mut f: impl FnMut(&[f64], &[f64]) -> f64,
    q: &[f64],
    v: &[f64],
    gq: &[f64],
    gv: &[f64],
    d: f64,
) -> f64 {
    let scale = gq.iter().chain(gv).fold(1e-30f64, |a, x| a.max(x.abs()));
    let mut worst = 0.0f64;
    for (wrt_q, grad) in [(true, gq), (false, gv)] {
        for (l, &g) in grad.iter().enumerate() {
            let mut acc = 0.0;
            for (cf, k) in [(8.0, 1.0), (-8.0, -1.0), (-1.0, 2.0), (1.0, -2.0)] {
                let (mut y, mut w) = (q.to_vec(), v.to_vec());
                if wrt_q {
                    y[l] += k * d;
                } else {
                    w[l] += k * d;
                }
                acc += cf * f(&y, &w);
            }
            worst = worst.max((acc / (12.0 * d) - g).abs());
        }
    }
    worst / scale
}
