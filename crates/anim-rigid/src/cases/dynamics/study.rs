//! The work-precision study of the steppers on the 32-link pendulum chain.

use crate::scenes::pendulum_chain_model;
use crate::sim::{ArticulatedSystem, RigidIntegrator, RigidSimulation, SimParams};
use crate::{Data, Model};
use anim_core::cases::{Ctx, Point, Series, StudyResult, median_seconds};
use anim_core::glam::DVec3;
use anim_core::integrate::{IntegratorKind, State};
use anim_core::solver::Solver;

/// Tip position of the chain (frame `tip`) for a state.
pub(super) fn tip(model: &Model, data: &mut Data, q: &[f64]) -> DVec3 {
    crate::forward_kinematics(model, data, q);
    let f = model.frame_id("tip").map(|f| model.frame(f));
    f.map_or(DVec3::NAN, |f| data.world_placements[f.parent_joint].transform_point(f.placement.translation))
}

pub(super) const STUDY_LINKS: usize = 32;

/// A run of the study chain for a number of steps, to the final configuration.
type ChainRun = dyn Fn(usize) -> Option<Vec<f64>>;

pub(super) fn study_model() -> Option<Model> {
    pendulum_chain_model(&[0.1; STUDY_LINKS], 0.1).ok()
}

/// The chain's initial state: horizontal, at rest, with a small bend so the motion is generic.
pub(super) fn study_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    ((0..n).map(|k| 0.02 * (k as f64 * 0.7).sin()).collect(), vec![0.0; n])
}

/// Final configuration after `steps` steps to `t_end` with one of our steppers.
pub(super) fn chain_run(integrator: RigidIntegrator, t_end: f64, steps: usize) -> Option<Vec<f64>> {
    let model = study_model()?;
    let (q, v) = study_state(model.nv());
    let mut sim = RigidSimulation::new(model, SimParams::default(), integrator).ok()?;
    let mut state = sim.initial_state(q, v).ok()?;
    let dt = t_end / steps as f64;
    for _ in 0..steps {
        sim.step(&mut state, dt).ok()?;
    }
    Some(state.q)
}

/// The same with an anim-core integrator through `SecondOrderSystem`.
pub(super) fn chain_run_core(kind: IntegratorKind, t_end: f64, steps: usize) -> Option<Vec<f64>> {
    let model = study_model()?;
    let (q, v) = study_state(model.nv());
    let n = model.nv();
    let mut system = ArticulatedSystem::new(model, SimParams::default()).ok()?;
    let mut state = State::new(q, v);
    let mut integrator = kind.build_explicit::<ArticulatedSystem>(n)?;
    let dt = t_end / steps as f64;
    for _ in 0..steps {
        integrator.step(&mut system, &mut state, dt).ok()?;
    }
    Some(state.x)
}

pub(super) fn chain_study(ctx: &Ctx) -> StudyResult {
    let t_end = if ctx.quick { 0.25 } else { 1.0 };
    let (batches, min_batch) = if ctx.quick { (3, 0.0) } else { (3, 0.05) };
    let points = if ctx.quick { 3 } else { 5 };
    let model = study_model();
    let mut data = model.as_ref().map(Data::new);
    // Reference: RK4 at 32 times RK4's finest step in the sweep.
    let finest = (if ctx.quick { 100 } else { 400 }) << (points - 1);
    let reference = chain_run(RigidIntegrator::Rk4, t_end, 32 * finest);
    let mut error = |q: Option<Vec<f64>>| -> f64 {
        match (&model, &mut data, &reference, q) {
            (Some(m), Some(d), Some(r), Some(q)) => {
                let a = tip(m, d, r);
                let b = tip(m, d, &q);
                (a - b).length()
            }
            _ => f64::NAN,
        }
    };
    let mut series = Vec::new();
    let sweeps: [(&str, usize, Box<ChainRun>); 5] = [
        ("symplectic-euler", 4000, Box::new(move |s| chain_run(RigidIntegrator::SymplecticEuler, t_end, s))),
        ("rk4 (CF4)", 400, Box::new(move |s| chain_run(RigidIntegrator::Rk4, t_end, s))),
        ("implicit-midpoint", 250, Box::new(move |s| chain_run(RigidIntegrator::ImplicitMidpoint, t_end, s))),
        (
            "anim-core velocity-verlet",
            1000,
            Box::new(move |s| chain_run_core(IntegratorKind::VelocityVerlet, t_end, s)),
        ),
        ("anim-core rk4", 400, Box::new(move |s| chain_run_core(IntegratorKind::Rk4, t_end, s))),
    ];
    for (label, base, run) in &sweeps {
        let base = if ctx.quick { base / 4 } else { *base };
        let pts = (0..points)
            .map(|i| {
                let steps = base << i;
                let err = error(run(steps));
                let seconds = if err.is_finite() {
                    median_seconds(batches, min_batch, || {
                        std::hint::black_box(run(steps));
                    })
                } else {
                    f64::NAN
                };
                Point { param: t_end / steps as f64, seconds, error: err }
            })
            .collect();
        series.push(Series { label: (*label).to_string(), points: pts });
    }
    StudyResult {
        title: format!(
            "{STUDY_LINKS}-link pendulum chain falling from horizontal, {t_end} s: tip position error against RK4 at a 32x smaller step"
        ),
        slug: "rigid-pendulum-chain".into(),
        error_label: format!("|tip - tip_ref| (m) at t = {t_end} s"),
        param_label: "dt".into(),
        series,
    }
}
