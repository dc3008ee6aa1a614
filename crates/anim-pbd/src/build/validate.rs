//! Checking and building: [`PbdBuilder::build`] validates every input (sizes, masses, positions,
//! pins, bodies, colliders, wind, triangles, edges, every constraint's indices, parameters and
//! rest shape, every balloon's mesh) and reports the first problem as a [`BuildError`] naming the
//! element; only then does a [`PbdModel`] exist. The rest values are computed from the positions
//! here, and the model's incidence lists (the constraints at each particle, in increasing
//! constraint order, and the triangles at each particle) are built for the solvers' fixed-order
//! sums. A balloon's mesh must be closed and consistently oriented with a positive volume: every
//! directed edge appears once and has its opposite.

use super::builder::{PbdBuilder, Pending, bad};
use super::closed::closed_outward;
use super::error::{BuildError, InputError};
use crate::constraint::{
    AttachTarget, Constraint, ConstraintFunction, ConstraintParams, IsometricBending, dihedral,
    isometric_weights, tet_is_flat, tet_volume,
};
use crate::model::{Particle, PbdModel, VolumeMesh};
use anim_core::glam::DVec3;
use anim_core::input::{check_particles, check_triangle_indices};
use std::collections::HashMap;

impl PbdBuilder {
    /// Checks everything and builds the model.
    ///
    /// # Errors
    /// The first problem found, as a [`BuildError`] naming the element.
    pub fn build(&self) -> Result<PbdModel, BuildError> {
        let n = self.positions.len();
        if n == 0 {
            return Err(BuildError::Input(InputError::NoParticles));
        }
        if n >= u32::MAX as usize {
            return Err(BuildError::Input(InputError::TooLarge {
                what: "particles",
                count: n,
                max: u32::MAX as usize - 1,
            }));
        }
        if self.pending.len() >= u32::MAX as usize {
            return Err(BuildError::Input(InputError::TooLarge {
                what: "constraints",
                count: self.pending.len(),
                max: u32::MAX as usize - 1,
            }));
        }
        let pinned = check_particles(&self.positions, &self.masses, &self.pins, self.gravity)?;
        let particles: Vec<Particle> =
            self.masses.iter().zip(pinned).map(|(&mass, pinned)| Particle { mass, pinned }).collect();
        let inv_mass: Vec<f64> =
            particles.iter().map(|p| if p.pinned { 0.0 } else { 1.0 / p.mass }).collect();
        for (b, body) in self.bodies.iter().enumerate() {
            let pose = body.pose;
            let ok = pose.position.is_finite()
                && pose.rotation.is_finite()
                && (pose.rotation.length() - 1.0).abs() < 1e-6
                && match body.motion {
                    crate::collide::BodyMotion::Fixed => true,
                    crate::collide::BodyMotion::Constant { velocity, angular_velocity } => {
                        velocity.iter().chain(&angular_velocity).all(|v| v.is_finite())
                    }
                    crate::collide::BodyMotion::Oscillate { amplitude, frequency } => {
                        amplitude.iter().all(|v| v.is_finite()) && frequency.is_finite()
                    }
                };
            if !ok {
                return Err(BuildError::BadBody {
                    body: b,
                    reason: "pose must be finite with a unit quaternion, motion finite".into(),
                });
            }
        }
        let colliders = self
            .colliders
            .iter()
            .enumerate()
            .map(|(k, c)| {
                c.validate(self.bodies.len())
                    .map_err(|reason| BuildError::Input(InputError::BadCollider { collider: k, reason }))
            })
            .collect::<Result<Vec<_>, _>>()?;
        for (k, c) in self.mesh_colliders.iter().enumerate() {
            c.check_contact(self.bodies.len())
                .map_err(|reason| BuildError::BadMeshCollider { collider: k, reason })?;
        }
        if let Some(w) = self.wind
            && !(w.velocity.iter().all(|v| v.is_finite())
                && w.drag >= 0.0
                && w.drag.is_finite()
                && w.gust.is_finite())
        {
            return Err(bad(
                "wind",
                "velocity, drag, gust",
                "must be finite with drag >= 0",
                format!("{w:?}"),
            ));
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            check_triangle_indices(t, *tri, n)?;
        }
        for e in &self.edges {
            if let Some(&i) = e.iter().find(|&&i| i >= n) {
                return Err(bad("edge", "vertex", "must be a particle index", i));
            }
        }
        self.check_contact_bodies(n)?;
        let pos: Vec<DVec3> = self.positions.iter().map(|&p| DVec3::from_array(p)).collect();
        let mut volume_meshes = Vec::with_capacity(self.volume_meshes.len());
        for (tris, c) in &self.volume_meshes {
            volume_meshes.push(volume_mesh(tris, &pos, *c)?);
        }
        let mut constraints = Vec::with_capacity(self.pending.len());
        for (j, (p, params)) in self.pending.iter().enumerate() {
            constraints.push(self.constraint(j, p, params, &pos, &volume_meshes)?);
        }
        // Incidence: constraints per particle, in increasing constraint order.
        let mut count = vec![0usize; n + 1];
        let parts = |c: &Constraint| -> Vec<usize> {
            match &c.function {
                ConstraintFunction::GlobalVolume { mesh, .. } => volume_meshes[*mesh].vertices.clone(),
                _ => c.particles().to_vec(),
            }
        };
        let all_parts: Vec<Vec<usize>> = constraints.iter().map(parts).collect();
        for ps in &all_parts {
            for &p in ps {
                count[p + 1] += 1;
            }
        }
        for p in 0..n {
            count[p + 1] += count[p];
        }
        let inc_ptr = count.clone();
        let mut fill = count;
        let mut inc = vec![(0u32, 0u32); inc_ptr[n]];
        for (j, ps) in all_parts.iter().enumerate() {
            for (slot, &p) in ps.iter().enumerate() {
                inc[fill[p]] = (j as u32, slot as u32);
                fill[p] += 1;
            }
        }
        let mut tcount = vec![0usize; n + 1];
        for t in &self.triangles {
            for &p in t {
                tcount[p + 1] += 1;
            }
        }
        for p in 0..n {
            tcount[p + 1] += tcount[p];
        }
        let tri_ptr = tcount.clone();
        let mut tfill = tcount;
        let mut tri_inc = vec![0u32; tri_ptr[n]];
        for (k, t) in self.triangles.iter().enumerate() {
            for &p in t {
                tri_inc[tfill[p]] = k as u32;
                tfill[p] += 1;
            }
        }
        Ok(PbdModel {
            particles,
            inv_mass,
            positions: self.positions.clone(),
            constraints,
            volume_meshes,
            colliders,
            mesh_colliders: self.mesh_colliders.clone(),
            bodies: self.bodies.clone(),
            gravity: DVec3::from_array(self.gravity),
            wind: self.wind,
            triangles: self.triangles.clone(),
            edges: self.edges.clone(),
            tets: self.tets.clone(),
            contact_bodies: self.contact_bodies.clone(),
            body_contact: self.body_contact,
            inc_ptr,
            inc,
            tri_ptr,
            tri_inc,
        })
    }

    fn constraint(
        &self,
        j: usize,
        p: &Pending,
        params: &ConstraintParams,
        pos: &[DVec3],
        meshes: &[VolumeMesh],
    ) -> Result<Constraint, BuildError> {
        let n = pos.len();
        let kind = match p {
            Pending::Distance { .. } => "distance",
            Pending::Dihedral(_) => "dihedral bending",
            Pending::Isometric(_) => "isometric bending",
            Pending::Tet(_) => "tetrahedral volume",
            Pending::Volume { .. } => "global volume",
            Pending::Attach { .. } => "attachment",
        };
        if !(0.0..=1.0).contains(&params.stiffness) {
            return Err(BuildError::BadStiffness { constraint: j, kind, value: params.stiffness });
        }
        if !(params.compliance >= 0.0 && params.compliance.is_finite()) {
            return Err(BuildError::BadCompliance { constraint: j, kind, value: params.compliance });
        }
        if !(params.damping >= 0.0 && params.damping.is_finite()) {
            return Err(BuildError::BadDamping { constraint: j, kind, value: params.damping });
        }
        let indices: Vec<usize> = match p {
            Pending::Distance { i, j, .. } => vec![*i, *j],
            Pending::Dihedral(s) | Pending::Isometric(s) | Pending::Tet(s) => s.to_vec(),
            Pending::Volume { .. } => vec![],
            Pending::Attach { particle, .. } => vec![*particle],
        };
        for (a, &i) in indices.iter().enumerate() {
            if i >= n {
                return Err(BuildError::ConstraintIndex { constraint: j, kind, index: i, particles: n });
            }
            if indices[..a].contains(&i) {
                return Err(BuildError::RepeatedIndex { constraint: j, kind, particle: i });
            }
        }
        let degenerate =
            |reason| BuildError::DegenerateRest { constraint: j, kind, particles: indices.clone(), reason };
        let function = match p {
            Pending::Distance { i, j: k, rest } => {
                let l = rest.unwrap_or_else(|| (pos[*i] - pos[*k]).length());
                if !(l >= 0.0 && l.is_finite()) {
                    return Err(BuildError::BadRestValue {
                        constraint: j,
                        kind,
                        name: "rest length",
                        requirement: "non-negative and finite",
                        value: l,
                    });
                }
                ConstraintFunction::Distance { particles: [*i, *k], rest_length: l }
            }
            Pending::Dihedral(s) => {
                let (theta, _) =
                    dihedral(s.map(|i| pos[i])).ok_or_else(|| degenerate("a triangle has zero area"))?;
                ConstraintFunction::DihedralBending { particles: *s, rest_angle: theta }
            }
            Pending::Isometric(s) => {
                let (weights, rest) = isometric_weights(s.map(|i| pos[i].to_array()))
                    .ok_or_else(|| degenerate("a triangle has zero area"))?;
                ConstraintFunction::IsometricBending(IsometricBending { particles: *s, weights, rest })
            }
            Pending::Tet(s) => {
                let p4 = s.map(|i| pos[i]);
                let v = tet_volume(p4).0;
                if tet_is_flat(p4, v) {
                    return Err(degenerate("zero volume"));
                }
                ConstraintFunction::TetVolume { particles: *s, rest_volume: v }
            }
            Pending::Volume { mesh, pressure } => {
                if !(*pressure > 0.0 && pressure.is_finite()) {
                    return Err(BuildError::BadRestValue {
                        constraint: j,
                        kind,
                        name: "pressure",
                        requirement: "positive and finite",
                        value: *pressure,
                    });
                }
                let m = &meshes[*mesh];
                let x: Vec<f64> = pos.iter().flat_map(|p| p.to_array()).collect();
                ConstraintFunction::GlobalVolume {
                    mesh: *mesh,
                    rest_volume: m.volume(&x),
                    pressure: *pressure,
                }
            }
            Pending::Attach { particle, target, distance } => {
                if !(*distance >= 0.0 && distance.is_finite()) {
                    return Err(BuildError::BadRestValue {
                        constraint: j,
                        kind,
                        name: "distance",
                        requirement: "non-negative and finite",
                        value: *distance,
                    });
                }
                match target {
                    AttachTarget::Point(t) if !t.iter().all(|c| c.is_finite()) => {
                        return Err(BuildError::BadRestValue {
                            constraint: j,
                            kind,
                            name: "target",
                            requirement: "finite",
                            value: f64::NAN,
                        });
                    }
                    AttachTarget::Body { body, local } => {
                        if *body >= self.bodies.len() {
                            return Err(BuildError::BodyIndex {
                                constraint: j,
                                body: *body,
                                bodies: self.bodies.len(),
                            });
                        }
                        if !local.iter().all(|c| c.is_finite()) {
                            return Err(BuildError::BadRestValue {
                                constraint: j,
                                kind,
                                name: "local point",
                                requirement: "finite",
                                value: f64::NAN,
                            });
                        }
                    }
                    AttachTarget::Point(_) => {}
                }
                ConstraintFunction::Attachment { particle: *particle, target: *target, distance: *distance }
            }
        };
        Ok(Constraint { function, params: *params })
    }
}

/// Validates a closed mesh (closed, oriented outward: [`closed_outward`]) and converts it to
/// local indices.
fn volume_mesh(tris: &[[usize; 3]], pos: &[DVec3], constraint: usize) -> Result<VolumeMesh, BuildError> {
    let n = pos.len();
    let fail =
        |reason: String| BuildError::BadVolumeMesh { reason: format!("constraint {constraint}: {reason}") };
    if tris.len() < 4 {
        return Err(fail(format!("a closed mesh needs at least 4 triangles, got {}", tris.len())));
    }
    for (t, tri) in tris.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i >= n) {
            return Err(fail(format!("triangle {t} names particle {i}, which does not exist")));
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            return Err(fail(format!("triangle {t} {tri:?} repeats a vertex")));
        }
    }
    closed_outward(tris, |i| pos[i]).map_err(|e| fail(e.to_string()))?;
    let mut vertices: Vec<usize> = tris.iter().flatten().copied().collect();
    vertices.sort_unstable();
    vertices.dedup();
    let local: HashMap<usize, u32> = vertices.iter().enumerate().map(|(k, &v)| (v, k as u32)).collect();
    let triangles = tris.iter().map(|t| t.map(|i| local[&i])).collect();
    Ok(VolumeMesh { vertices, triangles })
}
