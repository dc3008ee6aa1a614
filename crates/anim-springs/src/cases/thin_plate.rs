//! The hard case of a fast body against a thin mesh obstacle: particles thrown at a plate of
//! 1 cm at speeds up to 50 m/s. The contact is a penalty force (see [`crate::contact`]): it
//! acts on a particle whose position at the end of a step lies within the plate, pushing it
//! along the normal of the nearer face, so a particle is caught only if a step ends in the
//! plate's near half and the penalty there stops it before the middle. The case records the
//! largest speed at which every particle is caught, at the `springs` kind's step, integrator
//! and contact defaults (linearised backward Euler, `dt = 0.005` s, `k_c = 1e4` N/m,
//! `delta = 1` mm) and at a tenth of the step, with the bounds that predict it: the near half
//! of the plate reached by some step's end, `v dt < t / 2`, and its penalty energy absorbing the
//! particle's kinetic energy, `m v^2 / 2 < E(t / 2)`.

use crate::{MeshCollider, NetworkBuilder, SpringSimulation, scenes::animation_newton};
use anim_core::cases::{Ctx, Outcome, Sweep, fmt_num};
use anim_core::integrate::IntegratorKind;
use anim_core::linalg::LinearSolverKind;
use anim_core::surface::{ClosedSurface, DistanceField, cuboid};

/// The plate's thickness (m).
const PLATE: f64 = 0.01;
/// A particle's mass (kg): a vertex of a cloth of 0.2 kg/m^2 at 2 cm spacing is 8e-5 kg; a
/// heavier one is caught less easily.
const MASS: f64 = 1e-3;
/// Start offsets per speed: the ends of the step that reaches the plate fall at every depth.
const PHASES: usize = 16;

/// The plate `[-0.5, 0.5]^2 x [-0.01, 0]` (its top at `z = 0`) sampled every 5 mm, as the
/// kind's collider of it with the contact defaults.
fn plate() -> Result<MeshCollider, String> {
    let (p, t) = cuboid([-0.5, -0.5, -PLATE], [0.5, 0.5, 0.0]);
    let plate = ClosedSurface::new(p, t).map_err(|e| e.to_string())?;
    let field = DistanceField::around(&plate, 0.005, 0.05).map_err(|e| e.to_string())?;
    Ok(MeshCollider::new(field, 1e4).with_damping(0.1).with_friction(1.0).with_smoothing(1e-3))
}

/// Throws [`PHASES`] particles head on at `speed` from start heights a sixteenth of a step's
/// motion apart, steps `dt` for 0.1 s past the time they reach the plate, and counts those
/// that end under its bottom face.
fn crossed(collider: &MeshCollider, speed: f64, dt: f64) -> Result<usize, String> {
    let mut b = NetworkBuilder::new();
    for k in 0..PHASES {
        let height = 0.05 + (k as f64 / PHASES as f64) * speed * dt;
        b.particle([0.02 * k as f64 - 0.15, 0.0, height], MASS);
    }
    b.mesh_collider(collider.clone());
    let net = b.build().map_err(|e| e.to_string())?;
    let mut state = net.rest_state();
    for v in state.v.chunks_mut(3) {
        v[2] = -speed;
    }
    let mut sim = SpringSimulation::new(
        net,
        IntegratorKind::BackwardEuler,
        animation_newton(),
        LinearSolverKind::Cholesky,
    )
    .map_err(|e| e.to_string())?;
    let steps = ((0.1 + 0.1 / speed) / dt).ceil() as usize;
    for _ in 0..steps {
        sim.advance(&mut state, dt).map_err(|e| e.to_string())?;
    }
    Ok(state.x.chunks_exact(3).filter(|p| p[2] < -PLATE).count())
}

pub(super) fn thin_mesh_plate(ctx: &Ctx) -> Outcome {
    let collider = match plate() {
        Ok(c) => c,
        Err(e) => return Outcome::Rejected(e),
    };
    let speeds: &[f64] = if ctx.quick {
        &[0.5, 1.0, 2.0, 5.0, 20.0, 50.0]
    } else {
        &[0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 5.0, 7.5, 10.0, 20.0, 35.0, 50.0]
    };
    let mut rows = Vec::new();
    // m v^2 / 2 = E(t / 2) with E(p) = k (p^2 / 2 - delta p / 2 + delta^2 / 6).
    let (k, delta, p) = (collider.stiffness, collider.smoothing, PLATE / 2.0);
    let energy = k * (0.5 * p * p - 0.5 * delta * p + delta * delta / 6.0);
    for dt in [0.005, 5e-4] {
        match Sweep::run(speeds, |speed| crossed(&collider, speed, dt)) {
            Ok(sweep) => rows.push(format!(
                "dt = {dt} s: {}; bounds t / (2 dt) = {} m/s, sqrt(2 E(t/2) / m) = {} m/s",
                sweep.describe("particle", PHASES, 20.0),
                fmt_num(PLATE / (2.0 * dt)),
                fmt_num((2.0 * energy / MASS).sqrt()),
            )),
            Err(e) => return Outcome::Diverged(format!("dt = {dt}, {e}")),
        }
    }
    Outcome::Stable(format!(
        "particles of {MASS} kg thrown head on at a 1 cm mesh plate, penalty contact (k_c = 1e4 N/m, \
         delta = 1 mm), linearised backward Euler: {}",
        rows.join("; ")
    ))
}
