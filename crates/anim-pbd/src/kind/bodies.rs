//! A `pbd` scene of the user's own bodies: the `[[scene.bodies]]` tables ([`BodySpec`]) with the
//! scene-wide `obstacles`, `friction`, `restitution`, `thickness`, `gravity`, `body_contacts`
//! and solver settings of [`PbdSceneParams`].
//!
//! Every body is added to one [`PbdBuilder`] in the order given. Unless `body_contacts = false`,
//! each body is also a contact body: its particles collide with the other bodies' surfaces (a
//! soft body's boundary, a cloth's triangles), with the scene's thickness and friction; particles
//! of one body do not collide with that body's own surface. The obstacles (shapes, and the
//! `obstacle_meshes` as [`MeshCollider`]s of their distance fields) are colliders with the same
//! thickness, friction (static and kinetic alike) and restitution; a mesh's field covers its
//! surface's bounds widened by the thickness plus the contact margin (and two cells).

use super::PbdSceneParams;
use super::body::BodySpec;
use crate::build::{EARTH_GRAVITY, PbdBuilder};
use crate::collide::{BodyContact, Collider, MeshCollider};
use crate::sim::{Method, PbdParams, PbdSimulation, SolverKind};
use anim_core::integrate::State;
use anim_core::scene::{BuildContext, BuildError};

/// The default contact thickness of a scene with bodies (m).
pub const DEFAULT_THICKNESS: f64 = crate::collide::DEFAULT_THICKNESS;
/// The default solver iterations per substep of a scene with bodies.
pub const DEFAULT_ITERATIONS: usize = 5;
/// The default substeps per step of a scene with bodies.
pub const DEFAULT_SUBSTEPS: usize = 4;

/// Refuses the fields only a scene with bodies takes when `p` runs a preset.
pub(super) fn refuse_body_fields(p: &PbdSceneParams) -> Result<(), BuildError> {
    let given = [
        ("obstacles", !p.obstacles.is_empty()),
        ("obstacle_meshes", !p.obstacle_meshes.is_empty()),
        ("friction", p.friction.is_some()),
        ("restitution", p.restitution.is_some()),
        ("thickness", p.thickness.is_some()),
        ("gravity", p.gravity.is_some()),
        ("body_contacts", p.body_contacts.is_some()),
    ];
    if let Some((field, _)) = given.iter().find(|(_, g)| *g) {
        return Err(BuildError::invalid(
            *field,
            format!("only a scene with `bodies` takes `{field}`; a preset brings its own"),
        ));
    }
    Ok(())
}

/// The simulation and initial state of the bodies of `p` (which has no preset), their files read
/// relative to `context`.
pub(super) fn build_bodies(
    p: &PbdSceneParams,
    context: &BuildContext<'_>,
) -> Result<(PbdSimulation, State), BuildError> {
    if p.resolution.is_some() {
        return Err(BuildError::invalid(
            "resolution",
            "a scene with `bodies` takes no `resolution`: a body's resolution is its mesh's",
        ));
    }
    let gravity = p.gravity.unwrap_or(EARTH_GRAVITY);
    if !gravity.iter().all(|g| g.is_finite()) {
        return Err(BuildError::invalid("gravity", format!("{gravity:?} holds a non-finite value")));
    }
    let friction = p.friction.unwrap_or(0.0);
    if !(friction >= 0.0 && friction.is_finite()) {
        return Err(BuildError::invalid(
            "friction",
            format!("must be non-negative and finite, got {friction}"),
        ));
    }
    let restitution = p.restitution.unwrap_or(0.0);
    if !(0.0..=1.0).contains(&restitution) {
        return Err(BuildError::invalid("restitution", format!("must lie in [0, 1], got {restitution}")));
    }
    let thickness = p.thickness.unwrap_or(DEFAULT_THICKNESS);
    if !(thickness > 0.0 && thickness.is_finite()) {
        return Err(BuildError::invalid(
            "thickness",
            format!("must be positive and finite, got {thickness}"),
        ));
    }
    for (k, shape) in p.obstacles.iter().enumerate() {
        // Every shape of anim-core's geometry is a PBD collider; only bad parameters are refused.
        shape
            .check()
            .map_err(|e| BuildError::invalid(format!("obstacles[{k}]"), format!("{}: {e}", shape.name())))?;
    }
    // `iterations` and `substeps` outside [1, MAX_PBD_COUNT] were refused with the other fields.
    let params = PbdParams::new(
        p.method.unwrap_or(Method::Xpbd),
        SolverKind::ColoredGaussSeidel,
        p.iterations.unwrap_or(DEFAULT_ITERATIONS),
        p.substeps.unwrap_or(DEFAULT_SUBSTEPS),
    );
    let fields = super::obstacles::fields(&p.obstacle_meshes, context, thickness + params.contact_margin)?;
    let mut b = PbdBuilder::new();
    b.gravity(gravity);
    let mut added = Vec::with_capacity(p.bodies.len());
    for (k, body) in p.bodies.iter().enumerate() {
        added.push(body.add(k, context, &mut b)?);
    }
    if p.body_contacts.unwrap_or(true) && added.len() > 1 {
        for body in &added {
            b.contact_body(body.particles.clone(), &body.surface, body.closed);
        }
        b.body_contact(BodyContact { thickness, static_friction: friction, kinetic_friction: friction });
    }
    for shape in &p.obstacles {
        b.collider(
            Collider::new(*shape)
                .with_thickness(thickness)
                .with_friction(friction, friction)
                .with_restitution(restitution),
        );
    }
    for field in fields {
        b.mesh_collider(
            MeshCollider::new(field)
                .with_thickness(thickness)
                .with_friction(friction, friction)
                .with_restitution(restitution),
        );
    }
    let model = b.build().map_err(|e| BuildError::invalid("bodies", e.to_string()))?;
    let mut state = model.rest_state();
    for (spec, body) in p.bodies.iter().zip(&added) {
        set_velocity(spec, body.particles.clone(), &body.pinned, &mut state);
    }
    let sim = PbdSimulation::new(model, params).map_err(|e| BuildError::invalid("bodies", e.to_string()))?;
    Ok((sim, state))
}

/// Gives the particles of `spec`'s body but the pinned ones its initial velocity.
fn set_velocity(spec: &BodySpec, particles: std::ops::Range<usize>, pinned: &[usize], state: &mut State) {
    if spec.velocity == [0.0; 3] {
        return;
    }
    for i in particles {
        if pinned.binary_search(&i).is_err() {
            state.v[3 * i..3 * i + 3].copy_from_slice(&spec.velocity);
        }
    }
}
