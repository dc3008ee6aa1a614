//! Hard cases: the dam break at CFL 10 (large steps split into adaptive substeps), particles
//! driven into an obstacle (pushed out, counted); and the dam break on 1, 2 and 4 threads.

use crate::{FlipError, FlipParams, FlipSimulation, Particles, Transfer, scenes};
use anim_core::cases::{Check, Ctx, Outcome, across_threads, fmt_num};

/// A hard case's verdict: the run's own (Stable, or Diverged for a broken invariant); non-finite
/// values are a detected divergence, other errors a rejection.
fn outcome(r: Result<Outcome, FlipError>) -> Outcome {
    match r {
        Ok(o) => o,
        Err(e @ FlipError::NonFinite { .. }) => Outcome::Diverged(e.to_string()),
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

/// The dam break advanced in 0.05 s steps with `cfl = 10`: each step is split into substeps that
/// move no particle more than 10 cells; the particles must stay finite and inside the box.
pub(super) fn cfl_ten(_ctx: &Ctx) -> Outcome {
    outcome((|| {
        let params = FlipParams::<2> { cfl: 10.0, transfer: Transfer::Flip(0.97), ..FlipParams::default() };
        let (mut sim, mut p, _) = scenes::dam_break(64, 0.2, params)?;
        let v0 = sim.volume_estimate(&p, 4.0);
        let (mut subs, mut max_sub, mut pushed, mut max_div) = (0, 0, 0, 0.0f64);
        for _ in 0..20 {
            let info = sim.advance(&mut p, 0.05)?;
            subs += info.substeps;
            max_sub = max_sub.max(info.substeps);
            pushed += info.pushed_out;
            max_div = max_div.max(info.max_divergence);
        }
        let (lo, hi) = sim.fluid_box();
        let inside = p.x.iter().all(|x| (0..2).all(|a| x[a] >= lo[a] && x[a] <= hi[a]));
        let v1 = sim.volume_estimate(&p, 4.0);
        let detail = format!(
            "1 s in 20 steps of 50 ms: {subs} substeps (at most {max_sub} per step), {pushed} wall push-outs, max |div u| after projection {} 1/s, all particles inside: {inside}, volume change {:.2}%, max speed {:.2} m/s",
            fmt_num(max_div),
            100.0 * (v1 - v0) / v0,
            p.max_speed()
        );
        // A particle outside the box breaks the case's invariant: detected, not stable.
        Ok(if inside { Outcome::Stable(detail) } else { Outcome::Diverged(format!("{detail}: detected")) })
    })())
}

/// A 0.15 x 0.2 m slab at 5 m/s (no gravity) driven into a square obstacle: particles that enter
/// solid cells are pushed back out and counted; none may remain inside.
pub(super) fn into_obstacle(_ctx: &Ctx) -> Outcome {
    outcome((|| {
        let params = FlipParams::<2> { gravity: [0.0; 2], cfl: 2.0, ..FlipParams::default() };
        let n = 64;
        let h = 1.0 / n as f64;
        let mut sim = FlipSimulation::<2>::new([n, n], h, params)?;
        sim.set_solid(|x| (x[0] - 0.6).abs() < 0.1 && (x[1] - 0.5).abs() < 0.1);
        let mut p = Particles::new();
        scenes::fill_box(&mut p, h, 2, [0.2, 0.4], [0.35, 0.6], |_| [5.0, 0.0]);
        let mut pushed = 0;
        for _ in 0..20 {
            pushed += sim.advance(&mut p, 0.01)?.pushed_out;
        }
        let inside =
            p.x.iter().filter(|x| sim.solid()[(x[0] / h) as usize + n * (x[1] / h) as usize]).count();
        if inside > 0 {
            // The case's invariant is broken: a failure, not a stable run.
            return Ok(Outcome::Diverged(format!(
                "{inside} particles left inside solid cells after {pushed} push-outs, detected"
            )));
        }
        Ok(Outcome::Stable(format!(
            "{pushed} push-outs over 0.2 s, no particle left in a solid cell, max speed {:.2} m/s",
            p.max_speed()
        )))
    })())
}

/// The 2D dam break (APIC) on 1, 2 and 4 threads, bit for bit.
pub(super) fn flip_dam_break(ctx: &Ctx) -> Vec<Check> {
    let (n, steps) = if ctx.quick { (48, 10) } else { (96, 40) };
    across_threads(super::CRATE, &format!("dam break, {n} cells/m"), || {
        let params = FlipParams::<2> { transfer: Transfer::Apic, ..FlipParams::default() };
        let (mut sim, mut p, _) = scenes::dam_break(n, 0.2, params).map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.advance(&mut p, 0.01).map_err(|e| e.to_string())?;
        }
        Ok(p.x.iter().flatten().chain(p.v.iter().flatten()).copied().collect())
    })
}
