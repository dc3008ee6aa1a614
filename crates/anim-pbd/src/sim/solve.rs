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
//!   projections no longer wait for each other's results. On more than one thread a colour of
//!   at least `LEAF` constraints is swept along its split by particle ranges
//!   (`sim/colour_split.rs`): the two halves of the particles in parallel, each projection
//!   writing its particles at once, the straddling constraints after them.
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
use super::colour_split::{LEAF, Split, split_colour, sweep_colour};
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

/// (Re)builds the compiled constraints, the sweep order and the colouring for the settings `p`.
pub(super) fn plan_sweeps(model: &PbdModel, p: &PbdParams, data: &mut Data) {
    let m = model.constraints.len();
    let mut compiled: Vec<Compiled> =
        (0..m).map(|j| compile(model, j, p.iterations, p.stiffness_correction)).collect();
    let mut groups = Vec::new();
    let mut splits = Vec::new();
    match p.solver {
        SolverKind::GaussSeidel | SolverKind::Jacobi => groups.push(0..m),
        SolverKind::ColoredGaussSeidel => {
            let (colours, ncol) = colour(model);
            let mut order: Vec<usize> = (0..m).collect();
            order.sort_by_key(|&j| (colours[j], j));
            let mut start = 0;
            for c in 0..ncol as u32 {
                let len = colours.iter().filter(|&&k| k == c).count();
                splits.push(split_colour(model, &mut order[start..start + len], start));
                groups.push(start..start + len);
                start += len;
            }
            compiled = order.iter().map(|&j| compiled[j]).collect();
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
    // The Jacobi gather's incidences as flat indices `4 c + slot` of the corrections, when no
    // global volume (whose corrections live in its mesh's scratch) is among them.
    data.jacobi_inc = if p.solver == SolverKind::Jacobi && model.volume_meshes.is_empty() {
        model.inc.iter().map(|&(c, slot)| 4 * c + slot).collect()
    } else {
        Vec::new()
    };
    let buffered = p.solver != SolverKind::GaussSeidel;
    data.corr = if buffered { vec![[DVec3::ZERO; 4]; m] } else { Vec::new() };
    let is_volume = |c: &Compiled| matches!(c.kernel, Kernel::Volume { .. });
    data.group_has_volume = groups.iter().map(|r| compiled[r.clone()].iter().any(is_volume)).collect();
    data.splits = splits;
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
                &d.splits,
                &d.compiled,
                &mut d.lambda,
                &mut d.p,
                &mut d.contacts,
                &d.contact_groups,
            ),
            SolverKind::Jacobi => jacobi(
                &ctx,
                parallel,
                model,
                &d.compiled,
                &d.jacobi_inc,
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

/// One coloured Gauss-Seidel iteration: the colours `groups` of `compiled` in order (each along
/// its particle split, in parallel, when it holds no global volume), then the contacts collider
/// by collider.
fn coloured_gauss_seidel(
    ctx: &Ctx<'_>,
    parallel: bool,
    groups: &[Range<usize>],
    group_has_volume: &[bool],
    splits: &[Split],
    compiled: &[Compiled],
    lambda: &mut [f64],
    p: &mut [DVec3],
    contacts: &mut [Contact],
    contact_groups: &[Range<usize>],
) {
    for (g, r) in groups.iter().enumerate() {
        let cs = &compiled[r.clone()];
        let ls = &mut lambda[r.clone()];
        if parallel && cs.len() >= LEAF && !group_has_volume[g] {
            sweep_colour(ctx, &splits[g], r.start, cs, ls, p);
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
    jacobi_inc: &[u32],
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
    let flat = jacobi_inc;
    let gather = |i: usize| -> DVec3 {
        let r = model.inc_ptr[i]..model.inc_ptr[i + 1];
        if !flat.is_empty() {
            let mut s = DVec3::ZERO;
            for &f in &flat[r] {
                s += corr[(f >> 2) as usize][(f & 3) as usize];
            }
            return s;
        }
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
