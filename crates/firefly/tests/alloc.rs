//! A generation allocates nothing on the calling thread (serial stepping):
//! all population buffers are allocated once when the swarm is built.

use mbd_firefly::{testfns, Bounds, FireflySettings, Swarm, Variant};
use mbd_testkit::allocations_during;

#[global_allocator]
static GLOBAL: mbd_testkit::CountingAlloc = mbd_testkit::CountingAlloc;

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
