//! The invariant "no solver allocates inside `step`": after warm-up steps (which size the sparse
//! grid, the sort and the double buffer), stepping every scene on a rayon pool of 2 threads
//! performs no heap allocation. Counted by a wrapping global allocator, so this file is its own
//! test binary.

#![allow(unsafe_code)]

use anim_mpm::scenes;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

struct Counting;

static COUNT: AtomicUsize = AtomicUsize::new(0);
static ON: AtomicBool = AtomicBool::new(false);

// SAFETY: every call is forwarded unchanged to the system allocator; the counter has no effect on
// the memory handed out.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ON.load(Ordering::Relaxed) {
            COUNT.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if ON.load(Ordering::Relaxed) {
            COUNT.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

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
            COUNT.store(0, Ordering::Relaxed);
            ON.store(true, Ordering::Relaxed);
            let mut ok = true;
            for _ in 0..5 {
                ok &= scene.step().is_ok();
            }
            ON.store(false, Ordering::Relaxed);
            assert!(ok, "{name}: step failed");
            let count = COUNT.load(Ordering::Relaxed);
            assert_eq!(count, 0, "{name}: {count} allocations in 5 steps");
        }
    });
}
