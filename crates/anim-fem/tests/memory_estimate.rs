//! The memory an `fem` preset is estimated to take before its mesh is made (`anim_fem::memory`)
//! against the most bytes building it and stepping it once hold
//! (`anim_core::alloc_count::build_and_step_peak`: a build, a step, its context and a frame), at
//! two moderate resolutions of the beam (a bar: the factor fills as `N a`), the cube (`N^(4/3)`)
//! and the beam of 10-node elements, backward Euler with the Cholesky factor. Counted by a wrapping
//! global allocator, so this file is its own test binary.
//!
//! The estimate, less what writing frames holds (the measurement draws a frame, writes none), must
//! lie within `[0.5, 2]` times what is held: low by half at most, so a scene the check lets through
//! cannot take much more than the memory it was checked against; high by twice at most, so that the
//! check refuses no scene that would fit in half the memory.

use anim_core::alloc_count::{CountingAllocator, build_and_step_peak};
use anim_fem::model::ElementOrder;
use anim_fem::sim::{LinearSolverChoice, TimeIntegrator};
use anim_fem::{KIND, memory};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn the_estimate_is_within_a_factor_of_two_of_what_a_build_and_a_step_hold() {
    for (preset, element, order, dt, sizes) in [
        ("cantilever-beam", "tet4", ElementOrder::Linear, 1.0 / 60.0, [3, 6]),
        ("soft-cube-drop", "tet4", ElementOrder::Linear, 0.005, [6, 12]),
        ("cantilever-beam", "tet10", ElementOrder::Quadratic, 1.0 / 60.0, [2, 3]),
    ] {
        for n in sizes {
            let params = serde_json::json!({ "preset": preset, "resolution": n, "element": element });
            let (be, cholesky) = (TimeIntegrator::BackwardEuler, LinearSolverChoice::Cholesky);
            let need = memory::preset_need(preset, Some(n), order, be, cholesky).expect("known");
            // What writing frames holds is left out: the measurement draws a frame, writes none.
            let estimate = need.bytes_without_writing();
            let held = build_and_step_peak(&ALLOC, &KIND, &params, dt).expect("builds and steps") as f64;
            let ratio = estimate / held;
            println!(
                "{preset} {element} {n}: estimate {estimate:.4e} B, held {held:.4e} B, ratio {ratio:.3}"
            );
            assert!(
                (0.5..=2.0).contains(&ratio),
                "{preset} {element} at {n}: estimate {estimate} B, held {held} B"
            );
        }
    }
}
