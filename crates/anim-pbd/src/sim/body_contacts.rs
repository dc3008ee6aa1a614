//! Contacts between bodies: line (8) and the iterations for the model's contact bodies
//! ([`PbdBuilder::contact_body`](crate::PbdBuilder::contact_body)). Every particle of a contact
//! body is tested against the surface triangles of the other contact bodies; it gets at most one
//! contact per other body, with the triangle closest to its predicted position `p`, when that
//! distance is below `thickness + margin + |p - x| + max_k |p_k - x_k|` (the triangle's corners
//! `k`: both sides may move). The constraint, with the closest point's barycentric coordinates
//! `b_k` and the unit normal `n` frozen for the substep,
//!
//! ```text
//! C = n . (p - sum_k b_k p_k) - thickness >= 0,    grad_p C = n,  grad_{p_k} C = -b_k n
//! ```
//!
//! is projected like a collider's contact (rigid, an inequality; XPBD keeps its multiplier
//! `>= 0`), both sides weighted by their inverse masses, with positional friction on the relative
//! tangential motion over the substep (`mu_s`, `mu_k` of [`BodyContact`](crate::BodyContact);
//! see [`crate::collide`]). There is no restitution between bodies.
//!
//! The normal is the triangle's (at `p`): outward for a closed surface, so a particle that went
//! inside is pushed back out, if it is within the reach above of the surface (one that went
//! deeper, say through a thin body in one substep, gets no contact and stays inside: there is no
//! inside test); for an open surface (cloth) it points to the side the particle was on at the
//! start of the substep. Where the closest point is on an edge or a corner of the triangle (a
//! barycentric coordinate 0) the normal is instead the direction from the closest point to the
//! particle, turned to the side of the triangle's normal: a particle beside a body's edge,
//! level with its bottom face, is as close to the side face, whose normal would push it
//! sideways by up to `thickness` and make a body sliding over another catch on its vertices.
//! Among triangles as close within `1e-9` of the particle's reach, the one whose normal best
//! matches that direction wins (its cosine, or for an open surface its absolute value), then
//! the first.
//!
//! The candidates come from a uniform grid hashed by cell and body (a counting sort into a
//! fixed table), rebuilt every substep from the triangles' boxes grown by the search radius,
//! with cells at least as large as the largest grown box, so that a particle looks in one
//! bucket per other body. The cells are counted from the lowest corner of the boxes, so that
//! their rounding depends on the scene's extent, not on its distance from the origin. Particles
//! are visited in increasing order and each bucket's triangles in increasing order, so the
//! contacts and their order do not depend on the number of threads. The contacts are projected
//! sequentially after the collider contacts in every iteration, whatever the solver. Buffers are
//! sized when the simulation is made: a step allocates nothing unless a particle touches more
//! than four other bodies at once, or the scene is so wide (some 1e13 cells) that rounding
//! spreads a box over a third cell.

use super::scratch::Data;
use crate::model::PbdModel;
use crate::project::{CONTACT_ID, Ctx, contact_correction, positional_friction};
use anim_core::geometry::closest_point_on_triangle;
use anim_core::glam::DVec3;

/// Contacts per particle the buffer is sized for: a particle touching more bodies at once
/// makes the step grow it.
const MAX_RESERVED: usize = 4;

/// A contact between a particle and a triangle of another body, for one substep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PairContact {
    /// The particle.
    pub particle: u32,
    /// The triangle's corners.
    pub tri: [u32; 3],
    /// Barycentric coordinates of the closest point.
    pub bary: [f64; 3],
    /// Unit normal (from the triangle towards the particle's side).
    pub normal: DVec3,
    /// Accumulated normal correction (PBD) or multiplier (XPBD) this substep.
    pub lambda: f64,
}

/// The buffers of the body contacts: the surface triangles with their bodies, their boxes, the
/// spatial hash, the closest triangle per other body of the particle being tested, and the
/// contacts.
#[derive(Debug, Default)]
pub(super) struct BodyContactData {
    /// Every contact body's surface triangles with the body's index.
    pub surface: Vec<([u32; 3], u32)>,
    /// Per surface triangle: the box of its predicted corners and their largest motion.
    pub boxes: Vec<(DVec3, DVec3, f64)>,
    /// The hash table: bucket `k` holds `entries[start[k]..start[k + 1]]`.
    pub start: Vec<u32>,
    /// Surface triangles by bucket, in increasing order within each.
    pub entries: Vec<u32>,
    /// Per contact body: `(distance, fit, surface triangle)` of the closest triangle so far
    /// (see [`reach_distance`]).
    pub best: Vec<(f64, f64, u32)>,
    /// The contacts of the substep.
    pub contacts: Vec<PairContact>,
}

impl BodyContactData {
    /// Buffers for `model`'s contact bodies (empty without at least two).
    pub(super) fn new(model: &PbdModel) -> Self {
        let bodies = &model.contact_bodies;
        if bodies.len() < 2 {
            return Self::default();
        }
        let surface: Vec<([u32; 3], u32)> = bodies
            .iter()
            .enumerate()
            .flat_map(|(b, body)| body.triangles.iter().map(move |t| (t.map(|i| i as u32), b as u32)))
            .collect();
        let particles: usize = bodies.iter().map(|b| b.particles.1 - b.particles.0).sum();
        // A triangle's grown box spans at most two cells along each axis: at most 8 entries
        // each, in a table of at least twice as many buckets as triangles.
        let entries = 8 * surface.len();
        Self {
            boxes: vec![(DVec3::ZERO, DVec3::ZERO, 0.0); surface.len()],
            start: vec![0; (2 * surface.len()).next_power_of_two() + 1],
            entries: vec![0; entries],
            surface,
            best: vec![(f64::INFINITY, f64::NEG_INFINITY, u32::MAX); bodies.len()],
            // A particle has at most one contact per other body; room for four of them.
            contacts: Vec::with_capacity(particles * (bodies.len() - 1).min(MAX_RESERVED)),
        }
    }
}

/// The bucket of grid cell `c` for body `body` in a table of `mask + 1` buckets.
#[inline]
fn bucket(c: [i64; 3], body: u32, mask: usize) -> usize {
    let h = (c[0] as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (c[1] as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ (c[2] as u64).wrapping_mul(0x1656_67B1_9E37_79F9)
        ^ u64::from(body).wrapping_mul(0x27D4_EB2F_1656_67C5);
    (h ^ (h >> 29)) as usize & mask
}

/// The grid's cell coordinates are clamped to `[-CELL_LIMIT, CELL_LIMIT]`: far cells share
/// a bucket (slower, never wrong), and no cell coordinate overflows.
const CELL_LIMIT: f64 = 1e15;

/// The cell of `q` (relative to the grid's origin) for cells of size `size`. Monotone in
/// every coordinate, so that a point inside a box is inside the box's range of cells.
#[inline]
fn cell(q: DVec3, size: f64) -> [i64; 3] {
    let c = (q / size).floor();
    // `as` maps a NaN to 0: a non-finite position lands in some cell, the step's guard reports it.
    [c.x, c.y, c.z].map(|c| c.clamp(-CELL_LIMIT, CELL_LIMIT) as i64)
}

/// The cells from `lo` to `hi`, each once.
fn cells(lo: [i64; 3], hi: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (lo[0]..=hi[0])
        .flat_map(move |x| (lo[1]..=hi[1]).flat_map(move |y| (lo[2]..=hi[2]).map(move |z| [x, y, z])))
}

/// The distance from particle `i` at `q` (relative to the grid's origin) to the surface
/// triangle `t` with box `b` (relative to the same origin), when the triangle is a candidate:
/// `q` inside the box grown by the reach `near + b.2`, not every particle pinned, and the
/// distance below the reach; with it, how well the triangle's face normal matches the direction
/// from the closest point to the particle (the cosine of their angle, its absolute value for an
/// open surface, 1 where the particle is on the triangle, -inf for a triangle of zero area).
/// `p` and `w` are the predicted positions and inverse masses.
#[inline]
#[allow(clippy::too_many_arguments)]
fn reach_distance(
    p: &[DVec3],
    w: &[f64],
    i: usize,
    q: DVec3,
    near: f64,
    t: [u32; 3],
    b: &(DVec3, DVec3, f64),
    closed: bool,
) -> Option<(f64, f64)> {
    let (lo, hi, moved) = *b;
    let reach = near + moved;
    if (q - (lo - reach)).min_element() < 0.0 || ((hi + reach) - q).min_element() < 0.0 {
        return None;
    }
    let t = t.map(|j| j as usize);
    if w[i] == 0.0 && t.iter().all(|&j| w[j] == 0.0) {
        return None;
    }
    let [a, b, c] = t.map(|j| p[j]);
    let (closest, _) = closest_point_on_triangle(p[i], [a, b, c]);
    let d = p[i] - closest;
    let dist = d.length();
    if !(dist < reach) {
        return None;
    }
    let face = (b - a).cross(c - a);
    let area = face.length();
    let fit = if !(area > 0.0) {
        f64::NEG_INFINITY
    } else if dist > 0.0 {
        let cos = d.dot(face) / (dist * area);
        if closed { cos } else { cos.abs() }
    } else {
        1.0
    };
    Some((dist, fit))
}

/// Whether the candidate `(distance, fit)` of [`reach_distance`] beats the best so far `best`:
/// closer by more than `tie` (m), or as close within `tie` and a better fit. Where the closest
/// point is an edge or corner shared by several triangles their distances differ by rounding
/// only, and the one the particle faces best wins: its normal then orients the contact.
#[inline]
fn beats((dist, fit): (f64, f64), best: (f64, f64), tie: f64) -> bool {
    dist < best.0 - tie || (dist <= best.0 + tie && fit > best.1)
}

/// The distance within which two candidate triangles are as close, for a particle of reach
/// `near` (m): far above the rounding of a distance in a scene near the origin, far below any
/// distance that matters.
#[inline]
fn tie(near: f64) -> f64 {
    1e-9 * near
}

/// The contact of particle `i` with triangle `t` of a body that is `closed` or not, at start
/// positions `x` and predicted positions `p`; `None` where the triangle has no normal (zero
/// area) or an open surface's particle started in its plane.
fn pair_contact(x: &[DVec3], p: &[DVec3], i: usize, t: [u32; 3], closed: bool) -> Option<PairContact> {
    let corners = t.map(|j| j as usize);
    let (closest, bary) = closest_point_on_triangle(p[i], corners.map(|j| p[j]));
    let [a, b, c] = corners.map(|j| p[j]);
    let face = (b - a).cross(c - a).try_normalize()?;
    let side = if closed {
        face
    } else {
        let [a0, b0, c0] = corners.map(|j| x[j]);
        let q0 = bary[0] * a0 + bary[1] * b0 + bary[2] * c0;
        let side = (b0 - a0).cross(c0 - a0).dot(x[i] - q0);
        if side > 0.0 {
            face
        } else if side < 0.0 {
            -face
        } else {
            return None;
        }
    };
    // On an edge or a corner the face normal of one of the triangles sharing it could push the
    // particle sideways (a vertex level with a face, beside its edge, is as close to the side
    // face): the normal is then the direction from the closest point to the particle, turned to
    // the side of the face normal; the face normal where the particle is on the edge.
    let d = p[i] - closest;
    let scale = (b - a).length().max((c - a).length()).max((c - b).length());
    let normal = match d.try_normalize() {
        Some(n) if bary.contains(&0.0) && d.length() > 1e-9 * scale => {
            if n.dot(side) < 0.0 {
                -n
            } else {
                n
            }
        }
        _ => side,
    };
    Some(PairContact { particle: i as u32, tri: t, bary, normal, lambda: 0.0 })
}

/// Line (8) for the contact bodies: fills `d.bodies.contacts` for the predicted positions `d.p`
/// with thickness and speculative margin `margin`.
pub(super) fn generate_body_contacts(model: &PbdModel, d: &mut Data, margin: f64) {
    let bc = &mut d.bodies;
    bc.contacts.clear();
    if bc.surface.is_empty() {
        return;
    }
    let (x, p, w) = (&d.x, &d.p, &model.inv_mass);
    let thickness = model.body_contact.thickness;
    let motion = |i: usize| (p[i] - x[i]).length();
    let mut most = 0.0f64;
    for body in &model.contact_bodies {
        for i in body.particles.0..body.particles.1 {
            most = most.max(motion(i));
        }
    }
    // A triangle's box grown by `radius` holds every particle that can touch it: a particle's
    // reach `(thickness + margin + motion) + moved` never exceeds it, rounding included.
    let radius = (thickness + margin + most) + most;
    // The boxes, then relative to the lowest corner of them all: the grid's rounding then
    // depends on the scene's extent, not on its distance from the origin.
    let mut origin = DVec3::INFINITY;
    for (&(t, _), b) in bc.surface.iter().zip(bc.boxes.iter_mut()) {
        let t = t.map(|i| i as usize);
        let [a, b1, c] = t.map(|i| p[i]);
        let moved = motion(t[0]).max(motion(t[1])).max(motion(t[2]));
        *b = (a.min(b1).min(c), a.max(b1).max(c), moved);
        origin = origin.min(b.0);
    }
    let mut size = 0.0f64;
    for b in &mut bc.boxes {
        (b.0, b.1) = (b.0 - origin, b.1 - origin);
        size = size.max((b.1 - b.0).max_element() + 2.0 * radius);
    }
    // A little larger, so that rounding does not spread a box over a third cell.
    let size = size * 1.001;
    if !(size > 0.0 && size.is_finite() && origin.is_finite()) {
        // Non-finite positions: the step's guard reports them.
        return;
    }
    // Counting sort of the triangles into the buckets of the cells their grown boxes overlap.
    let mask = bc.start.len() - 2;
    let grown = |b: &(DVec3, DVec3, f64)| (cell(b.0 - radius, size), cell(b.1 + radius, size));
    bc.start.iter_mut().for_each(|s| *s = 0);
    for (&(_, body), b) in bc.surface.iter().zip(&bc.boxes) {
        let (lo, hi) = grown(b);
        for c in cells(lo, hi) {
            bc.start[bucket(c, body, mask) + 1] += 1;
        }
    }
    for k in 1..bc.start.len() {
        bc.start[k] += bc.start[k - 1];
    }
    let total = bc.start[bc.start.len() - 1] as usize;
    if total > bc.entries.len() {
        // Only when rounding spread boxes over a third cell (a scene some 1e13 cells across).
        bc.entries.resize(total, 0);
    }
    for (k, (&(_, body), b)) in bc.surface.iter().zip(&bc.boxes).enumerate() {
        let (lo, hi) = grown(b);
        for c in cells(lo, hi) {
            let slot = &mut bc.start[bucket(c, body, mask)];
            bc.entries[*slot as usize] = k as u32;
            *slot += 1;
        }
    }
    // The fill moved each bucket's start to the next one's: shift back.
    for k in (1..bc.start.len()).rev() {
        bc.start[k] = bc.start[k - 1];
    }
    bc.start[0] = 0;
    let nb = model.contact_bodies.len() as u32;
    for (body, own) in model.contact_bodies.iter().zip(0u32..) {
        for i in body.particles.0..body.particles.1 {
            let q = p[i] - origin;
            let c = cell(q, size);
            bc.best.iter_mut().for_each(|b| *b = (f64::INFINITY, f64::NEG_INFINITY, u32::MAX));
            let near = thickness + margin + motion(i);
            for other in (0..nb).filter(|&o| o != own) {
                let k = bucket(c, other, mask);
                let closed = model.contact_bodies[other as usize].closed;
                for &e in &bc.entries[bc.start[k] as usize..bc.start[k + 1] as usize] {
                    let (t, from) = bc.surface[e as usize];
                    if from != other {
                        continue;
                    }
                    // Triangles come in increasing order: the first of equally close and fitting
                    // ones wins.
                    let best = &mut bc.best[other as usize];
                    if let Some(found) = reach_distance(p, w, i, q, near, t, &bc.boxes[e as usize], closed)
                        && beats(found, (best.0, best.1), tie(near))
                    {
                        *best = (found.0, found.1, e);
                    }
                }
            }
            for &(_, _, k) in &bc.best {
                if k == u32::MAX {
                    continue;
                }
                let (t, other) = bc.surface[k as usize];
                let closed = model.contact_bodies[other as usize].closed;
                if let Some(contact) = pair_contact(x, p, i, t, closed) {
                    bc.contacts.push(contact);
                }
            }
        }
    }
}

/// One iteration over the body contacts, in order: each projected (rigid inequality) with
/// positional friction, the corrections applied at once.
pub(super) fn project_body_contacts(
    ctx: &Ctx<'_>,
    model: &PbdModel,
    contacts: &mut [PairContact],
    p: &mut [DVec3],
) {
    let (mu_s, mu_k) = (model.body_contact.static_friction, model.body_contact.kinetic_friction);
    let thickness = model.body_contact.thickness;
    for c in contacts {
        let i = c.particle as usize;
        let t = c.tri.map(|j| j as usize);
        let wt = t.map(|j| ctx.w[j]);
        let denom =
            ctx.w[i] + c.bary[0].powi(2) * wt[0] + c.bary[1].powi(2) * wt[1] + c.bary[2].powi(2) * wt[2];
        if !(denom > 0.0) {
            continue;
        }
        let q = c.bary[0] * p[t[0]] + c.bary[1] * p[t[1]] + c.bary[2] * p[t[2]];
        let value = c.normal.dot(p[i] - q) - thickness;
        // The correction of the gap along the normal (m).
        let dn = contact_correction(ctx.xpbd, value, denom, &mut c.lambda);
        if dn == 0.0 {
            continue;
        }
        // The relative correction `r` of the particle against the surface point is shared as
        // `w_i r / D` and `-w_k b_k r / D`, which moves the gap by exactly `r`.
        let mut r = c.normal * dn;
        r -= positional_friction(c.normal, dn, mu_s, mu_k, || {
            let moved = |j: usize| p[j] - ctx.x[j];
            moved(i) + r - (c.bary[0] * moved(t[0]) + c.bary[1] * moved(t[1]) + c.bary[2] * moved(t[2]))
        });
        let scale = r / denom;
        if !scale.is_finite() {
            ctx.flag(CONTACT_ID);
            continue;
        }
        p[i] += ctx.w[i] * scale;
        for k in 0..3 {
            p[t[k]] -= wt[k] * c.bary[k] * scale;
        }
    }
}

#[cfg(test)]
mod tests;
