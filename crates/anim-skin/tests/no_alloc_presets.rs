//! The presets of `anim_skin::KIND` step without allocating once their first step is done
//! (`anim_core::alloc_count::preset_step_allocations`: blocks of four steps of every preset's
//! quick parameters on a rayon pool of 2 threads). Counted by a wrapping global allocator, so
//! this file is its own test binary.

use anim_core::alloc_count::{CountingAllocator, preset_step_allocations};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn preset_steps_do_not_allocate() {
    let counted = preset_step_allocations(&ALLOC, &anim_skin::KIND).unwrap_or_else(|e| panic!("{e}"));
    assert!(!counted.is_empty());
    for c in counted {
        assert_eq!(
            c.blocks.last(),
            Some(&0),
            "{}: allocations per block of four steps {:?}",
            c.preset,
            c.blocks
        );
    }
}
