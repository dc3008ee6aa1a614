//! Constraint projection: the kernels behind line (10) of the PBD loop, `projectConstraints`, for
//! PBD (Müller et al. 2007) and XPBD (Macklin et al. 2016, equations 17 and 18), shared by the three
//! solvers.
//!
//! # One projection
//!
//! For a constraint `C` of cardinality `n` with gradient `g_k = grad_{p_k} C` and inverse masses
//! `w_k`, let `D = sum_k w_k |g_k|^2`.
//!
//! - **PBD** (the mass-weighted step): `dp_k = -k' C / D w_k g_k`, with the stiffness
//!   correction `k' = 1 - (1 - k)^(1/n_s)` of Müller et al. 2007 (section 3.3) over `n_s` solver
//!   iterations, so that a single constraint keeps the fraction `(1 - k)` of its error after the
//!   iterations whatever `n_s` is. An inequality is projected only while `C < 0`.
//! - **XPBD**: with `alpha~ = alpha / h^2` and the multiplier `lambda` accumulated over
//!   the iterations of the (sub)step (reset to 0 at its start, line 4 of the XPBD loop),
//!
//!   ```text
//!   dlambda = (-C - alpha~ lambda - gamma g . (p - x^n)) / ((1 + gamma) D + alpha~)     (eq. 18)
//!   dp_k    = w_k g_k dlambda,   lambda <- lambda + dlambda                            (eq. 17)
//!   ```
//!
//!   with Macklin et al. 2016's constraint damping `gamma = alpha~ beta h = alpha beta / h`
//!   (eq. 26, `beta` the damping coefficient; `beta = 0` gives eq. 18 exactly). An inequality keeps `lambda >= 0`: `dlambda = max(dlambda, -lambda)`.
//!
//! A projection whose gradient is undefined (degenerate stencil) or whose `D` is zero (every
//! particle pinned) or negligible against its rest value (`D < 1e-12 D_rest`: a tetrahedron
//! collapsed to a line) is skipped. A non-finite `dlambda` is skipped and the constraint recorded,
//! so the step fails with an error naming it.
//!
//! # Direct and buffered projection
//!
//! A kernel computes the correction `dp_k` of each of its particles by one fixed expression and
//! hands it to an [`Access`]: [`Direct`] adds it to the positions at once (sequential sweeps),
//! [`Buffered`] stores it (parallel sweeps, applied afterwards by the caller in a fixed order).
//! Constraints of one colour share no movable particle, so within a colour both give bitwise the
//! same positions, whatever the number of threads.

use crate::angle::atan2;
use crate::collide::{Collider, Contact, MeshCollider, Pose, coefficients};
use crate::constraint::{
    AttachTarget, Constraint, ConstraintFunction, ConstraintType, MIN_LENGTH, dihedral, dihedral_parts,
    distance, isometric, tet_volume, wrap_angle,
};
use crate::model::{PbdModel, VolumeMesh};
use anim_core::glam::DVec3;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// An attachment target in compiled form.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Target {
    Point(DVec3),
    Body { body: u32, local: DVec3 },
}

/// A constraint function with its indices, in the form the kernels read.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Kernel {
    Distance {
        p: [u32; 2],
        rest: f64,
        fallback: DVec3,
    },
    /// `cos_rest`, `sin_rest`: the rest angle's cosine and sine, precomputed.
    Dihedral {
        p: [u32; 4],
        rest: f64,
        cos_rest: f64,
        sin_rest: f64,
    },
    Isometric {
        p: [u32; 4],
        w: [f64; 4],
        rest: f64,
    },
    Tet {
        p: [u32; 4],
        rest: f64,
    },
    Volume {
        mesh: u32,
        target: f64,
    },
    Attach {
        p: u32,
        target: Target,
        distance: f64,
    },
}

/// A constraint ready for projection.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Compiled {
    pub kernel: Kernel,
    /// Index in the model.
    pub id: u32,
    /// PBD stiffness per iteration `k'` (or `k` without the correction).
    pub k: f64,
    /// XPBD compliance.
    pub alpha: f64,
    /// XPBD damping.
    pub beta: f64,
    pub inequality: bool,
    /// Skip when `D` falls below this (degenerate configuration).
    pub den_min: f64,
    /// Jacobi under-relaxation `omega / n_j` (1 for Gauss-Seidel).
    pub relax: f64,
}

/// Per-substep constants and read-only data the kernels share.
pub(crate) struct Ctx<'a> {
    pub w: &'a [f64],
    /// Positions at the start of the substep (`x^n`).
    pub x: &'a [DVec3],
    pub xpbd: bool,
    pub h: f64,
    pub inv_h2: f64,
    /// Body poses at the end of the substep.
    pub poses: &'a [Pose],
    pub meshes: &'a [VolumeMesh],
    pub scratch: &'a [Mutex<Vec<DVec3>>],
    pub colliders: &'a [Collider],
    pub mesh_colliders: &'a [MeshCollider],
    /// Smallest model index of a constraint whose update was not finite (`usize::MAX`: none).
    pub bad: &'a AtomicUsize,
}

impl Ctx<'_> {
    #[cold]
    pub(crate) fn flag(&self, id: u32) {
        self.bad.fetch_min(id as usize, Relaxed);
    }

    #[inline]
    fn target(&self, t: &Target) -> DVec3 {
        match *t {
            Target::Point(p) => p,
            Target::Body { body, local } => self.poses[body as usize].apply(local),
        }
    }
}

/// Where a projection reads positions and puts its corrections (see the module docs).
pub(crate) trait Access {
    /// Whether corrections go straight into the positions.
    const DIRECT: bool;
    /// Position of particle `i`.
    fn get(&self, i: usize) -> DVec3;
    /// Correction `dx` of particle `i`, the `slot`-th of the constraint.
    fn apply(&mut self, slot: usize, i: usize, dx: DVec3);
}

/// Sequential sweeps: apply at once.
pub(crate) struct Direct<'a>(pub &'a mut [DVec3]);

impl Access for Direct<'_> {
    const DIRECT: bool = true;
    #[inline(always)]
    fn get(&self, i: usize) -> DVec3 {
        self.0[i]
    }
    #[inline(always)]
    fn apply(&mut self, _slot: usize, i: usize, dx: DVec3) {
        self.0[i] += dx;
    }
}

/// Parallel sweeps: read shared positions, write the constraint's four slots.
pub(crate) struct Buffered<'a> {
    pub pos: &'a [DVec3],
    pub out: &'a mut [DVec3; 4],
}

impl Access for Buffered<'_> {
    const DIRECT: bool = false;
    #[inline(always)]
    fn get(&self, i: usize) -> DVec3 {
        self.pos[i]
    }
    #[inline(always)]
    fn apply(&mut self, slot: usize, _i: usize, dx: DVec3) {
        self.out[slot] = dx;
    }
}

/// The shared scalar update (module docs) for a constraint of `N <= 4` particles.
#[inline(always)]
fn solve<const N: usize>(
    ctx: &Ctx<'_>,
    c: &Compiled,
    idx: [usize; N],
    p: [DVec3; N],
    value: f64,
    grad: [DVec3; N],
    lambda: &mut f64,
    acc: &mut impl Access,
) {
    let mut w = [0.0; N];
    let mut den = 0.0;
    for k in 0..N {
        w[k] = ctx.w[idx[k]];
        den += w[k] * grad[k].length_squared();
    }
    if !(den > c.den_min) {
        return;
    }
    let scale = if ctx.xpbd {
        let at = c.alpha * ctx.inv_h2;
        let mut num = -value - at * *lambda;
        if c.beta > 0.0 {
            let gamma = at * c.beta * ctx.h;
            let mut gv = 0.0;
            for k in 0..N {
                gv += grad[k].dot(p[k] - ctx.x[idx[k]]);
            }
            num -= gamma * gv;
            den *= 1.0 + gamma;
        }
        let mut dl = num / (den + at);
        if c.inequality {
            dl = dl.max(-*lambda);
        }
        dl *= c.relax;
        if !dl.is_finite() {
            ctx.flag(c.id);
            return;
        }
        *lambda += dl;
        dl
    } else {
        if c.inequality && value >= 0.0 {
            return;
        }
        let s = -value / den * c.k * c.relax;
        if !s.is_finite() {
            ctx.flag(c.id);
            return;
        }
        s
    };
    for k in 0..N {
        if w[k] > 0.0 {
            acc.apply(k, idx[k], grad[k] * (w[k] * scale));
        }
    }
}

/// Projects one constraint. With a [`Buffered`] access a global volume leaves its corrections in
/// its mesh's scratch.
#[inline]
pub(crate) fn project<A: Access>(ctx: &Ctx<'_>, c: &Compiled, lambda: &mut f64, acc: &mut A) {
    let z = DVec3::ZERO;
    match c.kernel {
        Kernel::Distance { p: [i, j], rest, fallback } => {
            let (i, j) = (i as usize, j as usize);
            let (a, b) = (acc.get(i), acc.get(j));
            if c.beta == 0.0 && !c.inequality && ctx.xpbd && c.relax == 1.0 {
                // The common case written out: XPBD equality without damping (same arithmetic for
                // every access, so direct and buffered sweeps agree bitwise).
                let d = a - b;
                let len2 = d.length_squared();
                let (wi, wj) = (ctx.w[i], ctx.w[j]);
                let at = c.alpha * ctx.inv_h2;
                let den = wi + wj + at;
                if len2 > MIN_LENGTH * MIN_LENGTH && den > 0.0 {
                    let len = len2.sqrt();
                    let dl = (rest - len - at * *lambda) / den;
                    if !dl.is_finite() {
                        ctx.flag(c.id);
                        return;
                    }
                    *lambda += dl;
                    let step = d * (dl / len);
                    if wi > 0.0 {
                        acc.apply(0, i, step * wi);
                    }
                    if wj > 0.0 {
                        acc.apply(1, j, -(step * wj));
                    }
                    return;
                }
            }
            let (value, n) = distance(a, b, rest, fallback);
            solve(ctx, c, [i, j], [a, b], value, [n, -n], lambda, acc);
        }
        Kernel::Dihedral { p, rest, cos_rest, sin_rest } => {
            let idx = p.map(|i| i as usize);
            let x = idx.map(|i| acc.get(i));
            if c.beta == 0.0 && !c.inequality && ctx.xpbd && c.relax == 1.0 {
                // The common case written out: the gradient computed once, `theta - theta_0` as
                // one angle from the rotated sine and cosine (no wrap), the update of `solve`.
                let Some((s, co, g)) = dihedral_parts(x) else { return };
                let value = atan2(s * cos_rest - co * sin_rest, co * cos_rest + s * sin_rest);
                let m = idx.map(|i| ctx.w[i]);
                let den = m[0] * g[0].length_squared()
                    + m[1] * g[1].length_squared()
                    + m[2] * g[2].length_squared()
                    + m[3] * g[3].length_squared();
                if !(den > c.den_min) {
                    return;
                }
                let at = c.alpha * ctx.inv_h2;
                let dl = (-value - at * *lambda) / (den + at);
                if !dl.is_finite() {
                    ctx.flag(c.id);
                    return;
                }
                *lambda += dl;
                for k in 0..4 {
                    if m[k] > 0.0 {
                        acc.apply(k, idx[k], g[k] * (m[k] * dl));
                    }
                }
                return;
            }
            if let Some((theta, g)) = dihedral(x) {
                solve(ctx, c, idx, x, wrap_angle(theta - rest), g, lambda, acc);
            }
        }
        Kernel::Isometric { p, w, rest } => {
            let idx = p.map(|i| i as usize);
            let x = idx.map(|i| acc.get(i));
            if c.beta == 0.0 && !c.inequality && ctx.xpbd && c.relax == 1.0 {
                // The common case written out (|grad_k C| = |w_k|): same arithmetic for every access.
                let v = w[0] * x[0] + w[1] * x[1] + w[2] * x[2] + w[3] * x[3];
                let len2 = v.length_squared();
                let m = idx.map(|i| ctx.w[i]);
                let at = c.alpha * ctx.inv_h2;
                let den =
                    m[0] * w[0] * w[0] + m[1] * w[1] * w[1] + m[2] * w[2] * w[2] + m[3] * w[3] * w[3] + at;
                if len2 > MIN_LENGTH * MIN_LENGTH && den > 0.0 {
                    let len = len2.sqrt();
                    let dl = (rest - len - at * *lambda) / den;
                    if !dl.is_finite() {
                        ctx.flag(c.id);
                        return;
                    }
                    *lambda += dl;
                    let step = v * (dl / len);
                    for k in 0..4 {
                        if m[k] > 0.0 {
                            acc.apply(k, idx[k], step * (w[k] * m[k]));
                        }
                    }
                }
                return;
            }
            if let Some((value, g)) = isometric(x, w, rest) {
                solve(ctx, c, idx, x, value, g, lambda, acc);
            }
        }
        Kernel::Tet { p, rest } => {
            let idx = p.map(|i| i as usize);
            let x = idx.map(|i| acc.get(i));
            let (v, g) = tet_volume(x);
            solve(ctx, c, idx, x, v - rest, g, lambda, acc);
        }
        Kernel::Attach { p, target, distance: d } => {
            let i = p as usize;
            let a = acc.get(i);
            let t = ctx.target(&target);
            if (a - t).length() > crate::constraint::MIN_LENGTH {
                let (value, n) = distance(a, t, d, z);
                solve(ctx, c, [i], [a], value, [n], lambda, acc);
            }
        }
        Kernel::Volume { mesh, target } => project_volume(ctx, c, mesh as usize, target, lambda, acc),
    }
}

/// The global volume constraint: gradient into the mesh's scratch, then either applied
/// (Gauss-Seidel) or left in the scratch as corrections (Jacobi).
fn project_volume<A: Access>(
    ctx: &Ctx<'_>,
    c: &Compiled,
    mesh: usize,
    target: f64,
    lambda: &mut f64,
    acc: &mut A,
) {
    let buffered = !A::DIRECT;
    let m = &ctx.meshes[mesh];
    let mut g = ctx.scratch[mesh].lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let value = m.gradient(|i| acc.get(i), &mut g) - target;
    let mut den = 0.0;
    for (k, &i) in m.vertices.iter().enumerate() {
        den += ctx.w[i] * g[k].length_squared();
    }
    let clear = |g: &mut Vec<DVec3>| {
        if buffered {
            g.iter_mut().for_each(|d| *d = DVec3::ZERO);
        }
    };
    if !(den > c.den_min) {
        clear(&mut g);
        return;
    }
    let scale = if ctx.xpbd {
        let at = c.alpha * ctx.inv_h2;
        let mut num = -value - at * *lambda;
        let mut den = den;
        if c.beta > 0.0 {
            let gamma = at * c.beta * ctx.h;
            let gv: f64 = m.vertices.iter().enumerate().map(|(k, &i)| g[k].dot(acc.get(i) - ctx.x[i])).sum();
            num -= gamma * gv;
            den *= 1.0 + gamma;
        }
        let mut dl = num / (den + at);
        if c.inequality {
            dl = dl.max(-*lambda);
        }
        dl *= c.relax;
        if !dl.is_finite() {
            ctx.flag(c.id);
            clear(&mut g);
            return;
        }
        *lambda += dl;
        dl
    } else {
        if c.inequality && value >= 0.0 {
            clear(&mut g);
            return;
        }
        let s = -value / den * c.k * c.relax;
        if !s.is_finite() {
            ctx.flag(c.id);
            clear(&mut g);
            return;
        }
        s
    };
    for (k, &i) in m.vertices.iter().enumerate() {
        let dx = g[k] * (ctx.w[i] * scale);
        if buffered {
            g[k] = dx;
        } else if ctx.w[i] > 0.0 {
            acc.apply(k, i, dx);
        }
    }
}

/// The correction along the normal of a rigid contact (an inequality) whose gap is `value` and
/// whose inverse masses along the normal sum to `w`, accumulating the multiplier `lambda`: XPBD
/// with zero compliance (`dlambda = -C / w`, kept `>= -lambda`, the correction `w dlambda`), or
/// PBD's projection of a negative gap.
#[inline]
pub(crate) fn contact_correction(xpbd: bool, value: f64, w: f64, lambda: &mut f64) -> f64 {
    if xpbd {
        let dl = (-value / w).max(-*lambda);
        *lambda += dl;
        w * dl
    } else if value < 0.0 {
        *lambda += -value;
        -value
    } else {
        0.0
    }
}

/// Projects a contact (always rigid, an inequality) with positional friction (see
/// [`collide`](crate::collide)); returns the correction of its particle.
#[inline]
pub(crate) fn project_contact(ctx: &Ctx<'_>, c: &mut Contact, p: DVec3) -> DVec3 {
    let i = c.particle as usize;
    let w = ctx.w[i];
    let value = c.normal.dot(p) - c.offset;
    let dn = contact_correction(ctx.xpbd, value, w, &mut c.lambda);
    if dn == 0.0 {
        return DVec3::ZERO;
    }
    let mut dx = c.normal * dn;
    let (mu_s, mu_k, _) = coefficients(ctx.colliders, ctx.mesh_colliders, c.collider as usize);
    dx -= positional_friction(c.normal, dn, mu_s, mu_k, || p + dx - ctx.x[i] - c.obstacle_dx);
    if !dx.is_finite() {
        ctx.flag(CONTACT_ID);
        return DVec3::ZERO;
    }
    dx
}

/// Positional friction (Macklin et al. 2014, eq. 24; see [`collide`](crate::collide)) after a
/// contact's normal correction `dn` along `normal`: the part of the tangential motion to remove,
/// all of it when it is below `mu_s dn` (static), else `min(mu_k dn, |dx_t|)` of it (kinetic);
/// `rel` is the motion over the substep relative to the other side, the correction included.
/// Zero unless `dn > 0` and a coefficient is.
#[inline]
pub(crate) fn positional_friction(
    normal: DVec3,
    dn: f64,
    mu_s: f64,
    mu_k: f64,
    rel: impl FnOnce() -> DVec3,
) -> DVec3 {
    if !(dn > 0.0 && (mu_s > 0.0 || mu_k > 0.0)) {
        return DVec3::ZERO;
    }
    let rel = rel();
    let t = rel - normal * rel.dot(normal);
    let tl = t.length();
    if !(tl > 0.0) {
        DVec3::ZERO
    } else if tl < mu_s * dn {
        t
    } else {
        t * (mu_k * dn / tl).min(1.0)
    }
}

/// The id [`Ctx`] records for a contact whose update was not finite.
pub(crate) const CONTACT_ID: u32 = u32::MAX - 1;

/// The value of a compiled constraint at positions `get` (for reports and the divergence guard).
pub(crate) fn value(
    c: &Compiled,
    get: impl Fn(usize) -> DVec3,
    poses: &[Pose],
    meshes: &[VolumeMesh],
) -> f64 {
    match c.kernel {
        Kernel::Distance { p: [i, j], rest, .. } => (get(i as usize) - get(j as usize)).length() - rest,
        Kernel::Dihedral { p, rest, .. } => {
            dihedral(p.map(|i| get(i as usize))).map_or(0.0, |(t, _)| wrap_angle(t - rest))
        }
        Kernel::Isometric { p, w, rest } => {
            let x = p.map(|i| get(i as usize));
            (w[0] * x[0] + w[1] * x[1] + w[2] * x[2] + w[3] * x[3]).length() - rest
        }
        Kernel::Tet { p, rest } => tet_volume(p.map(|i| get(i as usize))).0 - rest,
        Kernel::Volume { mesh, target } => {
            let m = &meshes[mesh as usize];
            let mut v = 0.0;
            for t in &m.triangles {
                let [a, b, cc] = t.map(|k| get(m.vertices[k as usize]));
                v += a.dot(b.cross(cc));
            }
            v / 6.0 - target
        }
        Kernel::Attach { p, target, distance: d } => {
            let t = match target {
                Target::Point(q) => q,
                Target::Body { body, local } => poses[body as usize].apply(local),
            };
            (get(p as usize) - t).length() - d
        }
    }
}

/// Compiles model constraint `j` for `iterations` solver iterations per (sub)step.
pub(crate) fn compile(model: &PbdModel, j: usize, iterations: usize, correct_stiffness: bool) -> Compiled {
    let c: &Constraint = &model.constraints[j];
    let pos = |i: usize| DVec3::from_array(model.positions[i]);
    let w = &model.inv_mass;
    let u = |i: usize| i as u32;
    let mut den_rest = 0.0;
    let kernel = match &c.function {
        ConstraintFunction::Distance { particles: [i, k], rest_length } => {
            let d = pos(*i) - pos(*k);
            let fallback = if d.length() > crate::constraint::MIN_LENGTH { d.normalize() } else { DVec3::X };
            Kernel::Distance { p: [u(*i), u(*k)], rest: *rest_length, fallback }
        }
        ConstraintFunction::DihedralBending { particles, rest_angle } => {
            let (sin_rest, cos_rest) = rest_angle.sin_cos();
            Kernel::Dihedral { p: particles.map(u), rest: *rest_angle, cos_rest, sin_rest }
        }
        ConstraintFunction::IsometricBending(b) => {
            Kernel::Isometric { p: b.particles.map(u), w: b.weights, rest: b.rest }
        }
        ConstraintFunction::TetVolume { particles, rest_volume } => {
            let (_, g) = tet_volume(particles.map(pos));
            den_rest = particles.iter().zip(g).map(|(&i, g)| w[i] * g.length_squared()).sum();
            Kernel::Tet { p: particles.map(u), rest: *rest_volume }
        }
        ConstraintFunction::GlobalVolume { mesh, rest_volume, pressure } => {
            let m = &model.volume_meshes[*mesh];
            let mut g = vec![DVec3::ZERO; m.vertices.len()];
            m.gradient(pos, &mut g);
            den_rest = m.vertices.iter().zip(&g).map(|(&i, g)| w[i] * g.length_squared()).sum();
            Kernel::Volume { mesh: *mesh as u32, target: pressure * rest_volume }
        }
        ConstraintFunction::Attachment { particle, target, distance } => {
            let target = match *target {
                AttachTarget::Point(p) => Target::Point(DVec3::from_array(p)),
                AttachTarget::Body { body, local } => {
                    Target::Body { body: body as u32, local: DVec3::from_array(local) }
                }
            };
            Kernel::Attach { p: u(*particle), target, distance: *distance }
        }
    };
    let k = c.params.stiffness;
    let k =
        if correct_stiffness && k < 1.0 { 1.0 - (1.0 - k).powf(1.0 / iterations.max(1) as f64) } else { k };
    Compiled {
        kernel,
        id: j as u32,
        k,
        alpha: c.params.compliance,
        beta: c.params.damping,
        inequality: c.params.kind == ConstraintType::Inequality,
        den_min: 1e-12 * den_rest,
        relax: 1.0,
    }
}

/// Greedy graph colouring of the model's constraints in their order: two constraints that share
/// a movable particle (`w > 0`) get different colours. Returns the colour of each constraint and
/// the number of colours. Deterministic; computed once.
pub(crate) fn colour(model: &PbdModel) -> (Vec<u32>, usize) {
    let n = model.num_particles();
    let mut used: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut colours = Vec::with_capacity(model.constraints.len());
    let mut taken: Vec<bool> = Vec::new();
    let mut ncol = 0usize;
    for j in 0..model.constraints.len() {
        let parts = model.constraint_particles(j);
        taken.iter_mut().for_each(|t| *t = false);
        for &p in parts {
            if model.inv_mass[p] > 0.0 {
                for &c in &used[p] {
                    taken[c as usize] = true;
                }
            }
        }
        let c = taken.iter().position(|t| !t).unwrap_or(taken.len());
        if c == taken.len() {
            taken.push(false);
            ncol = taken.len();
        }
        for &p in parts {
            if model.inv_mass[p] > 0.0 {
                used[p].push(c as u32);
            }
        }
        colours.push(c as u32);
    }
    (colours, ncol)
}
