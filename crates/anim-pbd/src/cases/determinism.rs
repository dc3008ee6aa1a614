//! Determinism across thread counts: the cloth drape, and the same cloth falling onto a mesh
//! sphere (a distance field), run on rayon pools of 1, 2 and 4 threads must end in the same
//! state, bit for bit.

use crate::{Cloth, Collider, ConstraintParams, EARTH_GRAVITY, MeshCollider, PbdBuilder, PbdSimulation};
use anim_core::cases::{Check, Ctx, across_threads};
use anim_core::solver::Solver;
use anim_core::surface::{ClosedSurface, DistanceField, icosphere};

pub(super) fn drape(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 30 } else { 300 };
    across_threads("anim-pbd", "cloth drape", || {
        let scene = crate::scenes::cloth_drape(None).map_err(|e| e.to_string())?;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok(state.x.iter().chain(&state.v).copied().collect())
    })
}

/// The drape's cloth and settings over a mesh sphere of the drape's size (an icosphere of 5120
/// triangles sampled at 1 cm, its field built once and shared by the runs).
pub(super) fn drape_on_mesh(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 30 } else { 300 };
    let field = (|| {
        let (p, t) = icosphere(4);
        let p = p.iter().map(|x| [0.35 * x[0] + 0.05, 0.35 * x[1], 0.35 * x[2] + 0.35]).collect();
        let ball = ClosedSurface::new(p, t).map_err(|e| e.to_string())?;
        DistanceField::around(&ball, 0.01, 0.05).map_err(|e| e.to_string())
    })();
    across_threads("anim-pbd", "cloth drape on a mesh sphere", || {
        let field = field.clone()?;
        let scene = crate::scenes::cloth_drape(None).map_err(|e| e.to_string())?;
        let n = 32;
        let mut b = PbdBuilder::new();
        b.gravity(EARTH_GRAVITY);
        b.cloth(&Cloth {
            nx: n,
            ny: n,
            origin: [-0.6, -0.6, 1.2],
            u: [1.2, 0.0, 0.0],
            v: [0.0, 1.2, 0.0],
            particle_mass: 0.3 / (n * n) as f64,
            stretch: ConstraintParams::rigid(),
            bending: crate::Bending::Isometric(ConstraintParams::with_compliance(20.0)),
        })
        .map_err(|e| e.to_string())?;
        b.mesh_collider(MeshCollider::new(field).with_thickness(0.01).with_friction(0.6, 0.4));
        b.collider(Collider::ground(0.0).with_thickness(0.01).with_friction(0.6, 0.4));
        let model = b.build().map_err(|e| e.to_string())?;
        let mut state = model.rest_state();
        let mut sim = PbdSimulation::new(model, scene.params).map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.step(&mut state, scene.dt).map_err(|e| e.to_string())?;
        }
        Ok(state.x.iter().chain(&state.v).copied().collect())
    })
}
