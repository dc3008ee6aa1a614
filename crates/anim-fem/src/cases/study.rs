//! The beam work-precision study: explicit against implicit time integration, per material model.

use super::{CANTILEVER_DENSITY, cantilever_dynamic};
use crate::FemError;
use crate::material::MaterialModel;
use crate::sim::{FemParams, FemSimulation, LinearSolverChoice, TimeIntegrator};
use anim_core::cases::{Ctx, Point, Series, StudyResult, median_seconds};
use anim_core::solver::Solver;

/// The study beam: 1 m x 0.1 m x 0.1 m, E = 1e6 Pa, nu = 0.3, rho = 1000, clamped, sagging from
/// rest under gravity for 0.5 s; the error is the RMS over time of the tip-height difference to a
/// converged run of the same material model (symplectic Euler far below its stability limit: it
/// is second-order accurate in positions and not dissipative, while backward Euler is), relative
/// to the reference's RMS tip deflection. Every model is discretised by the same mesh, so the error
/// measures time integration and solver tolerance, which is what a user trades against wall time.
fn study_sim(method: BeamMethod) -> Result<FemSimulation, FemError> {
    let mut sim = cantilever_dynamic(STUDY_YOUNG, 0.3, method.model, STUDY_CELLS)?;
    let mut p = FemParams::new(method.integrator)
        .with_energy_report(false)
        .with_newton_tolerance(1e-8)
        .with_linear_solver(method.solver);
    p.max_newton_iterations = 100;
    p.cg_tolerance = 1e-10;
    sim.set_params(p)?;
    Ok(sim)
}

/// One method of the beam study: material model, integrator and (for backward Euler) the linear
/// solver inside Newton.
#[derive(Debug, Clone, Copy)]
struct BeamMethod {
    model: MaterialModel,
    integrator: TimeIntegrator,
    solver: LinearSolverChoice,
}

impl BeamMethod {
    fn label(self) -> String {
        match self.integrator {
            TimeIntegrator::SymplecticEuler => format!("{} {}", self.model.name(), self.integrator.name()),
            TimeIntegrator::BackwardEuler => {
                format!("{} {} ({})", self.model.name(), self.integrator.name(), self.solver.name())
            }
        }
    }
}

const STUDY_T: f64 = 0.5;
/// Young's modulus of the study beam (Pa).
const STUDY_YOUNG: f64 = 1e6;
/// Cells across the study beam's 0.1 m section.
const STUDY_CELLS: usize = 2;

/// The study problem's parameters `anim run --tolerance` scales a picked step by: Young's modulus
/// (Pa), density (kg/m^3, `cantilever_dynamic`'s) and cell size (m).
pub fn study_problem(_quick: bool) -> Vec<(&'static str, f64)> {
    vec![("young", STUDY_YOUNG), ("density", CANTILEVER_DENSITY), ("cell", 0.1 / STUDY_CELLS as f64)]
}
const SAMPLES: usize = 50;

fn tip_trajectory(method: BeamMethod, dt: f64) -> Option<Vec<f64>> {
    let mut sim = study_sim(method).ok()?;
    let tip: Vec<usize> = sim.model().vertices_where(|p| p[0] > 1.0 - 1e-9);
    let mut state = sim.rest_state();
    let steps = (STUDY_T / dt).round() as usize;
    let every = steps / SAMPLES;
    let mut out = Vec::with_capacity(SAMPLES);
    for s in 1..=steps {
        sim.step(&mut state, dt).ok()?;
        if every > 0 && s % every == 0 && out.len() < SAMPLES {
            out.push(tip.iter().map(|&v| state.x[3 * v + 2]).sum::<f64>() / tip.len() as f64);
        }
    }
    Some(out)
}

pub(super) fn beam_study(ctx: &Ctx) -> StudyResult {
    let (batches, min_batch) = if ctx.quick { (1, 0.0) } else { (3, 0.05) };
    let models = MaterialModel::ALL;
    let mut series = Vec::new();
    for model in models {
        let explicit = BeamMethod {
            model,
            integrator: TimeIntegrator::SymplecticEuler,
            solver: LinearSolverChoice::Cholesky,
        };
        // The converged reference: symplectic Euler at a step far below its stability limit.
        let ref_dt = STUDY_T / (SAMPLES as f64 * if ctx.quick { 80.0 } else { 400.0 });
        let Some(reference) = tip_trajectory(explicit, ref_dt) else {
            continue;
        };
        let rest_z = 0.05;
        let scale = (reference.iter().map(|z| (z - rest_z) * (z - rest_z)).sum::<f64>()
            / reference.len() as f64)
            .sqrt();
        let implicit = |solver| BeamMethod { model, integrator: TimeIntegrator::BackwardEuler, solver };
        let explicit_steps = if ctx.quick { vec![16.0, 32.0] } else { vec![16.0, 24.0, 32.0, 64.0, 128.0] };
        let implicit_steps = if ctx.quick { vec![1.0, 4.0] } else { vec![1.0, 2.0, 4.0, 8.0, 16.0, 32.0] };
        let mut sweeps =
            vec![(explicit, explicit_steps), (implicit(LinearSolverChoice::Cholesky), implicit_steps)];
        // The linear solvers inside Newton, compared on one model (the answer is the same to the
        // Newton tolerance; only the cost differs).
        if !ctx.quick && model == MaterialModel::StableNeoHookean {
            sweeps.push((implicit(LinearSolverChoice::Ldlt), vec![1.0, 4.0, 16.0]));
            sweeps.push((implicit(LinearSolverChoice::JacobiPcg), vec![1.0, 4.0, 16.0]));
        }
        for (method, steps_per_sample) in sweeps {
            let mut points = Vec::new();
            for k in steps_per_sample {
                let dt = STUDY_T / (SAMPLES as f64 * k);
                // The first timed run's trajectory is the one measured: the method runs
                // `batches` times in all (once when it fails).
                let mut first: Option<Option<Vec<f64>>> = None;
                let seconds = median_seconds(batches, min_batch, || {
                    if matches!(first, Some(None)) {
                        return;
                    }
                    let traj = tip_trajectory(method, dt);
                    first.get_or_insert(traj);
                });
                let Some(Some(traj)) = first else { continue };
                let err = (traj.iter().zip(&reference).map(|(a, b)| (a - b) * (a - b)).sum::<f64>()
                    / traj.len() as f64)
                    .sqrt()
                    / scale;
                points.push(Point { param: dt, seconds, error: err });
            }
            series.push(Series { label: method.label(), points });
        }
    }
    StudyResult {
        title: "FEM cantilever sagging under gravity (1 m, 480 tets, E = 1 MPa): tip trajectory".into(),
        slug: "fem-beam".into(),
        error_label: "RMS tip-height error / RMS tip deflection over 0.5 s".into(),
        param_label: "dt (s)".into(),
        series,
    }
}
