//! Determinism across thread counts: the 110 x 110 hanging cloth run on rayon pools of 1, 2 and
//! 4 threads must end in the same state, bit for bit.

use anim_core::cases::{Check, Ctx, across_threads};
use anim_core::solver::Solver;

pub(super) fn cloth(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 5 } else { 50 };
    across_threads("anim-springs", "hanging cloth 110 x 110", || {
        // 36,300 unknowns: above the threshold of anim-core's parallel update loops.
        let scene = crate::scenes::hanging_cloth(Some(110)).map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(state.x.iter().chain(&state.v).copied().collect())
    })
}
