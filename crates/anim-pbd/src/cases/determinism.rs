//! Determinism across thread counts: the cloth drape run on rayon pools of 1, 2 and 4 threads
//! must end in the same state, bit for bit.

use anim_core::cases::{Check, Ctx, across_threads};
use anim_core::solver::Solver;

pub(super) fn drape(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 30 } else { 300 };
    across_threads("anim-pbd", "cloth drape", || {
        let scene = crate::scenes::cloth_drape(None).map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(state.x.iter().chain(&state.v).copied().collect())
    })
}
