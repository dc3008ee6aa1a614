//! Every preset of the `skinning` scene kind steps and draws without allocating once its first
//! step is done, through the dynamic scene the run loop holds. Counted by a wrapping global
//! allocator, so this file is its own test binary.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use anim_core::alloc_count::CountingAllocator;
use anim_core::scene::{BuildContext, Frame};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn steps_two_to_five_of_every_preset_do_not_allocate() {
    for preset in (anim_skin::KIND.presets)() {
        let params = preset.quick_params.as_ref().unwrap_or(&preset.params);
        let mut scene = (anim_skin::KIND.build)(params, &BuildContext::default()).unwrap();
        let dt = preset.run.dt;
        let mut frame = Frame::default();
        scene.step(dt).unwrap();
        scene.frame(&mut frame);
        let steps = ALLOC.count(|| {
            for _ in 0..4 {
                scene.step(dt).unwrap();
            }
        });
        assert_eq!(steps, 0, "{}: {steps} allocations in steps 2 to 5", preset.name);
        let frames = ALLOC.count(|| scene.frame(&mut frame));
        assert_eq!(frames, 0, "{}: {frames} allocations writing a frame", preset.name);
    }
}
