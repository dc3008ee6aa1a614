//! The presets of the `mpm` scene kind step without allocating once the first step is done:
//! steps 2 to 5 of every preset's quick parameters, through the object-safe
//! [`DynScene`](anim_core::scene::DynScene), on a rayon pool of 2 threads. Counted by a wrapping
//! global allocator, so this file is its own test binary.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use anim_core::alloc_count::CountingAllocator;
use anim_core::scene::BuildContext;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn preset_steps_do_not_allocate() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    for preset in (anim_mpm::KIND.presets)() {
        let params = preset.quick_params.as_ref().unwrap_or(&preset.params);
        let mut scene = (anim_mpm::KIND.build)(params, &BuildContext::default()).expect("builds");
        let dt = preset.run.dt;
        let counted = pool.install(|| {
            scene.step(dt).expect("first step");
            ALLOC.count(|| {
                for _ in 0..4 {
                    scene.step(dt).expect("step");
                }
            })
        });
        assert_eq!(counted, 0, "{}: {counted} allocations in steps 2 to 5", preset.name);
    }
}
