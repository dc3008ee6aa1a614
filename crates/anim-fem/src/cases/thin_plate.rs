//! The hard case of a fast body against a thin mesh obstacle: small elastic cubes thrown at a
//! plate of 1 cm at speeds up to 50 m/s. Contact with an obstacle is a penalty in backward
//! Euler's incremental potential ([`crate::boundary`]): it acts on a vertex whose position at
//! the end of a step lies within the plate, along the gradient of the nearer face, so a vertex
//! is caught only if a step ends in the plate's near half and the penalty there stops it before
//! the middle. The case records the largest speed at which every cube is caught at the `fem`
//! kind's defaults (`dt = 1/120` s, contact stiffness `1e7` N/m) and at a tenth of the step,
//! with the bound that predicts it: some step's end in the near half, `v dt < t / 2`.

use crate::generate::box_mesh;
use crate::material::{Material, MaterialModel};
use crate::mesh::TetMesh;
use crate::model::FemModel;
use crate::sim::{FemParams, FemSimulation};
use anim_core::cases::{Ctx, Outcome, Sweep, fmt_num};
use anim_core::solver::Solver;
use anim_core::surface::{ClosedSurface, DistanceField, cuboid};

/// The plate's thickness (m).
const PLATE: f64 = 0.01;
/// Start offsets per speed: the ends of the step that reaches the plate fall at every depth.
const PHASES: usize = 8;
/// The cubes' edge (m).
const EDGE: f64 = 0.02;

/// The plate `[-0.5, 0.5]^2 x [-0.01, 0]` (its top at `z = 0`) sampled every 5 mm.
fn plate_field() -> Result<DistanceField, String> {
    let (p, t) = cuboid([-0.5, -0.5, -PLATE], [0.5, 0.5, 0.0]);
    let plate = ClosedSurface::new(p, t).map_err(|e| e.to_string())?;
    DistanceField::around(&plate, 0.005, 0.05).map_err(|e| e.to_string())
}

/// Throws [`PHASES`] cubes of 2 cm (stable Neo-Hookean, E = 1e5 Pa) head on at `speed` from
/// heights a step's motion over `PHASES` apart, steps `dt` for 0.05 s past the time they reach
/// the plate, and counts the cubes with a vertex under its bottom face.
fn crossed(field: &DistanceField, speed: f64, dt: f64) -> Result<usize, String> {
    let mut mesh = TetMesh { positions: Vec::new(), tets: Vec::new() };
    for k in 0..PHASES {
        let height = 0.02 + (k as f64 / PHASES as f64) * speed * dt;
        let cube = box_mesh([0.05 * k as f64 - 0.2, 0.0, height], [EDGE; 3], [1, 1, 1])
            .map_err(|e| e.to_string())?;
        let first = mesh.positions.len();
        mesh.positions.extend(cube.positions);
        mesh.tets.extend(cube.tets.iter().map(|t| t.map(|i| i + first)));
    }
    let per_cube = mesh.positions.len() / PHASES;
    let material =
        Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).map_err(|e| e.to_string())?;
    let mut model = FemModel::new(mesh, material).map_err(|e| e.to_string())?;
    model.add_mesh_obstacle(field.clone(), 1e7, 0.0).map_err(|e| e.to_string())?;
    let mut sim = FemSimulation::new(model, FemParams::default()).map_err(|e| e.to_string())?;
    let mut state = sim.rest_state();
    for v in state.v.chunks_mut(3) {
        v[2] = -speed;
    }
    let steps = ((0.05 + 0.1 / speed) / dt).ceil() as usize;
    for _ in 0..steps {
        sim.step(&mut state, dt).map_err(|e| e.to_string())?;
    }
    let below: Vec<bool> = state.x.chunks_exact(3).map(|p| p[2] < -PLATE).collect();
    Ok(below.chunks(per_cube).filter(|cube| cube.iter().any(|&b| b)).count())
}

pub(super) fn thin_mesh_plate(ctx: &Ctx) -> Outcome {
    let field = match plate_field() {
        Ok(f) => f,
        Err(e) => return Outcome::Rejected(e),
    };
    let speeds: &[f64] = if ctx.quick {
        &[0.25, 1.0, 5.0, 20.0, 50.0]
    } else {
        &[0.25, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 35.0, 50.0]
    };
    let mut rows = Vec::new();
    for dt in [1.0 / 120.0, 1.0 / 1200.0] {
        let sweep = match Sweep::run(speeds, |speed| crossed(&field, speed, dt)) {
            Ok(s) => s,
            Err(e) => return Outcome::Diverged(format!("dt = {dt}, {e}")),
        };
        let bound = fmt_num(PLATE / (2.0 * dt));
        rows.push(format!(
            "dt = {} s: {}; bound t / (2 dt) = {bound} m/s",
            fmt_num(dt),
            sweep.describe("cube", PHASES, 20.0)
        ));
    }
    Outcome::Stable(format!(
        "2 cm cubes (E = 1e5 Pa) thrown head on at a 1 cm mesh plate, penalty contact (1e7 N/m), backward Euler: {}",
        rows.join("; ")
    ))
}
