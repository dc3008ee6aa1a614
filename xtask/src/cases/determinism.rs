//! Determinism across thread counts: each crate's main scene run on rayon pools of 1, 2 and 4
//! threads must end in the same state, bit for bit. The metric is the number of state values
//! whose bits differ from the 1-thread run (must be 0).

use crate::registry::{Check, ConformanceCase, Ctx, Registry, across_threads};
use anim_core::integrate::systems::LinearChain;
use anim_core::integrate::{IntegratorKind, State, study::advance};
use anim_core::solver::Solver;

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: "anim-core",
        name: "determinism: 40k-dof chain on 1, 2, 4 threads",
        run: Box::new(core_chain),
    });
    r.conformance.push(ConformanceCase {
        crate_name: "anim-springs",
        name: "determinism: 110 x 110 hanging cloth on 1, 2, 4 threads",
        run: Box::new(springs_cloth),
    });
    r.conformance.push(ConformanceCase {
        crate_name: "anim-pbd",
        name: "determinism: cloth drape on 1, 2, 4 threads",
        run: Box::new(pbd_drape),
    });
    r.conformance.push(ConformanceCase {
        crate_name: "anim-rigid",
        name: "determinism: Panda swing on 1, 2, 4 threads",
        run: Box::new(rigid_panda),
    });
    r.conformance.push(ConformanceCase {
        crate_name: "anim-fem",
        name: "determinism: benchmark beam (backward Euler) on 1, 2, 4 threads",
        run: Box::new(fem_beam),
    });
}

fn flat(state: &State) -> Vec<f64> {
    state.x.iter().chain(&state.v).copied().collect()
}

fn core_chain(ctx: &Ctx) -> Vec<Check> {
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
            Ok(flat(&state))
        }));
    }
    out
}

fn springs_cloth(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 5 } else { 50 };
    across_threads("anim-springs", "hanging cloth 110 x 110", || {
        // 36,300 unknowns: above the threshold of anim-core's parallel update loops.
        let scene = anim_springs::scenes::hanging_cloth(Some(110)).map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(flat(&state))
    })
}

fn pbd_drape(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 30 } else { 300 };
    across_threads("anim-pbd", "cloth drape", || {
        let scene = anim_pbd::scenes::cloth_drape(None).map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(flat(&state))
    })
}

fn rigid_panda(ctx: &Ctx) -> Vec<Check> {
    // The rigid steppers are serial; the case guards against a parallel path changing that.
    let steps = if ctx.quick { 100 } else { 1000 };
    across_threads("anim-rigid", "Panda swing", || {
        let scene = anim_rigid::scenes::panda_swing().map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(state.q.iter().chain(&state.v).copied().collect())
    })
}

fn fem_beam(ctx: &Ctx) -> Vec<Check> {
    // CI: 14 x 2 x 2 cells (336 tetrahedra), element loops split into parallel chunks; the full
    // suite: 50 x 8 x 8 (19,200), where the gather into nodes runs in parallel too.
    let (cells, steps) = if ctx.quick { (14, 3) } else { (50, 5) };
    across_threads("anim-fem", &format!("benchmark beam, {cells} cells along"), || {
        let scene = anim_fem::scenes::benchmark_beam(cells).map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(flat(&state))
    })
}
