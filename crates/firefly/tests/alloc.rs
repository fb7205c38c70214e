//! A generation allocates nothing on the calling thread (serial stepping):
//! all population buffers are allocated once when the swarm is built.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use mbd_firefly::{testfns, Bounds, FireflySettings, Swarm, Variant};

struct Counting;

thread_local! {
    static ACTIVE: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: defers to the system allocator; only bumps a thread-local counter.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ACTIVE.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_during<F: FnOnce()>(f: F) -> u64 {
    COUNT.with(|c| c.set(0));
    ACTIVE.with(|a| a.set(true));
    f();
    ACTIVE.with(|a| a.set(false));
    COUNT.with(Cell::get)
}

#[test]
fn serial_generations_do_not_allocate() {
    // The counter works.
    let probe = allocations_during(|| {
        std::hint::black_box(vec![1u8; 16]);
    });
    assert!(probe >= 1);

    for variant in [Variant::Snapshot, Variant::Classic, Variant::ClassicSweep] {
        let bounds = Bounds::cube(10, -5.12, 5.12).expect("valid box");
        let settings = FireflySettings::default().population(30).variant(variant);
        let mut swarm = Swarm::new(&bounds, &settings, &[]).expect("valid settings");
        let mut f = testfns::rastrigin;
        swarm.initialize(&mut f, None);
        let n = allocations_during(|| {
            for _ in 0..20 {
                swarm.step(&mut f, Some(1_000_000));
                let _ = swarm.record();
            }
        });
        assert_eq!(n, 0, "{variant:?} allocated {n} times in 20 generations");
    }
}
