//! Determinism across thread counts: a chain large enough for the parallel update loops, run on
//! rayon pools of 1, 2 and 4 threads, must end in the same state, bit for bit.

use crate::cases::{Check, Ctx, across_threads};
use crate::integrate::systems::LinearChain;
use crate::integrate::{IntegratorKind, study::advance};

pub(super) fn chain(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 20 } else { 200 };
    let mut out = Vec::new();
    for kind in
        [IntegratorKind::SymplecticEuler, IntegratorKind::VelocityVerlet, IntegratorKind::ImplicitMidpoint]
    {
        out.extend(across_threads("anim-core", &format!("chain, {}", kind.label()), || {
            // 40,000 unknowns: above the threshold of the chunked parallel update loops.
            let mut sys = LinearChain::new(40_000, 0.01, 100.0, 0.01, 9.81);
            let mut state = sys.rest_state();
            for (i, v) in state.v.iter_mut().enumerate() {
                *v = ((i % 13) as f64 - 6.0) * 1e-3;
            }
            let mut integ = kind.build(40_000);
            advance(integ.as_mut(), &mut sys, &mut state, 1e-3, steps).map_err(|e| e.to_string())?;
            Ok(state.x.iter().chain(&state.v).copied().collect())
        }));
    }
    out
}
