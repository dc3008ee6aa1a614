//! The hard case of a fast body against a thin mesh obstacle: particles and a cloth thrown at a
//! plate of 1 cm at 20 to 50 m/s, each substep carrying them several times the plate's
//! thickness. The mesh collider's continuous contact (`collide/sweep.rs`) must stop every one
//! on the near side; the case records the speeds tried and the first at which the plate is
//! crossed, if any, and, for comparison, the speed from which the closest-point contact of the
//! analytic box of the same plate lets particles through.

use crate::{
    Bending, Cloth, Collider, ConstraintParams, MeshCollider, Method, PbdBuilder, PbdParams, PbdSimulation,
    SolverKind,
};
use anim_core::cases::{Ctx, Outcome, Sweep, fmt_num};
use anim_core::glam::DVec3;
use anim_core::surface::{ClosedSurface, DistanceField, cuboid};

/// The particles' distance kept from the plate (m).
const THICKNESS: f64 = 0.002;
/// Start offsets per throw: the ends of the substep that reaches the plate fall at every depth.
const PHASES: usize = 16;
/// Substeps of a step of 1/60 s.
const SUBSTEPS: usize = 4;

/// The plate `[-0.5, 0.5]^2 x [-0.01, 0]` (its top at `z = 0`) sampled every 5 mm.
fn plate_field() -> Result<DistanceField, String> {
    let (p, t) = cuboid([-0.5, -0.5, -0.01], [0.5, 0.5, 0.0]);
    let plate = ClosedSurface::new(p, t).map_err(|e| e.to_string())?;
    DistanceField::around(&plate, 0.005, 0.05).map_err(|e| e.to_string())
}

/// Whether `x` is over the plate (and so must stay above it).
fn over(x: DVec3) -> bool {
    x.x.abs() < 0.5 && x.y.abs() < 0.5
}

/// Throws particles (head on and at 45 degrees, from 5 cm above the plate plus [`PHASES`]
/// offsets each) or, with `cloth`, a 10 x 10 cloth of 0.3 m held flat 5 cm above it, at `speed`
/// towards the plate, without gravity, against the mesh collider `mesh` or the shape collider
/// `shape`, for 12 steps of 1/60 s; how many particles were ever under the plate's top face
/// (plus the thickness) while over it, and how many particles there were.
fn throw(
    speed: f64,
    cloth: bool,
    mesh: Option<&MeshCollider>,
    shape: Option<Collider>,
) -> Result<(usize, usize), String> {
    // No gravity: the particles meet the plate at the speed they are thrown at.
    let mut b = PbdBuilder::new();
    let mut dirs = Vec::new();
    if cloth {
        b.cloth(&Cloth {
            origin: [-0.15, -0.15, 0.05],
            u: [0.3, 0.0, 0.0],
            v: [0.0, 0.3, 0.0],
            nx: 10,
            ny: 10,
            particle_mass: 1e-3,
            stretch: ConstraintParams::with_compliance(1e-6),
            bending: Bending::None,
        })
        .map_err(|e| e.to_string())?;
        dirs.resize(100, -DVec3::Z);
    } else {
        for angle in [0.0f64, 45f64.to_radians()] {
            let dir = DVec3::new(angle.sin(), 0.0, -angle.cos());
            for k in 0..PHASES {
                let target = DVec3::new(-0.2 * angle.sin(), 0.02 * k as f64 - 0.15, 0.0);
                let distance =
                    0.05 / angle.cos() + (k as f64 / PHASES as f64) * speed / (60.0 * SUBSTEPS as f64);
                b.particle((target - distance * dir).to_array(), 0.01);
                dirs.push(dir);
            }
        }
    }
    if let Some(m) = mesh {
        b.mesh_collider(m.clone());
    }
    if let Some(c) = shape {
        b.collider(c);
    }
    let model = b.build().map_err(|e| e.to_string())?;
    let mut state = model.rest_state();
    for (v, d) in state.v.chunks_mut(3).zip(&dirs) {
        v.copy_from_slice(&(speed * *d).to_array());
    }
    let params = PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 5, SUBSTEPS);
    let mut sim = PbdSimulation::new(model, params).map_err(|e| e.to_string())?;
    let mut crossed = vec![false; dirs.len()];
    for _ in 0..12 {
        sim.run(&mut state, 1.0 / 60.0, 1).map_err(|e| e.to_string())?;
        for (c, p) in crossed.iter_mut().zip(state.x.chunks_exact(3)) {
            let x = DVec3::new(p[0], p[1], p[2]);
            *c |= over(x) && x.z < THICKNESS - 1e-6;
        }
    }
    Ok((crossed.iter().filter(|&&c| c).count(), dirs.len()))
}

pub(super) fn thin_mesh_plate(ctx: &Ctx) -> Outcome {
    let field = match plate_field() {
        Ok(f) => f,
        Err(e) => return Outcome::Rejected(e),
    };
    let mesh = MeshCollider::new(field).with_thickness(THICKNESS).with_friction(0.5, 0.5);
    let slab = Collider::cuboid([0.0, 0.0, -0.005], [0.5, 0.5, 0.005])
        .with_thickness(THICKNESS)
        .with_friction(0.5, 0.5);
    // The speeds the plate must hold at, then faster ones: particles (head on and at 45 degrees)
    // and the cloth.
    let beyond: &[f64] = if ctx.quick { &[1e3] } else { &[100.0, 200.0, 500.0, 1e3, 2e3, 5e3, 1e4] };
    let speeds: Vec<f64> = [20.0, 30.0, 40.0, 50.0].iter().chain(beyond).copied().collect();
    let crossed = |speed| -> Result<usize, String> {
        Ok(throw(speed, false, Some(&mesh), None)?.0 + throw(speed, true, Some(&mesh), None)?.0)
    };
    let on_mesh = match Sweep::run(&speeds, crossed) {
        Ok(s) => s,
        Err(e) => return Outcome::Diverged(format!("mesh plate, {e}")),
    };
    let particles = 2 * PHASES + 100;
    if on_mesh.held() < 50.0 {
        return Outcome::Diverged(format!(
            "the 1 cm mesh plate: {}",
            on_mesh.describe("particle", particles, 20.0)
        ));
    }
    // The closest-point contact alone, on the analytic box of the plate.
    let boxed = Sweep::run(&[0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 5.0, 10.0, 20.0], |speed| {
        throw(speed, false, None, Some(slab)).map(|c| c.0)
    });
    let boxed = match boxed {
        Ok(s) => s,
        Err(e) => return Outcome::Diverged(format!("analytic box, {e}")),
    };
    let h = 1.0 / (60.0 * SUBSTEPS as f64);
    Outcome::Stable(format!(
        "1 cm plate (field every 5 mm), thickness {THICKNESS} m, substep {} s, particles head on and at 45 degrees \
         ({PHASES} start offsets each) and a 10 x 10 cloth head on: on the mesh plate {}; on the analytic box of the \
         plate (closest-point contact, no path) {} (predicted: from a substep's motion above half the plate plus the \
         thickness, {} m/s)",
        fmt_num(h),
        on_mesh.describe("particle", particles, 20.0),
        boxed.describe("particle", 2 * PHASES, 20.0),
        fmt_num((0.005 + THICKNESS) / h),
    ))
}
