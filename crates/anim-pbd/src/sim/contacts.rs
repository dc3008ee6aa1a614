//! Line (8) of the loop, `generateCollisionConstraints(x_i -> p_i)`: every free particle is
//! tested against every collider at the collider's pose for the end of the substep, and a
//! particle whose predicted position `p` lies within `thickness + margin + |p - x|` of the
//! surface gets a contact constraint `n . (p - q) - thickness >= 0`, with `q` the closest surface
//! point and `n` the outward normal there, frozen for the substep ([`crate::collide`] has the
//! contact model, its friction and restitution). The contact also records how far the obstacle's
//! surface point moved over the substep (friction acts relative to it) and the normal velocity
//! before the solve (for restitution at line 16).
//!
//! A shape collider gives the signed distance and normal analytically; a mesh collider
//! ([`MeshCollider`](crate::MeshCollider)) samples them from its distance field, and a particle
//! outside the field's lattice gets no contact. Against a mesh the contact is continuous: a
//! particle whose motion over the substep is longer than its distance to the surface has its
//! path `x -> p` followed through the field, and where the path first comes within the
//! thickness (a point `y`) the contact is built from `y`'s closest surface point and normal
//! instead of `p`'s, so that a surface thinner than the motion stops the particle on its near
//! side (`collide/sweep.rs` has the march). The shape colliders come first, then the mesh
//! colliders, numbered on after them.
//!
//! Contacts are generated collider by collider, particles in increasing order, so each particle
//! appears at most once per collider: each collider's contacts form one group that the coloured
//! and Jacobi sweeps project in parallel.

use super::scratch::Data;
use crate::collide::{Contact, Pose, first_touch};
use crate::model::PbdModel;
use anim_core::glam::DVec3;
use anim_core::surface::DistanceField;

/// Line (8): fills `d.contacts` and their per-collider groups `d.contact_groups` for predicted
/// positions `d.p`, with speculative margin `margin`, over a substep of length `h`.
pub(super) fn generate_contacts(model: &PbdModel, d: &mut Data, margin: f64, h: f64) {
    d.contacts.clear();
    d.contact_groups.clear();
    for (ci, col) in model.colliders.iter().enumerate() {
        let distance = |local| Some(col.shape.signed_distance(local));
        collider_contacts(model, d, ci, col.body, col.thickness, margin, h, distance, None);
    }
    let first = model.colliders.len();
    for (k, col) in model.mesh_colliders.iter().enumerate() {
        let distance = |local| col.signed_distance(local);
        collider_contacts(
            model,
            d,
            first + k,
            col.body,
            col.thickness,
            margin,
            h,
            distance,
            Some(&col.shape),
        );
    }
}

/// The contacts of collider `ci` (on `body`, keeping `thickness`) as one group, its signed
/// distance and outward normal in its own frame given by `distance` (`None`: no contact); with
/// `field` (a mesh collider's), a particle's path is followed through it first
/// ([`first_touch`]) and the contact is built where the path first comes within the thickness.
#[allow(clippy::too_many_arguments)]
#[inline]
fn collider_contacts(
    model: &PbdModel,
    d: &mut Data,
    ci: usize,
    body: Option<usize>,
    thickness: f64,
    margin: f64,
    h: f64,
    distance: impl Fn(DVec3) -> Option<(f64, DVec3)>,
    field: Option<&DistanceField>,
) {
    let w = &model.inv_mass;
    let start = d.contacts.len();
    let (pose, prev) = match body {
        Some(b) => (d.pose_sub[b], d.pose_sub_prev[b]),
        None => (Pose::IDENTITY, Pose::IDENTITY),
    };
    for i in 0..model.num_particles() {
        if w[i] == 0.0 {
            continue;
        }
        let p = d.p[i];
        let local = pose.inverse_apply(p);
        // The path in the collider's frame: from the start in the substep's first pose to the
        // prediction in its last.
        let touch = field.and_then(|f| first_touch(f, prev.inverse_apply(d.x[i]), local, thickness));
        let (normal, q) = if let Some(y) = touch {
            let Some((phi, nl)) = distance(y) else {
                continue;
            };
            (pose.rotation * nl, pose.apply(y - nl * phi))
        } else {
            let Some((phi, nl)) = distance(local) else {
                continue;
            };
            if !(phi < thickness + margin + (p - d.x[i]).length()) {
                continue;
            }
            let normal = pose.rotation * nl;
            (normal, p - normal * phi)
        };
        let ql = pose.inverse_apply(q);
        let obstacle_dx = q - prev.apply(ql);
        let vn_pre = normal.dot(d.v[i] - obstacle_dx / h);
        d.contacts.push(Contact {
            particle: i as u32,
            collider: ci as u32,
            normal,
            offset: normal.dot(q) + thickness,
            obstacle_dx,
            vn_pre,
            lambda: 0.0,
            dx: DVec3::ZERO,
        });
    }
    d.contact_groups.push(start..d.contacts.len());
}
