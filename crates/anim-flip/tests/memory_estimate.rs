//! The memory a `flip` preset is estimated to take before its grid or particles exist
//! (`anim_flip::memory`) against the most bytes building it and stepping it once hold
//! (`anim_core::alloc_count::build_and_step_peak`: a build, a step, its context and a frame), at
//! two moderate resolutions of the 2D dam break and the 3D drop. Counted by a wrapping global
//! allocator, so this file is its own test binary.
//!
//! The estimate, less what writing frames holds (the measurement draws a frame, writes none), must
//! lie within `[0.5, 2]` times what is held: low by half at most, so a scene the check lets through
//! cannot take much more than the memory it was checked against; high by twice at most, so that the
//! check refuses no scene that would fit in half the memory.

use anim_core::alloc_count::{CountingAllocator, build_and_step_peak};
use anim_flip::{KIND, memory};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn the_estimate_is_within_a_factor_of_two_of_what_a_build_and_a_step_hold() {
    for (preset, sizes) in [("dam-break-2d", [64, 256]), ("drop-3d", [16, 32])] {
        for n in sizes {
            let params = serde_json::json!({ "preset": preset, "resolution": n });
            let need = memory::preset_need(preset, Some(n)).expect("known");
            // What writing frames holds is left out: the measurement draws a frame, writes none.
            let estimate = need.bytes_without_writing();
            let held = build_and_step_peak(&ALLOC, &KIND, &params, 0.02).expect("builds and steps") as f64;
            let ratio = estimate / held;
            println!("{preset} {n}: estimate {estimate:.4e} B, held {held:.4e} B, ratio {ratio:.3}");
            assert!((0.5..=2.0).contains(&ratio), "{preset} at {n}: estimate {estimate} B, held {held} B");
        }
    }
}
