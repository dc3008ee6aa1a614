//! Lines (9)-(11) of the loop: `solverIterations` times, `projectConstraints(C_1 .. C_{M+M_coll},
//! p)`, with the multipliers `lambda` reset to 0 at the start of the substep (XPBD, line 4 of its
//! algorithm). Each projection is one kernel of [`crate::project`]; what differs between the three
//! solvers is the order of the projections and which positions they read.
//!
//! - [`SolverKind::GaussSeidel`]: the sequential sweep of Müller et al. 2007, constraints in model order, then
//!   the contacts. Fastest convergence per iteration; one thread.
//! - [`SolverKind::ColoredGaussSeidel`]: the constraints are coloured once (greedy, in model
//!   order) so that no two of a colour share a movable particle; colours are swept in order, the
//!   constraints of a colour independently. It is Gauss-Seidel in another order: the same
//!   convergence, and faster than the model order on one thread, because consecutive
//!   projections no longer wait for each other's results. A colour of at least
//!   [`COLOUR_PARALLEL_MIN`] constraints per thread is swept in parallel, in two phases
//!   (corrections from the colour's start positions, then applied over disjoint particle ranges);
//!   on the 2-core machine this was measured slower than the sequential sweep at every cloth size
//!   tried, hence the threshold.
//! - [`SolverKind::Jacobi`]: every constraint is projected from the same positions (in parallel),
//!   its correction and multiplier increment scaled by `omega / n_j`, `n_j` the largest number of
//!   constraints meeting at one of its movable particles, and each particle adds its corrections
//!   in a fixed order (Jacobi with averaging, Macklin et al. 2014, eq. 11, in a form that keeps
//!   XPBD's `x` and `lambda` consistent). Slowest convergence; kept for comparison and for
//!   hardware without fast sequential sweeps.
//!
//! In the coloured and Jacobi sweeps the contacts form a second group, projected collider by
//! collider after the internal constraints in every iteration. Whatever the solver, the contacts
//! between bodies come last in each iteration, sequentially (`sim/body_contacts.rs`). Every parallel loop writes
//! disjoint data and every sum runs in one fixed order, so the positions are bitwise the same
//! for any number of threads.

use super::body_contacts::project_body_contacts;
use super::parallel::{CHUNK, PARALLEL_MIN, for_each_chunk};
use super::params::{Method, PbdParams, SolverKind};
use super::scratch::Data;
use crate::collide::Contact;
use crate::constraint::ConstraintFunction;
use crate::model::PbdModel;
use crate::project::{Buffered, Compiled, Ctx, Direct, Kernel, colour, compile, project, project_contact};
use anim_core::glam::DVec3;
use anim_core::par::prelude::*;
use std::ops::Range;

/// A colour is swept in parallel (two phases) only with at least this many constraints per
/// thread. Measured on the 2-core development machine, the two-phase sweep on 2 threads was
/// slower than the sequential colour-order sweep at every size tried (benchmark cloth 100^2,
/// 200^2, 300^2: 4.7 vs 3.0, 24 vs 13, 82 vs 35 ms per step): the corrections' second pass
/// costs more than the second core gains. Unit tests use a small value to exercise the path.
const COLOUR_PARALLEL_MIN: usize = if cfg!(test) { 64 } else { 1 << 16 };

/// (Re)builds the compiled constraints, the sweep order and the colouring for the settings `p`.
pub(super) fn plan_sweeps(model: &PbdModel, p: &PbdParams, data: &mut Data) {
    let m = model.constraints.len();
    let mut compiled: Vec<Compiled> =
        (0..m).map(|j| compile(model, j, p.iterations, p.stiffness_correction)).collect();
    let mut groups = Vec::new();
    match p.solver {
        SolverKind::GaussSeidel | SolverKind::Jacobi => groups.push(0..m),
        SolverKind::ColoredGaussSeidel => {
            let (colours, ncol) = colour(model);
            let mut order: Vec<usize> = (0..m).collect();
            order.sort_by_key(|&j| (colours[j], j));
            compiled = order.iter().map(|&j| compiled[j]).collect();
            let mut start = 0;
            for c in 0..ncol as u32 {
                let len = colours.iter().filter(|&&k| k == c).count();
                groups.push(start..start + len);
                start += len;
            }
        }
    }
    if p.solver == SolverKind::Jacobi {
        // n_i: constraints at particle i; n_j: the largest n_i over j's movable particles.
        for c in compiled.iter_mut() {
            let j = c.id as usize;
            let n_j = model
                .constraint_particles(j)
                .iter()
                .filter(|&&i| model.inv_mass[i] > 0.0)
                .map(|&i| model.inc_ptr[i + 1] - model.inc_ptr[i])
                .max()
                .unwrap_or(1)
                .max(1);
            c.relax = p.jacobi_relaxation / n_j as f64;
        }
    }
    let buffered = p.solver != SolverKind::GaussSeidel;
    data.corr = if buffered { vec![[DVec3::ZERO; 4]; m] } else { Vec::new() };
    let is_volume = |c: &Compiled| matches!(c.kernel, Kernel::Volume { .. });
    data.group_has_volume = groups.iter().map(|r| compiled[r.clone()].iter().any(is_volume)).collect();
    data.touched = if p.solver == SolverKind::ColoredGaussSeidel {
        groups
            .iter()
            .map(|r| {
                let mut t: Vec<(u32, u32, u32)> = Vec::new();
                for ci in r.clone() {
                    let j = compiled[ci].id as usize;
                    for (slot, &i) in model.constraint_particles(j).iter().enumerate() {
                        if model.inv_mass[i] > 0.0 {
                            t.push((i as u32, ci as u32, slot as u32));
                        }
                    }
                }
                t.sort_unstable();
                t
            })
            .collect()
    } else {
        Vec::new()
    };
    data.lambda = vec![0.0; m];
    data.compiled = compiled;
    data.groups = groups;
}

/// Lines (9)-(11) for a substep of length `h`: resets the multipliers, then runs the settings'
/// iterations of their sweep over the constraints and the contacts, moving `d.p`.
pub(super) fn solve_constraints(model: &PbdModel, params: &PbdParams, d: &mut Data, h: f64) {
    d.lambda.iter_mut().for_each(|l| *l = 0.0);
    let xpbd = params.method == Method::Xpbd;
    let ctx = Ctx {
        w: &model.inv_mass,
        x: &d.x,
        xpbd,
        h,
        inv_h2: 1.0 / (h * h),
        poses: &d.pose_sub,
        meshes: &model.volume_meshes,
        scratch: &d.scratch,
        colliders: &model.colliders,
        mesh_colliders: &model.mesh_colliders,
        bad: &d.bad,
    };
    let parallel = anim_core::par::current_num_threads() > 1;
    for _ in 0..params.iterations {
        match params.solver {
            SolverKind::GaussSeidel => {
                gauss_seidel(&ctx, &d.compiled, &mut d.lambda, &mut d.p, &mut d.contacts)
            }
            SolverKind::ColoredGaussSeidel => coloured_gauss_seidel(
                &ctx,
                parallel,
                &d.groups,
                &d.group_has_volume,
                &d.touched,
                &d.compiled,
                &mut d.lambda,
                &mut d.corr,
                &mut d.p,
                &mut d.contacts,
                &d.contact_groups,
            ),
            SolverKind::Jacobi => jacobi(
                &ctx,
                parallel,
                model,
                &d.compiled,
                &mut d.lambda,
                &mut d.corr,
                &mut d.volume_corr,
                &mut d.p,
                &mut d.contacts,
                &d.contact_groups,
            ),
        }
        project_body_contacts(&ctx, model, &mut d.bodies.contacts, &mut d.p);
    }
}

/// One sequential Gauss-Seidel iteration: the constraints in model order, then the contacts in
/// the order they were generated.
fn gauss_seidel(
    ctx: &Ctx<'_>,
    compiled: &[Compiled],
    lambda: &mut [f64],
    p: &mut [DVec3],
    contacts: &mut [Contact],
) {
    let mut acc = Direct(&mut *p);
    for (c, l) in compiled.iter().zip(lambda.iter_mut()) {
        project(ctx, c, l, &mut acc);
    }
    for c in contacts.iter_mut() {
        let dx = project_contact(ctx, c, p[c.particle as usize]);
        p[c.particle as usize] += dx;
    }
}

/// One coloured Gauss-Seidel iteration: the colours `groups` of `compiled` in order (each in
/// parallel when it is large enough and holds no global volume), then the contacts collider by
/// collider.
fn coloured_gauss_seidel(
    ctx: &Ctx<'_>,
    parallel: bool,
    groups: &[Range<usize>],
    group_has_volume: &[bool],
    touched: &[Vec<(u32, u32, u32)>],
    compiled: &[Compiled],
    lambda: &mut [f64],
    corr: &mut [[DVec3; 4]],
    p: &mut [DVec3],
    contacts: &mut [Contact],
    contact_groups: &[Range<usize>],
) {
    for (g, r) in groups.iter().enumerate() {
        let cs = &compiled[r.clone()];
        let ls = &mut lambda[r.clone()];
        let threads = anim_core::par::current_num_threads();
        if parallel && cs.len() >= COLOUR_PARALLEL_MIN * threads && !group_has_volume[g] {
            // Two phases: corrections from the colour's start positions, then
            // applied over disjoint particle ranges.
            let pos: &[DVec3] = p;
            let colour_corr = &mut corr[r.clone()];
            let chunk = cs.len().div_ceil(2 * anim_core::par::current_num_threads()).max(CHUNK);
            cs.par_chunks(chunk)
                .zip(ls.par_chunks_mut(chunk))
                .zip(colour_corr.par_chunks_mut(chunk))
                .for_each(|((cs, ls), out)| {
                    for ((c, l), o) in cs.iter().zip(ls.iter_mut()).zip(out.iter_mut()) {
                        *o = [DVec3::ZERO; 4];
                        project(ctx, c, l, &mut Buffered { pos, out: o });
                    }
                });
            let t = &touched[g];
            let leaf = t.len().div_ceil(2 * anim_core::par::current_num_threads()).max(4 * CHUNK);
            apply_sorted(p, 0, t, corr, leaf);
        } else {
            let mut acc = Direct(&mut *p);
            for (c, l) in cs.iter().zip(ls.iter_mut()) {
                project(ctx, c, l, &mut acc);
            }
        }
    }
    project_contact_groups(ctx, contacts, contact_groups, p, parallel);
}

/// One Jacobi iteration with averaging: every constraint projected from the same positions into
/// its buffered correction, the corrections gathered per particle in the fixed incidence order,
/// then the contacts collider by collider.
fn jacobi(
    ctx: &Ctx<'_>,
    parallel: bool,
    model: &PbdModel,
    compiled: &[Compiled],
    lambda: &mut [f64],
    corr: &mut [[DVec3; 4]],
    volume_corr: &mut [Vec<DVec3>],
    p: &mut [DVec3],
    contacts: &mut [Contact],
    contact_groups: &[Range<usize>],
) {
    let w = ctx.w;
    let pos: &[DVec3] = p;
    let work = |(c, (l, o)): (&Compiled, (&mut f64, &mut [DVec3; 4]))| {
        *o = [DVec3::ZERO; 4];
        project(ctx, c, l, &mut Buffered { pos, out: o });
    };
    let cs = compiled;
    if parallel && cs.len() >= PARALLEL_MIN {
        cs.par_iter().zip(lambda.par_iter_mut().zip(corr.par_iter_mut())).with_min_len(CHUNK).for_each(work);
    } else {
        cs.iter().zip(lambda.iter_mut().zip(corr.iter_mut())).for_each(work);
    }
    for (m, out) in ctx.scratch.iter().zip(volume_corr.iter_mut()) {
        out.copy_from_slice(&m.lock().unwrap_or_else(std::sync::PoisonError::into_inner));
    }
    // Gather per particle in the fixed incidence order.
    let (corr, vcorr) = (&*corr, &*volume_corr);
    let gather = |i: usize| -> DVec3 {
        let mut s = DVec3::ZERO;
        for &(c, slot) in &model.inc[model.inc_ptr[i]..model.inc_ptr[i + 1]] {
            s += match model.constraints[c as usize].function {
                ConstraintFunction::GlobalVolume { mesh, .. } => vcorr[mesh][slot as usize],
                _ => corr[c as usize][slot as usize],
            };
        }
        s
    };
    for_each_chunk(p, |first, out| {
        for (m, p) in out.iter_mut().enumerate() {
            let i = first + m;
            if w[i] > 0.0 {
                *p += gather(i);
            }
        }
    });
    project_contact_groups(ctx, contacts, contact_groups, p, parallel);
}

/// Adds the buffered corrections `list = (particle, constraint, slot)` (sorted by particle, each
/// particle at most once) to `pos`, whose first element is particle `base`; splits the list and
/// the positions at a particle boundary and recurses in parallel.
fn apply_sorted(pos: &mut [DVec3], base: usize, list: &[(u32, u32, u32)], corr: &[[DVec3; 4]], leaf: usize) {
    if list.len() <= leaf {
        for &(i, c, s) in list {
            pos[i as usize - base] += corr[c as usize][s as usize];
        }
        return;
    }
    let mid = list.len() / 2;
    let split = list[mid].0 as usize;
    let (lo, hi) = pos.split_at_mut(split - base);
    anim_core::par::join(
        || apply_sorted(lo, base, &list[..mid], corr, leaf),
        || apply_sorted(hi, split, &list[mid..], corr, leaf),
    );
}

/// Projects the contacts collider by collider; within a collider every particle appears once, so
/// its contacts run in parallel.
fn project_contact_groups(
    ctx: &Ctx<'_>,
    contacts: &mut [Contact],
    groups: &[Range<usize>],
    p: &mut [DVec3],
    parallel: bool,
) {
    for r in groups {
        let cs = &mut contacts[r.clone()];
        if parallel && cs.len() >= PARALLEL_MIN {
            let pos: &[DVec3] = p;
            cs.par_chunks_mut(CHUNK).for_each(|cs| {
                for c in cs {
                    c.dx = project_contact(ctx, c, pos[c.particle as usize]);
                }
            });
            for c in cs.iter() {
                p[c.particle as usize] += c.dx;
            }
        } else {
            for c in cs {
                let dx = project_contact(ctx, c, p[c.particle as usize]);
                p[c.particle as usize] += dx;
            }
        }
    }
}
