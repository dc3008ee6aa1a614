//! The architecture invariant "no solver allocates inside `step`": after the first step, stepping
//! every scene (contacts, wind, a moving body, a global volume) with every solver on a rayon pool
//! of 2 threads performs no heap allocation. Counted by a wrapping global allocator, so this file
//! is its own test binary.

use anim_core::alloc_count::CountingAllocator;
use anim_core::solver::Solver;
use anim_pbd::{PbdSimulation, SolverKind, scenes};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

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
                    let counted = ALLOC.count(|| {
                        for _ in 0..10 {
                            sim.advance(&mut state, dt).expect("step");
                            sim.step(&mut state, dt).expect("step with report");
                        }
                    });
                    blocks.push(counted);
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
