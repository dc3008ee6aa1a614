//! The presets of `anim_pbd::KIND` step without allocating once their first step is done
//! (`anim_core::alloc_count::preset_step_allocations`). Counted by a wrapping global allocator,
//! so this file is its own test binary.

anim_core::preset_allocation_test!(anim_pbd::KIND);
