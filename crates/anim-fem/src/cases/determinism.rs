//! Determinism across thread counts: the benchmark beam run on rayon pools of 1, 2 and 4 threads
//! must end in the same state, bit for bit (the metric is the number of state values whose bits
//! differ from the 1-thread run).

use anim_core::cases::{Check, Ctx, across_threads};
use anim_core::integrate::State;
use anim_core::solver::Solver;

fn flat(state: &State) -> Vec<f64> {
    state.x.iter().chain(&state.v).copied().collect()
}

pub(super) fn fem_beam(ctx: &Ctx) -> Vec<Check> {
    // CI: 14 x 2 x 2 cells (336 tetrahedra), element loops split into parallel chunks; the full
    // suite: 50 x 8 x 8 (19,200), where the gather into nodes runs in parallel too.
    let (cells, steps) = if ctx.quick { (14, 3) } else { (50, 5) };
    across_threads("anim-fem", &format!("benchmark beam, {cells} cells along"), || {
        let scene = crate::scenes::benchmark_beam(cells).map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(flat(&state))
    })
}
