//! The hard case of a fast body against a thin mesh obstacle: an elastic block thrown at a plate
//! of 1 cm at 20 and 50 m/s. A mesh obstacle acts on the grid nodes inside it
//! ([`crate::mesh_collider`]), and the step's substeps keep a particle's motion within a cell
//! (the advective CFL limit), so a plate is as thin as the grid sees it: the case records what
//! happens at two resolutions, for a plate whose middle holds a layer of nodes (from how many
//! particles end up beyond it), and for one between two layers of nodes (refused: no node
//! inside it, it would have no effect).

use crate::mesh_collider::MeshCollider;
use crate::scenes::fill;
use crate::{Boundary, Elastic, Material, MpmError, MpmParams, MpmSimulation, Particles};
use anim_core::cases::{Ctx, Outcome, fmt_num};
use anim_core::surface::{ClosedSurface, cuboid};

/// The plate's thickness (m).
const PLATE: f64 = 0.01;

/// The plate `[0.2, 0.8]^2 x [z0, z0 + 1 cm]` as the grid of `params` sees it.
fn plate(params: &MpmParams, z0: f64) -> Result<MeshCollider, String> {
    let (p, t) = cuboid([0.2, 0.2, z0], [0.8, 0.8, z0 + PLATE]);
    let surface = ClosedSurface::new(p, t).map_err(|e| e.to_string())?;
    MeshCollider::new(&surface, params, Boundary::SeparateFrictionless)
}

/// Throws a 6 cm elastic block (E = 1e4 Pa, 2 particles per cell and axis) down at `speed`
/// from 6 cm above the plate whose bottom is at `z0` (or where it would be, without
/// `with_plate`), without gravity, for the time it takes to cover 20 cm; the fraction of its
/// particles below the plate at the end.
fn through(resolution: usize, z0: f64, speed: f64, with_plate: bool) -> Result<f64, MpmError> {
    let mut params = MpmParams::with_resolution(resolution);
    params.gravity = [0.0; 3];
    let h = params.h();
    let collider = plate(&params, z0).map_err(|reason| MpmError::BadCollider { index: 0, reason })?;
    let mut sim = MpmSimulation::<3>::new(params, vec![Material::Elastic(Elastic::default())])?;
    if with_plate {
        sim.set_mesh_colliders(vec![collider])?;
    }
    let mut p = Particles::<3>::new();
    let top = z0 + PLATE;
    fill(
        &mut p,
        h,
        2,
        [0.47, 0.47, top + 0.06],
        [0.53, 0.53, top + 0.12],
        0,
        1000.0,
        [0.0, 0.0, -speed as f32],
        |_| true,
    )?;
    let dt = 1e-3;
    for _ in 0..((0.2 / speed) / dt).ceil() as usize {
        sim.advance(&mut p, dt)?;
    }
    let below = (0..p.len()).filter(|&i| f64::from(p.x[3 * i + 2]) < z0).count();
    Ok(below as f64 / p.len() as f64)
}

pub(super) fn thin_mesh_plate(ctx: &Ctx) -> Outcome {
    let resolutions: &[usize] = if ctx.quick { &[32] } else { &[32, 64] };
    let mut rows = Vec::new();
    for &n in resolutions {
        let h = 1.0 / n as f64;
        // Around the middle node layer z = 0.5, and between the layers at 0.5 and 0.5 + h.
        let (on, between) = (0.5 - 0.5 * PLATE, 0.5 + 0.5 * (h - PLATE));
        let mut at = Vec::new();
        for speed in [20.0, 50.0] {
            match (through(n, on, speed, true), through(n, on, speed, false)) {
                (Ok(f), Ok(free)) => at.push(format!(
                    "{}% at {speed} m/s ({}% without the plate)",
                    fmt_num(100.0 * f),
                    fmt_num(100.0 * free)
                )),
                (Err(e @ MpmError::NonFinite { .. }), _) | (_, Err(e @ MpmError::NonFinite { .. })) => {
                    return Outcome::Diverged(e.to_string());
                }
                (Err(e), _) | (_, Err(e)) => {
                    return Outcome::Rejected(format!("resolution {n}, {speed} m/s: {e}"));
                }
            }
        }
        let refused = match plate(&MpmParams::with_resolution(n), between) {
            Err(e) => format!("refused ({e})"),
            Ok(_) => "accepted".to_string(),
        };
        rows.push(format!(
            "resolution {n} (cells {} m): a plate holding a node layer stops the block (beyond it: {}); \
             one between two layers is {refused}",
            fmt_num(h),
            at.join(", "),
        ));
    }
    Outcome::Stable(format!(
        "a 6 cm elastic block thrown at a 1 cm mesh plate (separating, frictionless; substeps at CFL 1): {}",
        rows.join("; ")
    ))
}
