//! Body forces, solid boundary conditions and the free-surface pressure projection
//! `v = Project(v^)` (Chorin's splitting, as in stable fluids, Stam 1999).
//!
//! With the cells labelled by [`crate::classify`], the right-hand side is the negated net
//! outflow `-h div u` of every fluid cell, the Poisson problem over fluid cells (air
//! neighbours at `p = 0`, solid neighbours Neumann) is `anim_fluid::pressure::Poisson`, solved
//! by its `PressureSolver` (MGPCG, CG, Gauss-Seidel or Jacobi), and the gradient update
//! `u_f -= s_hi - s_lo` (with `s = dt p / (rho h)`, air `s = 0`) is applied on every face between
//! two non-solid cells one of which is fluid: the same conventions as `anim_fluid::mac`. Faces
//! touching a solid cell carry the (static) solid's velocity, zero.

use crate::mac::{MacGrid, flatten, unflatten};
use crate::par;
use anim_fluid::pressure::{CellLabel, Poisson, PressureMethod, PressureSolver, SolveInfo};
use rayon::prelude::*;

/// Whether the face `idx` of axis `a` touches a solid cell (or the domain edge).
#[inline]
fn touches_solid<const D: usize>(n: [usize; D], solid: &[bool], a: usize, idx: [usize; D]) -> bool {
    if idx[a] == 0 || idx[a] == n[a] {
        return true;
    }
    let hi = flatten(n, idx);
    let mut lo_idx = idx;
    lo_idx[a] -= 1;
    solid[hi] || solid[flatten(n, lo_idx)]
}

/// The labels of the two cells of face `idx` of axis `a` (`None` outside the grid).
#[inline]
fn face_cells<const D: usize>(
    n: [usize; D],
    labels: &[CellLabel],
    a: usize,
    idx: [usize; D],
) -> (Option<usize>, Option<usize>, Option<CellLabel>, Option<CellLabel>) {
    let hi = (idx[a] < n[a]).then(|| flatten(n, idx));
    let lo = (idx[a] > 0).then(|| {
        let mut l = idx;
        l[a] -= 1;
        flatten(n, l)
    });
    (lo, hi, lo.map(|c| labels[c]), hi.map(|c| labels[c]))
}

/// Adds the velocity change `dv` of the body forces over the substep (`dt g`, in a moving tank
/// less the tank's velocity change) to every face not touching a solid and sets faces touching a
/// solid to zero.
pub(crate) fn body_forces_and_walls<const D: usize>(grid: &mut MacGrid<D>, solid: &[bool], dv: [f64; D]) {
    let n = grid.n;
    for a in 0..D {
        let fd = grid.face_dims(a);
        let dv = dv[a];
        grid.u[a]
            .par_chunks_mut(fd[0])
            .enumerate()
            .with_min_len(par::min_len(par::MIN_ENTRIES, fd[0]))
            .for_each(|(line, row)| {
                let mut idx = unflatten(fd, line * fd[0]);
                for (i, u) in row.iter_mut().enumerate() {
                    idx[0] = i;
                    if touches_solid(n, solid, a, idx) {
                        *u = 0.0;
                    } else {
                        *u += dv;
                    }
                }
            });
    }
}

/// Net outflow `h div u` of every fluid cell (0 elsewhere), m/s.
pub(crate) fn net_outflow<const D: usize>(grid: &MacGrid<D>, labels: &[CellLabel], out: &mut [f64]) {
    let n = grid.n;
    let fds: [[usize; D]; D] = std::array::from_fn(|a| grid.face_dims(a));
    out.par_chunks_mut(n[0]).enumerate().with_min_len(par::min_len(par::MIN_ENTRIES, n[0])).for_each(
        |(line, row)| {
            let mut idx = unflatten(n, line * n[0]);
            for (i, o) in row.iter_mut().enumerate() {
                idx[0] = i;
                let c = line * n[0] + i;
                if labels[c] != CellLabel::Fluid {
                    *o = 0.0;
                    continue;
                }
                let mut s = 0.0;
                for a in 0..D {
                    let lo = flatten(fds[a], idx);
                    let mut up = idx;
                    up[a] += 1;
                    s += grid.u[a][flatten(fds[a], up)] - grid.u[a][lo];
                }
                *o = s;
            }
        },
    );
}

/// The pressure solver settings.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PressureSettings {
    pub method: PressureMethod,
    pub tolerance: f64,
    pub max_iterations: usize,
}

/// Projects `grid.u` onto velocities with zero net outflow in every fluid cell. `rhs` and `s`
/// are scratch of one entry per cell; `target`, if given, is the net outflow wanted per
/// cell instead of zero (volume correction); `solver` is the cached solver of the last labels.
/// Returns the solve report.
///
/// # Errors
/// The pressure operator's errors (a grid it refuses).
pub(crate) fn project<const D: usize>(
    grid: &mut MacGrid<D>,
    labels: &[CellLabel],
    settings: PressureSettings,
    solver: &mut Option<PressureSolver>,
    target: Option<&[f64]>,
    rhs: &mut [f64],
    s: &mut [f64],
) -> Result<SolveInfo, anim_fluid::FluidError> {
    let n = grid.n;
    net_outflow(grid, labels, rhs);
    match target {
        Some(t) => rhs
            .par_iter_mut()
            .zip(t.par_iter())
            .with_min_len(par::min_len(par::MIN_ENTRIES, 1))
            .for_each(|(x, t)| *x = t - *x),
        None => rhs.par_iter_mut().with_min_len(par::min_len(par::MIN_ENTRIES, 1)).for_each(|x| *x = -*x),
    }
    if !labels.contains(&CellLabel::Fluid) {
        s.fill(0.0);
        return Ok(SolveInfo { iterations: 0, residual: 0.0, converged: true });
    }
    // The operator depends on the labels only: rebuild it (and its multigrid hierarchy) when
    // they changed since the last projection, in the buffers of the first one built.
    match solver.as_mut() {
        Some(sv) if sv.operator().labels() == labels => {}
        Some(sv) => sv.relabel(labels)?,
        None => {
            let dims3 = [n[0], n[1], if D == 3 { n[D - 1] } else { 1 }];
            let op = Poisson::new(dims3, D, labels.to_vec(), [[false; 2]; 3])?;
            *solver =
                Some(PressureSolver::new(op, settings.method, settings.tolerance, settings.max_iterations)?);
        }
    }
    let Some(solver) = solver.as_mut() else {
        return Ok(SolveInfo { iterations: 0, residual: 0.0, converged: true });
    };
    s.fill(0.0);
    let info = solver.solve(rhs, s);
    let s: &[f64] = s;
    for a in 0..D {
        let fd = grid.face_dims(a);
        grid.u[a]
            .par_chunks_mut(fd[0])
            .enumerate()
            .with_min_len(par::min_len(par::MIN_ENTRIES, fd[0]))
            .for_each(|(line, row)| {
                let mut idx = unflatten(fd, line * fd[0]);
                for (i, u) in row.iter_mut().enumerate() {
                    idx[0] = i;
                    let (lo, hi, llo, lhi) = face_cells(n, labels, a, idx);
                    let (Some(lo), Some(hi), Some(llo), Some(lhi)) = (lo, hi, llo, lhi) else { continue };
                    if llo == CellLabel::Solid || lhi == CellLabel::Solid {
                        continue;
                    }
                    if llo != CellLabel::Fluid && lhi != CellLabel::Fluid {
                        continue;
                    }
                    let value = |c: usize, l: CellLabel| if l == CellLabel::Fluid { s[c] } else { 0.0 };
                    *u -= value(hi, lhi) - value(lo, llo);
                }
            });
    }
    Ok(info)
}

/// Marks the faces with a fluid cell on either side valid (projected, or the wall's zero), the
/// others invalid, for extrapolation.
pub(crate) fn mark_fluid_faces<const D: usize>(grid: &mut MacGrid<D>, labels: &[CellLabel]) {
    let n = grid.n;
    for a in 0..D {
        let fd = grid.face_dims(a);
        grid.valid[a]
            .par_chunks_mut(fd[0])
            .enumerate()
            .with_min_len(par::min_len(par::MIN_ENTRIES, fd[0]))
            .for_each(|(line, row)| {
                let mut idx = unflatten(fd, line * fd[0]);
                for (i, v) in row.iter_mut().enumerate() {
                    idx[0] = i;
                    let (_, _, llo, lhi) = face_cells(n, labels, a, idx);
                    *v = llo == Some(CellLabel::Fluid) || lhi == Some(CellLabel::Fluid);
                }
            });
    }
}

/// Marks the faces that received particle weight valid.
pub(crate) fn mark_weighted_faces<const D: usize>(grid: &mut MacGrid<D>) {
    for a in 0..D {
        let (valid, weight) = (&mut grid.valid[a], &grid.weight[a]);
        valid
            .par_iter_mut()
            .zip(weight.par_iter())
            .with_min_len(par::min_len(par::MIN_ENTRIES, 1))
            .for_each(|(v, &w)| *v = w > 0.0);
    }
}

/// No-slip walls: zero the faces lying inside solid cells (both neighbours solid or outside the
/// grid), the tangential velocities particles next to a wall interpolate from.
pub(crate) fn no_slip<const D: usize>(grid: &mut MacGrid<D>, solid: &[bool]) {
    let n = grid.n;
    for a in 0..D {
        let fd = grid.face_dims(a);
        grid.u[a]
            .par_chunks_mut(fd[0])
            .enumerate()
            .with_min_len(par::min_len(par::MIN_ENTRIES, fd[0]))
            .for_each(|(line, row)| {
                let mut idx = unflatten(fd, line * fd[0]);
                for (i, u) in row.iter_mut().enumerate() {
                    idx[0] = i;
                    let hi = idx[a] == n[a] || solid[flatten(n, idx)];
                    let lo = idx[a] == 0 || {
                        let mut l = idx;
                        l[a] -= 1;
                        solid[flatten(n, l)]
                    };
                    if hi && lo {
                        *u = 0.0;
                    }
                }
            });
    }
}
