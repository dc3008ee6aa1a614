//! Determinism across thread counts: the Panda swing run on rayon pools of 1, 2 and 4 threads
//! must end in the same state, bit for bit.

use anim_core::cases::{Check, Ctx, across_threads};
use anim_core::solver::Solver;

pub(super) fn panda(ctx: &Ctx) -> Vec<Check> {
    // The rigid steppers are serial; the case guards against a parallel path changing that.
    let steps = if ctx.quick { 100 } else { 1000 };
    across_threads("anim-rigid", "Panda swing", || {
        let scene = crate::scenes::panda_swing().map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(state.q.iter().chain(&state.v).copied().collect())
    })
}
