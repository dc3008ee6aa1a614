//! The architecture invariant "no solver allocates inside `step`": after the first step, stepping
//! every scene (contacts, wind, a moving body, a global volume) with every solver on a rayon pool
//! of 2 threads performs no heap allocation. Counted by a wrapping global allocator, so this file
//! is its own test binary.

#![allow(unsafe_code)]

use anim_core::solver::Solver;
use anim_pbd::{PbdSimulation, SolverKind, scenes};
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
    for name in scenes::NAMES {
        for solver in SolverKind::ALL {
            let scene = scenes::by_name(name, None).expect("known").expect("builds");
            let dt = scene.dt;
            let mut params = scene.params;
            params.solver = solver;
            let mut sim = PbdSimulation::new(scene.model, params).expect("params");
            let mut state = scene.state;
            // The counter sees every thread of the process, including the thread pool's own
            // bookkeeping (its work-stealing deques free old buffers through epoch-based
            // reclamation, which can allocate when the machine is loaded). A step that allocates
            // does so in every block of 20 steps; three blocks are run and one must be clean.
            let blocks: Vec<usize> = pool.install(|| {
                sim.advance(&mut state, dt).expect("first step");
                let mut blocks = Vec::with_capacity(3);
                for _ in 0..3 {
                    COUNT.store(0, Ordering::Relaxed);
                    ON.store(true, Ordering::Relaxed);
                    for _ in 0..10 {
                        sim.advance(&mut state, dt).expect("step");
                        sim.step(&mut state, dt).expect("step with report");
                    }
                    ON.store(false, Ordering::Relaxed);
                    blocks.push(COUNT.load(Ordering::Relaxed));
                    if blocks.last() == Some(&0) {
                        break;
                    }
                }
                blocks
            });
            assert_eq!(
                blocks.last(),
                Some(&0),
                "{name} / {}: allocations in each block of 20 steps: {blocks:?}",
                solver.label()
            );
        }
    }
}
