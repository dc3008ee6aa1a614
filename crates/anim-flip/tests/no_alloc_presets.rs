//! The invariant "`step` allocates nothing", through the scene registry: every preset of
//! [`anim_flip::KIND`] at its quick parameters, built by the kind's builder and stepped as a
//! `Box<dyn DynScene>`, makes no heap allocation in steps 2 to 5 (on a rayon pool of 2
//! threads), the steps whose cell labels change (the pressure operator rebuilt in place) and
//! those whose labels stay included. Counted by a wrapping global allocator, so this file is
//! its own test binary. The pool's own bookkeeping can allocate now and then under load; a step
//! that allocates does so every time, so up to three blocks of four steps are run and one must
//! be clean.

use anim_core::alloc_count::CountingAllocator;
use anim_core::scene::DynScene;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// Allocations in up to three blocks of four steps, stopping at a clean one.
fn blocks(scene: &mut dyn DynScene, dt: f64) -> Vec<usize> {
    let mut out = Vec::with_capacity(3);
    for _ in 0..3 {
        let mut ok = true;
        out.push(ALLOC.count(|| {
            for _ in 0..4 {
                ok &= scene.step(dt).is_ok();
            }
        }));
        assert!(ok, "a step failed");
        if out.last() == Some(&0) {
            break;
        }
    }
    out
}

#[test]
fn preset_steps_do_not_allocate() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    pool.install(|| {
        for preset in (anim_flip::KIND.presets)() {
            let params = preset.quick_params.as_ref().unwrap_or(&preset.params);
            let mut scene = (anim_flip::KIND.build)(params, &Default::default()).expect("builds");
            scene.step(preset.run.dt).expect("the first step");
            let counts = blocks(scene.as_mut(), preset.run.dt);
            assert_eq!(counts.last(), Some(&0), "{}: allocations per block {counts:?}", preset.name);
        }
    });
}
