//! The invariant "`step` allocates nothing": after one warm-up step, stepping Stam's solver and
//! the MAC solver (every pressure method and both splittings, 2D and 3D, with viscosity,
//! buoyancy, vorticity confinement, an obstacle and an inflow) on a rayon pool of 2 threads
//! performs no heap allocation; nor does rebinding a pressure solver to new cell labels. Counted
//! by a wrapping global allocator, so this file is its own test binary. The pool's own
//! bookkeeping can allocate now and then under load; a step that allocates does so every time,
//! so three blocks of steps are run and one must be clean.

use anim_core::alloc_count::CountingAllocator;
use anim_fluid::advection::{Advection, Splitting};
use anim_fluid::mac::{MacFluid, MacParams, Source};
use anim_fluid::pressure::{CellLabel, Poisson, PressureMethod, PressureSolver};
use anim_fluid::scenes;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// Allocations in up to three blocks of `steps` calls of `step`, stopping at a clean one.
fn blocks(mut step: impl FnMut() -> bool, steps: usize) -> Vec<usize> {
    let mut out = Vec::with_capacity(3);
    for _ in 0..3 {
        let mut ok = true;
        out.push(ALLOC.count(|| {
            for _ in 0..steps {
                ok &= step();
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
fn stam_and_mac_steps_do_not_allocate() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    pool.install(|| {
        for name in ["smoke-box-2d", "smoke-plume-3d", "lid-driven-cavity"] {
            let mut scene = scenes::by_name(name, Some(12)).expect("known").expect("builds");
            scene.step().expect("warm-up");
            let counts = blocks(|| scene.step().is_ok(), 3);
            assert_eq!(counts.last(), Some(&0), "{name}: allocations per block {counts:?}");
        }
        for (k, method) in PressureMethod::ALL.into_iter().enumerate() {
            for splitting in Splitting::ALL {
                for (dims, dim) in [([12, 10, 1], 2), ([6, 6, 6], 3)] {
                    let params = MacParams {
                        pressure: method,
                        pressure_tolerance: 1e-4,
                        pressure_max_iterations: 100_000,
                        viscosity: 0.01,
                        advection: Advection::ALL[k % 4],
                        splitting,
                        buoyancy_temperature: 1.0,
                        vorticity_confinement: 1.0,
                        sources: vec![Source {
                            min: [0.3, 0.0, 0.3],
                            max: [0.6, 0.2, 0.6],
                            density: 1.0,
                            temperature: 1.0,
                            velocity: Some([0.0, 1.0, 0.0]),
                        }],
                        ..MacParams::default()
                    };
                    let (mut fluid, mut state) = MacFluid::new(dims, dim, 0.1, params).expect("fluid");
                    fluid.set_solid(|p| (p[0] - 0.7).powi(2) + (p[1] - 0.5).powi(2) < 0.02).expect("solid");
                    fluid.set_velocity(&mut state, |p| [(3.0 * p[1]).sin(), (2.0 * p[0]).cos(), 0.5 * p[1]]);
                    fluid.advance(&mut state, 0.02).expect("warm-up");
                    let counts = blocks(|| fluid.advance(&mut state, 0.02).is_ok(), 3);
                    assert_eq!(
                        counts.last(),
                        Some(&0),
                        "{method:?} {} {dim}D: allocations per block {counts:?}",
                        splitting.name()
                    );
                }
            }
        }
    });
    // Rebinding a pressure solver to new labels (what a particle fluid does when its fluid
    // cells change) allocates nothing, for every method, in 2D and 3D.
    for (dims, dim) in [([24, 20, 1], 2), ([10, 12, 9], 3)] {
        let cells = dims[0] * dims[1] * dims[2];
        let level = |h: usize| -> Vec<CellLabel> {
            (0..cells)
                .map(|c| if (c / dims[0]) % dims[1] < h { CellLabel::Fluid } else { CellLabel::Air })
                .collect()
        };
        let (low, high) = (level(4), level(7));
        for method in PressureMethod::ALL {
            let op = Poisson::new(dims, dim, low.clone(), [[false; 2]; 3]).expect("operator");
            let mut solver = PressureSolver::new(op, method, 1e-6, 100).expect("solver");
            let made = ALLOC.count(|| {
                solver.relabel(&high).expect("relabel");
                solver.relabel(&low).expect("relabel");
            });
            assert_eq!(made, 0, "{method:?} {dim}D");
        }
    }
}
