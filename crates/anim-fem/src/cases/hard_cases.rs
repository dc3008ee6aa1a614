//! Hard cases: a fully inverted mesh, E = 1e8 at dt = 1/24 s, nu = 0.49, 10:1 grading, and an
//! explicit step far above its stability limit (diverged and detected).

use super::cantilever_dynamic;
use crate::FemError;
use crate::generate::{box_mesh, graded_box};
use crate::material::{Material, MaterialModel};
use crate::model::{EARTH_GRAVITY, FemModel};
use crate::sim::{FemParams, FemSimulation, TimeIntegrator};
use anim_core::cases::{Ctx, Outcome, fmt_num};
use anim_core::solver::Solver;

fn run_steps(
    sim: &mut FemSimulation,
    state: &mut anim_core::integrate::State,
    dt: f64,
    steps: usize,
) -> Result<f64, FemError> {
    let mut max_speed = 0.0f64;
    for _ in 0..steps {
        sim.step(state, dt)?;
        max_speed = max_speed.max(state.v.iter().fold(0.0f64, |m, v| m.max(v.abs())));
    }
    Ok(max_speed)
}

fn inverted_recovery_with(ctx: &Ctx, model: MaterialModel) -> Outcome {
    let run = || -> Result<String, FemError> {
        let mesh = box_mesh([0.0; 3], [1.0; 3], [4, 4, 4])?;
        let m = FemModel::new(mesh, Material::new(model, 1e5, 0.3, 1000.0)?)?;
        let mut params = FemParams::default().with_rayleigh(0.01);
        params.max_newton_iterations = 500;
        let mut sim = FemSimulation::new(m, params)?;
        let mut state = sim.rest_state();
        // Every vertex reflected through the centre (x -> 1 - x): all elements inverted, F = -I.
        for p in state.x.chunks_mut(3) {
            for c in p.iter_mut() {
                *c = 1.0 - *c;
            }
        }
        // Stable Neo-Hookean needs about 4 s of simulated time to untangle completely.
        let steps = if ctx.quick { 300 } else { 360 };
        run_steps(&mut sim, &mut state, 1.0 / 60.0, steps)?;
        let inverted = (0..sim.model().elements())
            .filter(|&e| sim.model().deformation_gradient(e, &state.x).determinant() <= 0.0)
            .count();
        let vol: f64 = (0..sim.model().elements())
            .map(|e| {
                sim.model().rest_volume()[e] * sim.model().deformation_gradient(e, &state.x).determinant()
            })
            .sum();
        Ok(format!(
            "{}: 384/384 elements inverted at t = 0, {inverted} inverted after {steps} steps of 1/60 s, signed volume {:.4}",
            model.name(),
            vol
        ))
    };
    match run() {
        Ok(s) if s.contains(", 0 inverted") => Outcome::Stable(s),
        Ok(s) => Outcome::Diverged(format!("did not recover: {s}")),
        Err(e) => Outcome::Diverged(format!("{}: {e}", model.name())),
    }
}

pub(super) fn inverted_recovery_fc(ctx: &Ctx) -> Outcome {
    inverted_recovery_with(ctx, MaterialModel::FixedCorotated)
}

pub(super) fn inverted_recovery_snh(ctx: &Ctx) -> Outcome {
    inverted_recovery_with(ctx, MaterialModel::StableNeoHookean)
}

pub(super) fn stiff_large_dt(ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, FemError> {
        let mut sim = cantilever_dynamic(1e8, 0.3, MaterialModel::StableNeoHookean, 2)?;
        let mut state = sim.rest_state();
        let steps = if ctx.quick { 24 } else { 96 };
        let vmax = run_steps(&mut sim, &mut state, 1.0 / 24.0, steps)?;
        let tip = state.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
        Ok(format!("{steps} steps, max |v| {} m/s, lowest point z = {} m", fmt_num(vmax), fmt_num(tip)))
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e) => Outcome::Diverged(e.to_string()),
    }
}

pub(super) fn near_incompressible(ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, FemError> {
        let mesh = box_mesh([0.0, 0.0, 0.2], [0.3; 3], [3, 3, 3])?;
        let mut m = FemModel::new(mesh, Material::new(MaterialModel::StableNeoHookean, 1e5, 0.49, 1000.0)?)?
            .with_gravity(EARTH_GRAVITY);
        m.add_obstacle(crate::boundary::Obstacle::ground(0.0), 1e7)?;
        let mut sim = FemSimulation::new(m, FemParams::default())?;
        let mut state = sim.rest_state();
        let steps = if ctx.quick { 60 } else { 180 };
        run_steps(&mut sim, &mut state, 1.0 / 120.0, steps)?;
        let vol: f64 = (0..sim.model().elements())
            .map(|e| {
                sim.model().rest_volume()[e] * sim.model().deformation_gradient(e, &state.x).determinant()
            })
            .sum();
        Ok(format!("{steps} steps of 1/120 s, volume ratio after impact {:.5}", vol / 0.027))
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e) => Outcome::Diverged(e.to_string()),
    }
}

pub(super) fn graded(ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, FemError> {
        let mesh = graded_box([0.0; 3], [1.0, 0.1, 0.1], [20, 2, 2], 10.0)?;
        let mut m = FemModel::new(mesh, Material::new(MaterialModel::FixedCorotated, 1e6, 0.3, 1000.0)?)?
            .with_gravity(EARTH_GRAVITY);
        let clamp = m.vertices_where(|p| p[0] < 1e-9);
        m.pin_vertices(&clamp)?;
        let mut sim = FemSimulation::new(m, FemParams::default())?;
        let mut state = sim.rest_state();
        let steps = if ctx.quick { 30 } else { 120 };
        let vmax = run_steps(&mut sim, &mut state, 1.0 / 60.0, steps)?;
        Ok(format!("{steps} implicit steps of 1/60 s, max |v| {} m/s", fmt_num(vmax)))
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e) => Outcome::Diverged(e.to_string()),
    }
}

pub(super) fn explicit_divergence(_ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, FemError> {
        let mut sim = cantilever_dynamic(1e8, 0.3, MaterialModel::StVenantKirchhoff, 2)?;
        let mut params = *sim.params();
        params.integrator = TimeIntegrator::SymplecticEuler;
        sim.set_params(params)?;
        let mut state = sim.rest_state();
        run_steps(&mut sim, &mut state, 1.0 / 240.0, 2000)?;
        Ok("did not diverge".into())
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e @ (FemError::NonFiniteState { .. } | FemError::NonFiniteElement { .. })) => {
            Outcome::Diverged(e.to_string())
        }
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}
