//! The invariant "no solver allocates inside `step`": after warm-up steps (which size the sparse
//! grid, the sort and the double buffer), stepping every scene on a rayon pool of 2 threads
//! performs no heap allocation. Counted by a wrapping global allocator, so this file is its own
//! test binary.

use anim_core::alloc_count::CountingAllocator;
use anim_mpm::scenes;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn steps_do_not_allocate() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    pool.install(|| {
        for name in ["three-materials", "benchmark-3d", "snowball"] {
            let res = if name == "three-materials" { 32 } else { 16 };
            let mut scene = scenes::by_name(name, Some(res)).expect("known").expect("builds");
            // Warm-up: the buffers grow to the block and particle counts of the scene's motion.
            for _ in 0..20 {
                scene.step().expect("step");
            }
            // The counter sees every thread of the process, the test harness's included, which
            // can allocate at any time under load; a step that allocates does so in every
            // block, so one clean block of five steps out of three shows that steps do not.
            let mut counts = Vec::new();
            for _ in 0..3 {
                let mut ok = true;
                counts.push(ALLOC.count(|| {
                    for _ in 0..5 {
                        ok &= scene.step().is_ok();
                    }
                }));
                assert!(ok, "{name}: step failed");
                if counts.last() == Some(&0) {
                    break;
                }
            }
            assert_eq!(counts.last(), Some(&0), "{name}: allocations per block of 5 steps {counts:?}");
        }
    });
}
